"""A flag given without its value does not take the next flag as the value: each program refuses "--record
--bench", "--out --quick" and the like with exit code 2, naming both, and writes nothing (the server would
have recorded into a file named "--bench" and run the daemon). A value with one dash is still a value ("--move
-2,0,0"). A word that belongs to no flag is refused the same way, not dropped (fishtank-client 10.0.0.5:7878
connected to the default address). fishtank-client refuses a value out of range with the range and the value
given."""

import os
import subprocess

import pytest

BUILD = os.environ["FISHTANK_BUILD_DIR"]


@pytest.mark.parametrize("program, words, said", [
    ("server/fishtank-server", ["--record", "--bench"], "--record wants a value, got the flag '--bench'"),
    ("server/fishtank-accuracy", ["--out", "--quick", "--collisions-only"],
     "--out wants a value, got the flag '--quick'"),
    ("client/fishtank-client", ["--connect", "--json"], "--connect wants a value, got the flag '--json'"),
    ("viewer/fishtank-viewer", ["--screenshot", "--observer"],
     "--screenshot wants a value, got the flag '--observer'"),
    ("server/fishtank-server", ["3000", "--duration", "0.1"],
     "unexpected '3000': every setting is a flag and its value"),
    ("server/fishtank-accuracy", ["--quick", "collisions"],
     "unexpected 'collisions': every setting is a flag and its value"),
    ("client/fishtank-client", ["127.0.0.1:1", "--duration", "0.1"],
     "unexpected '127.0.0.1:1': every setting is a flag and its value (did you mean --connect 127.0.0.1:1?)"),
    ("viewer/fishtank-viewer", ["127.0.0.1:1", "--duration", "0.1"],
     "unexpected '127.0.0.1:1': every setting is a flag and its value (did you mean --connect 127.0.0.1:1?)"),
])
def test_a_flag_missing_its_value_or_a_word_of_no_flag_is_refused_and_nothing_is_written(tmp_path, program, words,
                                                                                         said):
    path = os.path.join(BUILD, program)
    if not os.path.exists(path):
        pytest.skip(f"{program} is not built here")
    run = subprocess.run([path, *words], capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert run.returncode == 2, run.stderr
    assert run.stderr.splitlines() == [f"{os.path.basename(program)}: {said}", "Try --help for the list of options."]
    assert list(tmp_path.iterdir()) == []


def test_a_value_with_one_dash_is_still_a_value(tmp_path):
    run = subprocess.run([os.path.join(BUILD, "client", "fishtank-client"), "--move", "-2,0,0", "--connect",
                          "127.0.0.1:1", "--duration", "0.1"], capture_output=True, text=True, timeout=60)
    assert run.returncode == 1, run.stderr  # past the flags, to the connection
    assert "no connection to 127.0.0.1:1" in run.stderr


@pytest.mark.parametrize("flags, said", [
    (["--clients", "0"], "--clients must be between 1 and 1000, got 0"),
    (["--max-pending", "0"], "--max-pending must be between 1 and 1000, got 0"),
    (["--add", "-1"], "--add must be between 0 and 100000, got -1"),
    (["--duration", "0"], "--duration must be more than 0 and at most 86400 seconds, got 0"),
    (["--for", "nan"], "--for must be seconds >= 0, got nan"),
    (["--every", "-1"], "--every must be 0 (no interval reports) or at least 0.05 s, the client's tick, got -1"),
    (["--every", "0.001"], "--every must be 0 (no interval reports) or at least 0.05 s, the client's tick, got 0.001"),
    (["--step", "-2"], "--step must be between 0 and 100000, got -2"),
    (["--time-scale", "5"], "--time-scale must be between 0.1 and 1, got 5"),
    (["--reset", "--seed", "-1"], "--seed must be >= 0, got -1"),
    (["--move", "1,2"], "--move wants three finite numbers x,y,z, got '1,2'"),
    (["--pause", "--resume"], "--pause and --resume contradict each other; give one"),
    (["--scene", "Drop"], "--scene: unknown scene 'Drop'; the scenes are tank, wide, dam-break and drop"),
    (["--scene", "tank", "--reset"], "--scene starts that scene from its start already; drop --reset"),
    (["--for", "2"], "--for goes with --move (how long to move)"),
])
def test_a_client_value_out_of_range_is_refused_with_its_range_and_the_value_given(flags, said):
    run = subprocess.run([os.path.join(BUILD, "client", "fishtank-client"), *flags], capture_output=True, text=True,
                         timeout=30)
    assert run.returncode == 2, run.stderr
    assert run.stderr.splitlines() == [f"fishtank-client: {said}", "Try --help for the list of options."]
