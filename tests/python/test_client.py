"""The Python client against a real server: snapshots come out as numpy arrays
that agree with the server's own state; the controls do what they say
(pause holds, step runs exactly N, the same seed restarts the same run bit for
bit, a time scale of one half halves the pace); refusals raise FishtankError
and leave the connection working."""

import os
import signal
import socket
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import fishtank
import fishtank_tools  # scripts/, on the path from server_process (conftest.py)
from fishtank import Client, FishtankError


def test_a_snapshot_gives_positions_kinds_and_ids_as_numpy_arrays_inside_the_tank(start_server):
    server = start_server("--balls", "300")
    with Client("127.0.0.1", server.port) as tank:
        deadline = time.monotonic() + 10
        s = tank.snapshot()
        while s.positions.shape[0] < 300 and time.monotonic() < deadline:
            s = tank.snapshot()
        assert s.positions.shape == (300, 3) and s.positions.dtype == np.float32
        assert s.kinds.shape == (300,) and s.kinds.dtype == np.uint8
        assert np.array_equal(s.ids, np.arange(300, dtype=np.uint32))
        assert sorted(np.bincount(s.kinds).tolist()) == [100, 100, 100]  # three sizes in equal numbers
        assert np.all(s.positions >= s.tank_min) and np.all(s.positions <= s.tank_max)
        assert s.scene == "tank" and not s.paused
        assert tank.player_id is not None and s.player_ids.tolist() == [tank.player_id]


def test_positions_agree_with_the_servers_own_state_within_half_a_quantisation_step(start_server, tmp_path):
    dump = tmp_path / "final.csv"
    server = start_server("--scene", "drop", "--balls", "400", "--dump", str(dump))
    with Client("127.0.0.1", server.port) as tank:
        tank.pause()
        tank.step(300)  # the balls are falling: positions that differ from the start
        s = tank.snapshot()
    assert server.stop() == 0
    state = np.loadtxt(dump, delimiter=",", skiprows=1, dtype=np.float64)  # x,y,z,... in id order
    half_step = 0.5 * (s.tank_max - s.tank_min) / 65535.0
    error = np.abs(s.positions - state[:, :3])
    assert np.all(error <= half_step * 1.01 + 1e-5), error.max(axis=0)


def test_the_welcome_says_how_dt_was_chosen_from_the_tolerance_or_given(start_server):
    with Client("127.0.0.1", start_server("--balls", "10").port) as tank:
        assert tank.tolerance == pytest.approx(0.005)
        assert tank.steps_per_contact == pytest.approx(13, rel=1e-4)  # ceil(sqrt(0.8 / 0.005))
        contact_duration = tank.steps_per_contact * tank.dt
    with Client("127.0.0.1", start_server("--balls", "10", "--tolerance", "0.002").port) as tank:
        assert tank.tolerance == pytest.approx(0.002)
        assert tank.steps_per_contact == pytest.approx(20, rel=1e-4)
    with Client("127.0.0.1", start_server("--balls", "10", "--dt", "0.0005").port) as tank:
        assert tank.tolerance == 0.0
        assert tank.steps_per_contact * tank.dt == pytest.approx(contact_duration, rel=1e-5)  # fixed by k


def test_pause_holds_still_and_step_runs_exactly_the_steps_asked_for(start_server):
    server = start_server("--balls", "200")
    with Client("127.0.0.1", server.port) as tank:
        paused = tank.pause()
        time.sleep(0.3)
        still = tank.snapshot()
        assert still.paused and still.physics_steps == paused.physics_steps
        assert np.array_equal(still.positions, paused.positions)
        stepped = tank.step(40)
        assert stepped.physics_steps == paused.physics_steps + 40
        assert stepped.sim_time == pytest.approx(paused.sim_time + 40 * tank.dt, rel=1e-6)
        running = tank.resume()
        assert not running.paused


def test_a_reset_with_the_same_seed_replays_the_run_bit_for_bit_and_another_seed_does_not(start_server):
    server = start_server("--balls", "300")
    with Client("127.0.0.1", server.port) as tank:
        tank.pause()
        runs = {}
        for label, seed in (("first", 4), ("again", 4), ("other", 5)):
            start = tank.scene("dam-break", seed=seed)
            assert start.scene == "dam-break" and start.positions.shape == (300, 3)
            runs[label] = tank.step(500).positions
        assert np.array_equal(runs["first"], runs["again"])
        assert not np.array_equal(runs["first"], runs["other"])
        assert tank.reset().scene == "dam-break"  # reset keeps the scene running


