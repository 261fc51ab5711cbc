"""A flag given without its value does not take the next flag as the value: each program refuses
"--record --bench", "--out --quick" and the like with exit code 2, naming both, and writes nothing (the
server would have recorded into a file named "--bench" and run the daemon). A value with one dash is still
a value ("--move -2,0,0")."""

import os
import subprocess

import pytest

BUILD = os.environ["FISHTANK_BUILD_DIR"]


@pytest.mark.parametrize("program, flags, named", [
    ("server/fishtank-server", ["--record", "--bench"], "--record wants a value, got the flag '--bench'"),
    ("server/fishtank-accuracy", ["--out", "--quick", "--collisions-only"],
     "--out wants a value, got the flag '--quick'"),
    ("client/fishtank-client", ["--connect", "--json"], "--connect wants a value, got the flag '--json'"),
    ("viewer/fishtank-viewer", ["--screenshot", "--observer"],
     "--screenshot wants a value, got the flag '--observer'"),
])
def test_a_flag_missing_its_value_is_refused_and_nothing_is_written(tmp_path, program, flags, named):
    path = os.path.join(BUILD, program)
    if not os.path.exists(path):
        pytest.skip(f"{program} is not built here")
    run = subprocess.run([path, *flags], capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert run.returncode == 2, run.stderr
    assert run.stderr.splitlines() == [f"{os.path.basename(program)}: {named}", "Try --help for the list of options."]
    assert list(tmp_path.iterdir()) == []


def test_a_value_with_one_dash_is_still_a_value(tmp_path):
    run = subprocess.run([os.path.join(BUILD, "client", "fishtank-client"), "--move", "-2,0,0", "--connect",
                          "127.0.0.1:1", "--duration", "0.1"], capture_output=True, text=True, timeout=60)
    assert run.returncode == 1, run.stderr  # past the flags, to the connection
    assert "no connection to 127.0.0.1:1" in run.stderr
