"""Each bad flag of fishtank-viewer is refused before a window opens: exit code 2, the flag and the value given
on one line, then the pointer to --help; a --connect port that cannot exist is one of them, not an address
retried every second, and a --screenshot path that cannot be written is another. No display is needed: the flags
are read first."""

import os
import subprocess

import pytest

VIEWER = os.path.join(os.environ["FISHTANK_BUILD_DIR"], "viewer", "fishtank-viewer")


@pytest.mark.parametrize("flags, said", [
    (["--frobnicate"], "unrecognised option '--frobnicate'"),
    (["--connect"], "the required argument for option '--connect' is missing"),
    (["--connect", "127.0.0.1"], "--connect wants host:port with a port 1 .. 65535, got '127.0.0.1'"),
    (["--connect", "127.0.0.1:99999"], "--connect wants host:port with a port 1 .. 65535, got '127.0.0.1:99999'"),
    (["--connect", "127.0.0.1:abc"], "--connect wants host:port with a port 1 .. 65535, got '127.0.0.1:abc'"),
    (["--frames", "0"], "--frames must be at least 1, got 0"),
    (["--frames", "5"], "--frames counts the frames before --screenshot: give --screenshot FILE too, or drop it"),
    (["--max-fps", "-1"], "--max-fps must be between 0 (no cap) and"),
    (["--duration", "-2"], "--duration must be a number of seconds >= 0 (0: stay open), got -2"),
    (["--duration", "soon"], "the argument ('soon') for option '--duration' is invalid"),
    # Checked before a window opens, not found when the frames are drawn.
    (["--screenshot", "shot.jpg"], "--screenshot writes a PNG: name a .png file, got 'shot.jpg'"),
    (["--screenshot", "/nonexistent-folder/shot.png"],
     "--screenshot /nonexistent-folder/shot.png: the folder /nonexistent-folder does not exist"),
])
def test_a_bad_flag_is_refused_with_what_is_wrong_and_where_help_is(flags, said):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    run = subprocess.run([VIEWER, *flags], capture_output=True, text=True, timeout=30, env=env)
    assert run.returncode == 2, run.stderr
    lines = run.stderr.splitlines()
    assert len(lines) == 2 and lines[0].startswith("fishtank-viewer: ") and said in lines[0], run.stderr
    assert lines[1] == "Try --help for the list of options."
    assert run.stdout == ""