def test_a_time_scale_of_one_half_runs_simulated_time_at_half_the_wall_clocks_pace(start_server):
    server = start_server("--balls", "100")
    with Client("127.0.0.1", server.port) as tank:
        assert tank.time_scale(0.5).time_scale_set == 0.5
        before, wall = tank.snapshot().sim_time, time.monotonic()
        time.sleep(1.5)
        after, wall_after = tank.snapshot().sim_time, time.monotonic()
        assert (after - before) / (wall_after - wall) == pytest.approx(0.5, abs=0.08)


def test_move_drives_the_player_sphere_and_add_balls_pours_more_in(start_server):
    server = start_server("--balls", "100", "--max-balls", "250")
    with Client("127.0.0.1", server.port) as tank:
        start = tank.snapshot().player_positions[0]
        tank.move((4.0, 0.0, 0.0))
        time.sleep(1.0)
        moved = tank.snapshot().player_positions[0]
        assert moved[0] > start[0] + 2.0
        tank.add_balls(100)
        deadline = time.monotonic() + 10
        while tank.snapshot().positions.shape[0] < 200 and time.monotonic() < deadline:
            pass
        assert tank.snapshot().positions.shape[0] == 200
        with pytest.raises(FishtankError) as full:
            tank.add_balls(100)  # 250 at most
        assert full.value.code == "tank_full"


def test_a_client_in_line_for_a_sphere_gets_the_one_its_holder_frees_and_can_move_it(start_server):
    server = start_server("--balls", "0", "--max-players", "1")
    holder = Client("127.0.0.1", server.port)
    with Client("127.0.0.1", server.port) as waiting:
        assert holder.player_id is not None and waiting.player_id is None
        waiting.snapshot()  # the refusal follows the Welcome, before any snapshot
        assert [e.code for e in waiting.errors] == ["player_limit"]
        assert "in line for the next one freed" in waiting.errors[0].message
        assert waiting.ahead_in_line == 0
        with pytest.raises(FishtankError) as none:
            waiting.move((1.0, 0.0, 0.0))
        assert none.value.code == "no_player"
        with pytest.raises(FishtankError) as not_yet:
            waiting.wait_for_player(timeout=0.5)  # the holder has not left
        assert not_yet.value.code == "timeout"
        holder.close()
        granted = waiting.wait_for_player()
        assert granted is not None and granted == waiting.player_id
        assert waiting.may_control
        assert waiting.ahead_in_line is None
        start, deadline = waiting.snapshot(), time.monotonic() + 10
        while waiting.player_id not in start.player_ids and time.monotonic() < deadline:
            start = waiting.snapshot()  # one taken before the grant may still have been waiting to be read
        mine = list(start.player_ids).index(waiting.player_id)
        waiting.move((4.0, 0.0, 0.0))
        time.sleep(1.0)
        moved = waiting.snapshot()
        assert moved.player_positions[list(moved.player_ids).index(waiting.player_id)][0] > \
            start.player_positions[mine][0] + 2.0


def test_waiting_for_a_sphere_outside_the_line_says_so_at_once(start_server):
    server = start_server("--balls", "0", "--max-players", "0")
    with Client("127.0.0.1", server.port) as refused, Client("127.0.0.1", server.port, player=False) as watcher:
        for client in (refused, watcher):
            started = time.monotonic()
            with pytest.raises(FishtankError) as none:
                client.wait_for_player(timeout=10)
            assert none.value.code == "no_player" and time.monotonic() - started < 5
        assert "--max-players 0" in str(refused.errors[0])


def test_refusals_raise_with_the_servers_reason_and_the_connection_keeps_working(start_server):
    server = start_server("--balls", "50")
    with Client("127.0.0.1", server.port) as tank, Client("127.0.0.1", server.port, player=False) as observer:
        with pytest.raises(FishtankError) as running:
            tank.step(5)
        assert running.value.code == "not_paused"
        with pytest.raises(FishtankError) as unknown:
            tank.scene("cube")
        assert unknown.value.code == "invalid_value" and "tank, wide, dam-break and drop" in unknown.value.message
        with pytest.raises(FishtankError) as fast:
            tank.time_scale(5)
        assert fast.value.code == "invalid_value"
        assert not observer.may_control and "observers may not" in observer.control_policy
        with pytest.raises(FishtankError) as refused:
            observer.pause()
        assert refused.value.code == "not_permitted"
        assert not tank.snapshot().paused and observer.snapshot().scene == "tank"


