"""A viewer pointed at a port where nothing listens says so on the terminal:
the address, why (connection refused) and the exact command that starts a
server on that port, once, not at every retry; at exit it counts the frames it
really drew, none of them with the scene. A --screenshot it could not take
fails the run and says why. Under Xvfb; skipped without xvfb-run."""

import os
import re
import shutil
import socket
import subprocess

import pytest

VIEWER = os.path.join(os.environ["FISHTANK_BUILD_DIR"], "viewer", "fishtank-viewer")


@pytest.mark.skipif(shutil.which("xvfb-run") is None, reason="xvfb-run is not installed (scripts/install-deps viewer)")
def test_a_viewer_with_no_server_says_where_why_and_how_to_start_one_and_counts_its_frames():
    with socket.socket() as probe:  # a port just freed: nothing listens there
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    run = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", VIEWER, "--connect",
                          f"127.0.0.1:{port}", "--duration", "2.5", "--max-fps", "20"],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    told = [line for line in run.stderr.splitlines() if "no connection to" in line]
    assert len(told) == 1, run.stderr  # three attempts, one reason: said once
    assert f"127.0.0.1:{port}: cannot connect: Connection refused" in told[0]
    assert f"To start a server here: build/server/fishtank-server --port {port}" in told[0]
    summary = re.search(r"(\d+) frames in ([\d.]+) s \(([\d.]+) fps\), none with the scene: no snapshot from "
                        + re.escape(f"127.0.0.1:{port}"), run.stderr)
    assert summary, run.stderr
    # Counted from the end of the first frame (software rendering on a busy machine can make it slow) to the
    # first past --duration; fps is printed to 0.1 and seconds to 0.01.
    frames, seconds, fps = int(summary.group(1)), float(summary.group(2)), float(summary.group(3))
    assert frames >= 10 and 1.5 <= seconds <= 2.6 and fps == pytest.approx((frames - 1) / seconds, abs=0.15)


@pytest.mark.skipif(shutil.which("xvfb-run") is None, reason="xvfb-run is not installed (scripts/install-deps viewer)")
def test_a_screenshot_the_viewer_closed_before_taking_fails_the_run_and_says_why(tmp_path):
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    shot = tmp_path / "shot.png"
    run = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", VIEWER, "--connect",
                          f"127.0.0.1:{port}", "--duration", "1", "--screenshot", str(shot)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 1, run.stderr
    assert f"--screenshot {shot} not saved: the viewer closed before the first snapshot came" in run.stderr
    assert not shot.exists()
