"""Errors a new user meets first say what happened and what to do, in one
message, and nothing before it reads as success: --bench refuses more balls
than the tank holds and says what fits, as on a scene that holds fewer, where
its default count becomes what fits; a port in use names --port and
--port 0, with no "Ctrl-C stops" banner first; a final-state path that cannot
be written is refused before the run, not after it; fishtank-client pointed
where nothing listens gives the command that starts a server there, and one
whose connections are not all welcomed says so and fails, as does one whose command the
server refuses; a server
bound to every address gives the others an address that reaches it, not
0.0.0.0; a server given one core (taskset) starts one thread, not one per
core installed; a second Ctrl-C ends a server that is writing its final files."""

import json
import os
import re
import shutil
import signal
import socket
import subprocess
import time

import pytest

SERVER = os.path.join(os.environ["FISHTANK_BUILD_DIR"], "server", "fishtank-server")
CLIENT = os.path.join(os.environ["FISHTANK_BUILD_DIR"], "client", "fishtank-client")


def test_bench_with_more_balls_than_fit_refuses_in_one_line_that_says_what_fits():
    run = subprocess.run([SERVER, "--bench", "--balls", "7000"], capture_output=True, text=True, timeout=30)
    assert run.returncode == 2
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1, run.stderr
    fits = re.search(r"refuses --balls 7000: the tank holds at most (\d+); use --balls (\d+) or fewer", lines[0])
    assert fits and fits.group(1) == fits.group(2) and 5000 < int(fits.group(1)) < 7000, lines[0]
    assert "added" not in run.stderr and run.stdout == ""


def test_bench_on_a_scene_that_holds_fewer_says_what_it_holds_and_that_count_runs():
    run = subprocess.run([SERVER, "--bench", "--scene", "drop", "--balls", "6000"], capture_output=True, text=True,
                         timeout=30)
    assert run.returncode == 2
    holds = re.fullmatch(r"fishtank-server: --bench refuses --balls 6000: the drop scene holds at most (\d+); "
                         r"use --balls (\d+) or fewer, or --scene wide for more", run.stderr.strip())
    assert holds and holds.group(1) == holds.group(2), run.stderr
    quick = ["--steps", "10", "--windows", "1", "--settle-time", "0.05"]
    given = subprocess.run([SERVER, "--bench", "--scene", "drop", "--balls", holds.group(1), *quick],
                           capture_output=True, text=True, timeout=120)
    assert given.returncode == 0, given.stderr
    assert json.loads(given.stdout)["balls"] == int(holds.group(1))
    # Without --balls the benchmark's 6000 becomes what the scene holds, instead of a refusal.
    default = subprocess.run([SERVER, "--bench", "--scene", "drop", *quick], capture_output=True, text=True,
                             timeout=120)
    assert default.returncode == 0, default.stderr
    assert json.loads(default.stdout)["balls"] == int(holds.group(1))


def test_bench_keeps_to_max_balls_on_a_placed_scene_too():
    for scene in ("wide", "tank"):  # the tank's refusal sent readers to --scene wide, which --max-balls caps too
        run = subprocess.run([SERVER, "--bench", "--scene", scene, "--balls", "1000", "--max-balls", "500"],
                             capture_output=True, text=True, timeout=30)
        assert run.returncode == 2 and run.stdout == ""
        assert run.stderr.strip() == ("fishtank-server: --bench refuses --balls 1000: --max-balls lets in at most "
                                      "500; use --balls 500 or fewer"), run.stderr
    quick = ["--steps", "10", "--windows", "1", "--settle-time", "0.05"]
    default = subprocess.run([SERVER, "--bench", "--scene", "wide", "--max-balls", "500", *quick],
                             capture_output=True, text=True, timeout=120)
    assert default.returncode == 0, default.stderr
    assert json.loads(default.stdout)["balls"] == 500  # the benchmark's 6000 becomes what --max-balls lets in