def test_a_port_where_nothing_listens_raises_fishtank_error_with_the_address_and_the_server_command():
    with socket.socket() as probe:  # a port just freed: nothing listens there
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    with pytest.raises(FishtankError) as refused:
        Client("127.0.0.1", port)
    assert refused.value.code == "cannot_connect"
    assert f"127.0.0.1:{port}" in refused.value.message
    assert f"build/server/fishtank-server --port {port}" in refused.value.message


def test_an_ipv6_address_in_brackets_as_the_server_writes_it_is_connected_to_not_looked_up_as_a_name():
    with socket.socket() as probe:  # a port just freed on 127.0.0.1; on ::1 nothing listens there either
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    with pytest.raises(FishtankError) as refused:
        Client("[::1]", port, timeout=5)
    assert refused.value.code == "cannot_connect"
    assert "cannot resolve" not in refused.value.message and f"[::1]:{port}" in refused.value.message


def test_the_server_command_binds_where_the_default_127_0_0_1_would_not_answer():
    # The viewer's hint (common/server_hint.h) says the same; a refused connection to another host cannot be
    # made to happen here, so the command is checked on its own.
    command = fishtank.client._server_command
    assert command("localhost", 7878) == "build/server/fishtank-server --port 7878"
    assert command("::1", 7878) == "build/server/fishtank-server --bind ::1 --port 7878"
    assert command("tank.example", 7878) == "build/server/fishtank-server --bind 0.0.0.0 --port 7878"
    assert command("fe80::1", 7878) == "build/server/fishtank-server --bind :: --port 7878"


def test_a_port_or_timeout_out_of_range_is_refused_before_any_connection_with_the_range():
    for port in (0, "7878", 7878.0, True):
        with pytest.raises(ValueError, match=r"port must be a whole number from 1 to 65535, got"):
            Client("127.0.0.1", port)
    with pytest.raises(ValueError, match=r"port must be a whole number from 1 to 65535, got 70000"):
        Client("127.0.0.1", np.int64(70000))
    for timeout in (0, -1):
        with pytest.raises(ValueError, match=r"timeout must be a positive number of seconds"):
            Client("127.0.0.1", 7878, timeout=timeout)


def test_arguments_the_wire_cannot_carry_raise_value_error_at_once_and_the_next_refusal_is_the_right_one(
        start_server):
    server = start_server("--balls", "100")
    with Client("127.0.0.1", server.port) as tank:
        for bad in ((1, 2), "abc", (float("nan"), 0, 0), (0, float("inf"), 0)):
            with pytest.raises(ValueError, match="velocity must be"):
                tank.move(bad)
        for call, bad in ((tank.add_balls, -5), (tank.add_balls, 0), (tank.add_balls, 1.5), (tank.step, 0), (tank.step, -1),
                          (tank.reset, -1), (lambda seed: tank.scene("drop", seed=seed), 2.5)):
            with pytest.raises(ValueError, match="must be a whole number from"):
                call(bad)
        # Beyond the wire's uint32 counts and uint64 seed: FlatBuffers' TypeError otherwise.
        counts, seeds = "from 1 to 4294967295", "from 0 to 18446744073709551615"
        reset, scene = (lambda seed: tank.reset(seed=seed)), (lambda seed: tank.scene("drop", seed=seed))
        for call, bad, what, allowed in ((tank.add_balls, 2**32, "add_balls' n", counts),
                                         (tank.add_balls, 2**40, "add_balls' n", counts),
                                         (tank.step, 2**40, "step's n", counts),
                                         (reset, 2**64, "seed", seeds), (reset, 2**70, "seed", seeds),
                                         (scene, 2**64, "seed", seeds)):
            with pytest.raises(ValueError) as refused:
                call(bad)
            assert str(refused.value) == f"{what} must be a whole number {allowed}, got {bad}"
        # Nothing of the above reached the server: the refusal a time scale of 5 raises is its own.
        with pytest.raises(FishtankError) as refused:
            tank.time_scale(5)
        assert refused.value.code == "invalid_value" and "SetTimeScale" in refused.value.message
        assert tank.errors == [refused.value]


