"""--fullscreen fills the monitor (SPEC 5.2): under Xvfb on a 1920x1080 screen, a screenshot of the viewer full
screen is 1920x1080 and one of the viewer in its window is smaller. Skipped without xvfb-run."""

import os
import shutil
import struct
import subprocess
import sys

import pytest

sys.path.insert(0, os.path.join(os.environ["FISHTANK_SOURCE_DIR"], "scripts"))
import fishtank_tools as ft  # noqa: E402  (after the path)

BUILD = os.environ["FISHTANK_BUILD_DIR"]
VIEWER = os.path.join(BUILD, "viewer", "fishtank-viewer")
SERVER = os.path.join(BUILD, "server", "fishtank-server")


def png_size(path):
    with open(path, "rb") as f:
        header = f.read(24)
    assert header[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    return struct.unpack(">II", header[16:24])  # IHDR's width and height


@pytest.mark.skipif(shutil.which("xvfb-run") is None, reason="xvfb-run is not installed (scripts/install-deps viewer)")
def test_full_screen_fills_the_monitor_and_a_window_does_not(tmp_path):
    sizes = {}
    with ft.Server(SERVER, "--bind", "127.0.0.1", "--port", "0", "--no-web", "--threads", "1", "--balls", "100",
                   timeout=15) as server:
        for mode in ("--fullscreen", "--window"):
            shot = tmp_path / f"{mode[2:]}.png"
            flags = [mode] if mode == "--fullscreen" else []
            run = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", VIEWER, "--connect",
                                  server.endpoint, *flags, "--screenshot", str(shot), "--frames", "3"],
                                 capture_output=True, text=True, timeout=120)
            assert run.returncode == 0, run.stderr
            sizes[mode] = png_size(shot)
    assert sizes["--fullscreen"] == (1920, 1080), sizes
    width, height = sizes["--window"]
    assert width < 1920 and height < 1080, sizes