def test_a_port_in_use_names_the_flag_and_port_0_and_no_banner_comes_first():
    first = subprocess.Popen([SERVER, "--port", "0", "--no-web", "--threads", "1", "--duration", "30"],
                             stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
    try:
        port = None
        deadline = time.monotonic() + 15
        while port is None and time.monotonic() < deadline:
            found = re.match(r"listening on 127\.0\.0\.1:(\d+)", first.stderr.readline())
            port = found and found.group(1)
        assert port, "the first server did not start"
        second = subprocess.run([SERVER, "--port", port, "--no-web", "--threads", "1"], capture_output=True, text=True,
                                timeout=30)
    finally:
        first.send_signal(signal.SIGTERM)
        first.wait(timeout=10)
    assert second.returncode == 1
    assert f"cannot listen on 127.0.0.1:{port}" in second.stderr
    assert "--port P" in second.stderr and "--port 0" in second.stderr
    assert "Ctrl-C stops" not in second.stderr and "listening on" not in second.stderr


def test_output_paths_that_cannot_be_written_are_refused_before_anything_runs(tmp_path):
    a_file = tmp_path / "a-file"
    a_file.write_text("")
    refusals = {
        ("--dump", str(tmp_path / "missing" / "final.csv")): f"the folder {tmp_path / 'missing'} does not exist",
        ("--dump", str(tmp_path)): "is a folder",
        ("--record", str(tmp_path / "missing" / "run.dump")): f"the folder {tmp_path / 'missing'} does not exist",
        ("--export-lammps", str(a_file / "lammps")): "cannot create",
        # /proc lets root pass access(2) yet makes no file: only making one tells.
        ("--dump", "/proc/fishtank-final.csv"): "cannot write /proc/fishtank-final.csv: No such file or directory",
        ("--export-lammps", "/proc/self"): "cannot write in /proc/self: ",  # a folder that exists
    }
    for (flag, path), why in refusals.items():
        for mode in (["--bench", "--balls", "200", "--steps", "100"], ["--port", "0", "--no-web", "--duration", "5"]):
            run = subprocess.run([SERVER, *mode, flag, path], capture_output=True, text=True, timeout=30)
            assert run.returncode == 2, (mode, run.stderr)
            lines = run.stderr.strip().splitlines()
            assert len(lines) == 1 and lines[0].startswith(f"fishtank-server: {flag} {path}: "), run.stderr
            assert why in lines[0], lines[0]
            assert run.stdout == ""  # no benchmark ran, no server listened
    made = tmp_path / "made" / "lammps"  # a folder that can be made is made, and the run goes ahead
    run = subprocess.run([SERVER, "--bench", "--balls", "200", "--steps", "100", "--export-lammps", str(made)],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    assert (made / "data.fishtank").exists() and (made / "in.fishtank").exists()


def test_an_address_not_of_this_machine_is_refused_saying_so_and_what_listens_everywhere():
    # 192.0.2.1 is TEST-NET-1 (RFC 5737): never an address of this machine.
    run = subprocess.run([SERVER, "--bind", "192.0.2.1", "--port", "0", "--no-web", "--duration", "5"],
                         capture_output=True, text=True, timeout=30)
    assert run.returncode != 0
    assert ("cannot listen on 192.0.2.1:0: that is not an address of this machine; --bind 0.0.0.0 listens on all "
            "of them") in run.stderr, run.stderr


def test_a_client_with_no_server_says_where_why_and_the_command_that_starts_one_there():
    with socket.socket() as probe:  # a port just freed: nothing listens there
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    run = subprocess.run([CLIENT, "--connect", f"127.0.0.1:{port}", "--duration", "1"], capture_output=True,
                         text=True, timeout=30)
    assert run.returncode == 1
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1, run.stderr
    assert f"no connection to 127.0.0.1:{port}: cannot connect: Connection refused" in lines[0]
    assert lines[0].endswith(f"To start a server here: build/server/fishtank-server --port {port}"), lines[0]


def test_a_client_whose_connections_are_not_all_welcomed_says_how_many_and_fails_and_says_each_reason_once():
    server = subprocess.Popen([SERVER, "--port", "0", "--no-web", "--threads", "1", "--balls", "10",
                               "--max-connections", "3", "--max-players", "1", "--duration", "20"],
                              stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
    try:
        line = server.stderr.readline()
        while line and not line.startswith("listening on"):
            line = server.stderr.readline()
        port = int(line.strip().rsplit(":", 1)[1])
        client = [CLIENT, "--connect", f"127.0.0.1:{port}", "--clients", "4", "--duration", "1"]
        run = subprocess.run(client, capture_output=True, text=True, timeout=30)
        as_json = subprocess.run(client + ["--json"], capture_output=True, text=True, timeout=30)
    finally:
        server.send_signal(signal.SIGTERM)
        server.wait(timeout=10)
    assert run.returncode == 1, run.stdout + run.stderr
    assert run.stdout.startswith("3 of 4 clients welcomed"), run.stdout
    errors = [line for line in run.stdout.splitlines() if line.startswith("error: ")]
    assert any(e.startswith("error: player_limit: ") and e.endswith(" (2 connections)") for e in errors), errors
    assert any(e.startswith("error: server_full: ") and "--max-connections" in e for e in errors), errors
    assert len(errors) == len(set(errors)), errors
    assert run.stderr.strip() == ("fishtank-client: 1 of 4 connections were not welcomed "
                                  "(the server's reasons are above)"), run.stderr
    # --json lists each message once too, with the same count, and counts every error.
    summary = json.loads(as_json.stdout)
    counts = [int(m.group(1)) if (m := re.search(r" \((\d+) connections\)$", e)) else 1
              for e in summary["error_messages"]]
    assert sum(counts) == summary["errors"] and len(set(summary["error_messages"])) == len(counts), summary
    assert any(e.startswith("player_limit: ") and e.endswith(" (2 connections)") for e in summary["error_messages"])


def test_a_client_whose_command_the_server_refuses_fails_but_one_waiting_in_line_for_a_sphere_does_not():
    server = subprocess.Popen([SERVER, "--port", "0", "--no-web", "--threads", "1", "--balls", "10",
                               "--max-players", "1", "--duration", "20"],
                              stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
    try:
        line = server.stderr.readline()
        while line and not line.startswith("listening on"):
            line = server.stderr.readline()
        address = ["--connect", f"127.0.0.1:{int(line.strip().rsplit(':', 1)[1])}", "--duration", "1"]
        step = subprocess.run([CLIENT, *address, "--step", "10"], capture_output=True, text=True, timeout=30)
        in_line = subprocess.run([CLIENT, *address, "--clients", "2"], capture_output=True, text=True, timeout=30)
    finally:
        server.send_signal(signal.SIGTERM)
        server.wait(timeout=10)
    assert step.returncode == 1, step.stdout + step.stderr
    assert "error: not_paused: " in step.stdout
    assert step.stderr.strip() == "fishtank-client: the server refused what was asked (its reasons are above)"
    assert in_line.returncode == 0, in_line.stdout + in_line.stderr
    assert "error: player_limit: " in in_line.stdout


def test_a_server_that_takes_other_machines_gives_them_an_address_that_reaches_it_not_0_0_0_0():
    server = subprocess.Popen([SERVER, "--bind", "0.0.0.0", "--port", "0", "--web-port", "0", "--threads", "1",
                               "--duration", "20"], stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
    try:
        lines = [server.stderr.readline()]  # the page's "not built" line may come first, then listening, web
        while not lines[-1].startswith("from other machines") and len(lines) < 6:
            lines.append(server.stderr.readline())
        assert any(re.match(r"listening on 0\.0\.0\.0:\d+$", line) for line in lines), lines
        said = re.fullmatch(r"from other machines: a browser at http://(\S+):(\d+)/, fishtank-viewer --connect "
                            r"(\S+):(\d+) \(this machine: (.+)\)\n", lines[-1])
        assert said, lines
        host, web_port, same_host, port, known_as = said.groups()
        assert host == same_host and not host.startswith("127.") and host != "0.0.0.0"
        assert known_as.split(", ")[0] == socket.gethostname()  # its name, then its addresses
        for reach in (int(port), int(web_port)):  # the address given reaches both ports of this server
            socket.create_connection((host, reach), timeout=5).close()
    finally:
        server.send_signal(signal.SIGTERM)
        server.wait(timeout=10)
    local = subprocess.run([SERVER, "--port", "0", "--no-web", "--threads", "1", "--duration", "0.5"],
                           capture_output=True, text=True, timeout=30)
    assert "from other machines" not in local.stderr  # 127.0.0.1: no other machine gets in


@pytest.mark.skipif(shutil.which("taskset") is None, reason="taskset (util-linux) is not installed")
def test_a_server_given_one_core_starts_one_thread():
    run = subprocess.run(["taskset", "-c", "0", SERVER, "--port", "0", "--no-web", "--balls", "0", "--duration",
                          "0.3"], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, run.stderr
    assert re.search(r"fishtank-server \(sse, [^)]*, 1 thread\)", run.stderr), run.stderr
    assert "oversubscribed" not in run.stderr


def _started(flags):
    """A server on an ephemeral port with these flags, once its banner says Ctrl-C stops it."""
    server = subprocess.Popen([SERVER, "--port", "0", "--no-web", *flags], stderr=subprocess.PIPE, text=True)
    line = server.stderr.readline()
    while "Ctrl-C stops" not in line:
        assert line, "the server ended before its banner"
        line = server.stderr.readline()
    return server


def test_a_second_ctrl_c_ends_a_server_that_is_writing_its_final_files(tmp_path):
    # A million balls' final files take the server a second or more to write: long enough to interrupt.
    server = _started(["--scene", "wide", "--balls", "1000000", "--dump", str(tmp_path / "final.csv"),
                       "--export-lammps", str(tmp_path / "lammps")])
    try:
        server.send_signal(signal.SIGINT)
        line = ""
        while "stopped after" not in line:  # it stops stepping and goes on to the files
            line = server.stderr.readline()
            assert line, "the server ended without saying it stopped"
        server.send_signal(signal.SIGINT)
        assert server.wait(timeout=10) == 128 + signal.SIGINT, "the files were finished: the second Ctrl-C waited"
        assert "interrupted again: stopping at once" in server.stderr.read()
    finally:
        server.kill()
        server.wait()


def test_a_sigterm_after_ctrl_c_lets_the_server_write_its_final_files(tmp_path):
    # scripts/run's exit trap sends SIGTERM to a server the terminal's Ctrl-C reached a moment before.
    dump = tmp_path / "final.csv"
    server = _started(["--balls", "50", "--dump", str(dump)])
    try:
        time.sleep(1)  # some balls poured in
        server.send_signal(signal.SIGINT)
        server.send_signal(signal.SIGTERM)
        assert server.wait(timeout=10) == 0
        stopped = re.search(r"stopped after \d+ steps, (\d+) balls", server.stderr.read())
    finally:
        server.kill()
        server.wait()
    assert stopped and int(stopped.group(1)) > 0
    assert len(dump.read_text().splitlines()) == 1 + int(stopped.group(1))  # a header, then every ball