def test_a_scene_name_that_is_not_a_string_raises_value_error_naming_the_scenes_and_none_does_not_reset(start_server):
    server = start_server("--balls", "10")
    with Client("127.0.0.1", server.port) as tank:
        before = tank.snapshot().scene_start
        for bad in (5, None, b"drop"):
            with pytest.raises(ValueError) as refused:
                tank.scene(bad)
            assert str(refused.value) == ("scene's name must be a string (tank, wide, dam-break or drop), "
                                          f"got {bad!r}; reset() starts the running scene again")
        assert tank.pause().scene_start == before and tank.errors == []  # nothing reached the server


def test_every_call_after_close_raises_connection_error_this_client_was_closed(start_server):
    server = start_server("--balls", "10")
    player, observer = Client("127.0.0.1", server.port), Client("127.0.0.1", server.port, player=False)
    for tank in (player, observer):
        tank.snapshot()
        time.sleep(0.3)  # newer snapshots arrive: one waits to be taken, as it would for a call after close()
        tank.close()
        for call in (tank.snapshot, tank.wait_for_player, lambda: tank.move((1, 0, 0)), lambda: tank.add_balls(1),
                     tank.pause, tank.resume, tank.step, tank.reset, lambda: tank.scene("drop"),
                     lambda: tank.time_scale(0.5)):
            with pytest.raises(ConnectionError) as closed:
                call()
            assert str(closed.value) == "this client was closed"
        tank.close()  # again: nothing to do


def test_a_host_with_its_port_in_one_string_raises_cannot_connect_saying_to_give_the_port_second(monkeypatch):
    tried = []

    def unknown(address, timeout):  # what the resolver says of a name holding a port, without asking one
        tried.append(address)
        raise socket.gaierror(socket.EAI_NONAME, "Name or service not known")

    monkeypatch.setattr(socket, "create_connection", unknown)
    for host, alone, port in (("127.0.0.1:47110", "127.0.0.1", 47110), ("tank.example:7878", "tank.example", 7878),
                              ("[::1]:7878", "::1", 7878)):
        with pytest.raises(FishtankError) as joined:
            Client(host)
        assert joined.value.code == "cannot_connect"
        assert joined.value.message == (f"{host} is a host and a port in one string; give the port as the second "
                                        f'argument: Client("{alone}", {port})')
    assert tried == []  # refused before any look-up
    for host in ("::1", "[::1]", "fe80::1"):  # IPv6 literals end in a colon and digits too
        with pytest.raises(FishtankError, match="cannot resolve"):
            Client(host, 7878)
    assert [address[0] for address in tried] == ["::1", "::1", "fe80::1"]


def test_waiting_for_a_sphere_says_why_with_the_refusal_about_spheres_not_an_unrelated_later_one(start_server):
    server = start_server("--balls", "10", "--max-players", "0")
    with Client("127.0.0.1", server.port) as refused, Client("127.0.0.1", server.port, player=False) as watcher:
        for client, why in ((refused, " (player_limit: this server has no player spheres (--max-players 0); you are "
                                      "observing)"),
                            (watcher, ": it asked for none (Client(..., player=False))")):
            with pytest.raises(FishtankError) as unrelated:
                client.add_balls(1)  # observers may not add balls: the newest refusal
            assert unrelated.value.code == "not_permitted"
            with pytest.raises(FishtankError) as none:
                client.wait_for_player(timeout=10)
            assert none.value.code == "no_player"
            assert none.value.message == "this client is not in line for a player sphere" + why


def test_the_example_with_no_server_says_why_and_what_to_do_in_one_line_without_a_traceback():
    with socket.socket() as probe:  # a port just freed: nothing listens there
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    example = Path(__file__).resolve().parents[2] / "docs" / "examples" / "pile_height.py"
    run = subprocess.run([sys.executable, example, "--port", str(port), "--seconds", "1"], capture_output=True,
                         text=True, timeout=60, env={**os.environ, "MPLBACKEND": "Agg"})
    assert run.returncode == 1
    assert run.stderr.strip().splitlines() == [
        f"pile_height.py: cannot_connect: nothing listens at 127.0.0.1:{port} (connection refused); start a server "
        f"there with build/server/fishtank-server --port {port}, or use the port its 'listening on' line shows"]


def _example(*args):
    example = Path(__file__).resolve().parents[2] / "docs" / "examples" / "pile_height.py"
    return subprocess.run([sys.executable, example, *args], capture_output=True, text=True, timeout=60,
                          env={**os.environ, "MPLBACKEND": "Agg"})


def test_the_example_refuses_arguments_it_cannot_use_with_exit_2_before_connecting(tmp_path):
    with socket.socket() as probe:  # nothing listens there: an example that connected first would exit 1
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    missing = tmp_path / "missing"
    for args, words in ((["--seconds", "-2"], "argument --seconds: a positive number of seconds, got '-2'"),
                        (["--seconds", "nan"], "argument --seconds: a positive number of seconds, got 'nan'"),
                        (["--add", "-1"], "argument --add: a whole number from 0 to 4294967295, got '-1'"),
                        (["--out", str(missing / "x.png")], f"argument --out: the folder {missing} does not exist"),
                        (["--out", str(tmp_path)], f"argument --out: {tmp_path} is a folder; give a file in it"),
                        (["--out", str(tmp_path / "x.txt")], "argument --out: matplotlib cannot write .txt files")):
        run = _example("--port", str(port), *args)
        assert run.returncode == 2, (args, run.stderr)
        assert run.stderr.splitlines()[-1].startswith(f"pile_height.py: error: {words}"), run.stderr
    assert list(tmp_path.iterdir()) == [] and not missing.exists()


def test_the_example_measures_once_at_least_however_short_its_time(start_server, tmp_path):
    server = start_server("--balls", "10")
    run = _example("--port", str(server.port), "--seconds", "1e-9", "--out", str(tmp_path / "pile.png"))
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("1 measurements;") and (tmp_path / "pile.png").exists()


def test_a_host_name_that_does_not_resolve_raises_cannot_connect_saying_to_check_it(monkeypatch):
    def unknown(address, timeout):  # what the resolver says of an unknown name, without asking one
        raise socket.gaierror(socket.EAI_NONAME, "Name or service not known")

    monkeypatch.setattr(socket, "create_connection", unknown)
    with pytest.raises(FishtankError) as refused:
        Client("nohost.invalid", 7878)
    assert refused.value.code == "cannot_connect"
    assert refused.value.message == ("cannot resolve nohost.invalid: Name or service not known; check the host name, "
                                     "or give its IP address")


def test_a_peer_that_never_answers_raises_fishtank_error_timeout_with_the_address_in_time():
    with socket.socket() as silent:  # accepts connections (the kernel's backlog) and never says a word
        silent.bind(("127.0.0.1", 0))
        silent.listen()
        port = silent.getsockname()[1]
        started = time.monotonic()
        with pytest.raises(FishtankError) as waited:
            Client("127.0.0.1", port, timeout=0.5)
        assert time.monotonic() - started < 5
    assert waited.value.code == "timeout"
    assert f"127.0.0.1:{port}" in waited.value.message and "timeout=" in waited.value.message


def _foreign_server(*frames):
    """A server that is not ours: it sends these frames to the first peer, then waits for it to leave."""
    listener = socket.create_server(("127.0.0.1", 0))

    def serve():
        peer, _ = listener.accept()
        with peer:
            peer.sendall(b"".join(frames))
            while peer.recv(4096):
                pass
        listener.close()

    threading.Thread(target=serve, daemon=True).start()
    return listener.getsockname()[1]


def test_a_foreign_servers_bytes_that_are_not_utf8_arrive_escaped_not_as_a_decode_error():
    from fishtank.client import _frame
    from fishtank.wire import Error, Payload, Vec3f, Welcome

    def welcome(b):
        policy = b.CreateString(b"nobody \xff controls")
        Welcome.Start(b)
        Welcome.AddTankMin(b, Vec3f.CreateVec3f(b, -1, 0, -1))
        Welcome.AddTankMax(b, Vec3f.CreateVec3f(b, 1, 2, 1))
        Welcome.AddDt(b, 1e-3)
        Welcome.AddControlPolicy(b, policy)
        return Welcome.End(b)

    def error(b):
        message = b.CreateString(b"refused \xfe\xc3")
        Error.Start(b)
        Error.AddCode(b, 3)
        Error.AddMessage(b, message)
        return Error.End(b)

    with Client("127.0.0.1", _foreign_server(_frame(Payload.Payload.Welcome, welcome)), timeout=5) as c:
        assert c.control_policy == "nobody \\xff controls"
    with pytest.raises(FishtankError) as refused:  # an Error before the Welcome is raised by the constructor
        Client("127.0.0.1", _foreign_server(_frame(Payload.Payload.Error, error)), timeout=5)
    assert refused.value.message == "refused \\xfe\\xc3"


def test_add_balls_beyond_the_rate_limit_says_rate_limited_before_the_tank_is_full(start_server):
    server = start_server("--balls", "10")
    with Client("127.0.0.1", server.port) as tank:
        with pytest.raises(FishtankError) as limited:
            tank.add_balls(100000)
    assert limited.value.code == "rate_limited" and "added at most 3000 of 100000" in limited.value.message


def test_a_connection_the_server_ended_raises_its_reason_at_the_next_call_not_a_broken_pipe(start_server):
    server = start_server("--balls", "50", "--max-commands", "20")
    with Client("127.0.0.1", server.port) as tank:
        with pytest.raises(FishtankError) as flood:
            for _ in range(10000):  # far past 20 messages a second: the server closes it with command_flood
                tank.move((1, 0, 0))
        assert flood.value.code == "command_flood"
        time.sleep(2.5)  # the server's grace for its last word is over: the socket is gone, sends fail
        for _ in range(3):  # every later call, a send or a wait, says why the connection ended
            with pytest.raises(ConnectionError, match="closed the connection \\(command_flood: "):
                tank.move((1, 0, 0))
        with pytest.raises(ConnectionError, match="command_flood"):
            tank.snapshot()


def test_a_stopping_server_says_why_and_the_client_lets_go_without_making_it_wait(start_server):
    server = start_server("--balls", "50")
    with Client("127.0.0.1", server.port) as tank:
        tank.snapshot()
        time.sleep(0.2)  # snapshots arrive that no call takes: after the end, none of them is an answer
        server.process.send_signal(signal.SIGTERM)
        assert server.process.wait(timeout=10) == 0
        log = server.text()
        # The client closed its side on the server's end, so the server did not wait out its grace for it.
        assert "('fishtank-python') closed: disconnected" in log and "had not closed its side" not in log, log
        with pytest.raises(ConnectionError, match="server_stopping: the server is stopping: it was stopped"):
            tank.snapshot()
    server.stop()  # exited already: this removes its log


def test_a_program_that_reads_less_often_than_the_servers_idle_timeout_keeps_its_connection(start_server):
    """Snapshots the program has not asked for yet do not pile up in the sockets until the server gives up on
    the connection (a write stalled for --idle-timeout): the client reads them as they come."""
    server = start_server("--balls", "6000", "--idle-timeout", "2")
    with Client("127.0.0.1", server.port, player=False) as tank:
        tank.snapshot()
        time.sleep(10)  # a plot, a fit, a breakpoint
        later = tank.snapshot()
        with Client("127.0.0.1", server.port, player=False) as direct:
            behind = direct.snapshot().sim_time - later.sim_time
    assert behind < 1.0, f"the snapshot returned is {behind:.1f} s older than the server's newest"


def test_over_a_slow_link_the_server_paces_the_client_so_its_snapshots_stay_fresh(start_server):
    """The client acknowledges each snapshot as it arrives, so a link slower than the snapshots gets fewer of
    them, not a queue: 2000 balls are 12 kB a snapshot, 720 kB/s at 60 a second, through 100 kB/s."""
    server = start_server("--balls", "2000")
    link = fishtank_tools.SlowLink(server.port, 100_000)
    with Client("127.0.0.1", link.port, player=False) as slow, Client("127.0.0.1", server.port, player=False) as fast:
        deadline = time.monotonic() + 12
        while time.monotonic() < deadline:
            slow.snapshot()
        behind = fast.snapshot().sim_time - slow.snapshot().sim_time
    assert behind < 1.0, f"through 100 kB/s the newest snapshot is {behind:.1f} s behind the server's"


def test_the_assembled_package_is_readable_by_every_user():
    """Built by root (scripts/run), run by a student: no folder or file of it may be closed to others."""
    package = os.path.dirname(fishtank.__file__)
    for folder, _, files in os.walk(package):
        assert stat.S_IMODE(os.stat(folder).st_mode) & 0o005 == 0o005, f"{folder} is not open to other users"
        for name in files:
            path = os.path.join(folder, name)
            assert stat.S_IMODE(os.stat(path).st_mode) & 0o004, f"{path} is not readable by other users"
