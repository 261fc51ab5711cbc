"""The Python client against a real server: snapshots come out as numpy arrays
that agree with the server's own state; the controls do what they say
(pause holds, step runs exactly N, the same seed restarts the same run bit for
bit, a time scale of one half halves the pace); refusals raise FishtankError
and leave the connection working."""

import os
import re
import signal
import socket
import stat
import subprocess
import sys
import threading
import time
import warnings
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


def test_the_documented_bound_on_positions_holds_for_the_worst_rounding_in_the_40_m_tank():
    """Quantised as the server does (protocol/quantize.h, in float32) and dequantised by the client, positions
    just either side of the midpoints between two quanta: half a step, plus float32 rounding."""
    docs = (Path(__file__).resolve().parents[2] / "docs" / "python-client.md").read_text()
    bound = float(re.search(r"within\s+([0-9.]+)\s+m\s+of\s+the\s+server's\s+own\s+value", docs)[1])
    worst = 0.0
    for lo, hi in ((np.float32(-20), np.float32(20)), (np.float32(0), np.float32(40))):  # x and z, y
        k = np.arange(65535, dtype=np.float64)
        v = np.concatenate([lo + (k + 0.5) * ((float(hi) - lo) / 65535) + d for d in (-1e-6, 0, 1e-6)])
        v = v.astype(np.float32)
        t = np.clip((v - lo) / (hi - lo), np.float32(0), np.float32(1))
        q = (t * np.float32(65535) + np.float32(0.5)).astype(np.uint16)
        worst = max(worst, float(np.max(np.abs(fishtank.client.dequantize(q, lo, hi).astype(np.float64) - v))))
    assert 40 / 65535 / 2 < worst <= bound, (worst, bound)


def test_the_welcome_says_how_dt_was_chosen_from_the_tolerance_or_given(start_server):
    with Client("127.0.0.1", start_server("--balls", "10").port) as tank:
        assert tank.tolerance == 0.005  # as given, not the float32 widened (0.004999999888241291)
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
        # The server answered (the client is in line): no sphere was freed in the time asked for.
        assert not_yet.value.message.startswith("no player sphere came to this client within 0.5 s: it is next in "
                                                "line, and no sphere was freed"), not_yet.value.message
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


def test_a_sphere_freed_for_idleness_takes_control_as_the_servers_policy_does_and_raises_nothing_itself(
        start_server):
    for policy, may in (("players", False), ("everyone", True)):
        server = start_server("--balls", "10", "--player-idle", "0.5", "--control", policy)
        with Client("127.0.0.1", server.port) as idle:
            assert idle.may_control
            deadline = time.monotonic() + 10
            while idle.player_id is not None and time.monotonic() < deadline:
                idle.snapshot()
            assert idle.player_id is None and [e.code for e in idle.errors] == ["player_idle"]
            assert idle.may_control is may, policy
            if may:
                assert idle.pause().paused  # the server lets it: player_idle is not raised in its place
            else:
                with pytest.raises(FishtankError) as refused:
                    idle.pause()
                assert refused.value.code == "not_permitted"  # the server's answer, not the player_idle before it
            with pytest.raises(FishtankError) as none:
                idle.move((1, 0, 0))
            assert none.value.code == "no_player" and "(player_idle: your player sphere did not move, and you sent no control" in \
                none.value.message


def test_a_step_longer_than_the_timeout_returns_once_done_as_long_as_its_steps_keep_coming(start_server):
    server = start_server("--balls", "1000")
    with Client("127.0.0.1", server.port) as tank:
        paused = tank.pause()
        tank.timeout = 1  # for the step alone: the connection and the pause had the default
        started = time.monotonic()
        stepped = tank.step(100_000)  # seconds of stepping, each snapshot showing more steps done
        took = time.monotonic() - started
        assert stepped.physics_steps == (paused.physics_steps + 100_000) % 2**32
        assert stepped.paused
        if took <= 1:
            pytest.skip(f"100000 steps of 1000 balls took {took:.2f} s, within the timeout: nothing to show here")


def test_refusals_raise_with_the_servers_reason_and_the_connection_keeps_working(start_server):
    server = start_server("--balls", "50")
    with Client("127.0.0.1", server.port) as tank, Client("127.0.0.1", server.port, player=False) as observer:
        with pytest.raises(FishtankError) as running:
            tank.step(5)
        assert running.value.code == "not_paused"
        with pytest.raises(FishtankError) as unknown:
            tank.scene("cube")
        assert unknown.value.code == "invalid_value" and "tank, wide, dam-break and drop" in unknown.value.message
        with pytest.raises(FishtankError) as many:
            tank.add_balls(100_001)  # the server's limit, not the wire's
        assert many.value.code == "invalid_value" and "AddBalls.count must be between 1 and 100000" in \
            many.value.message
        assert not observer.may_control and "observers may not" in observer.control_policy
        with pytest.raises(FishtankError) as refused:
            observer.pause()
        assert refused.value.code == "not_permitted"
        assert not tank.snapshot().paused and observer.snapshot().scene == "tank"


def test_a_control_refused_where_what_it_asks_for_holds_already_raises_its_own_refusal_not_the_next_call(
        start_server):
    server = start_server("--balls", "50")
    with Client("127.0.0.1", server.port) as tank, Client("127.0.0.1", server.port, player=False) as observer:
        for call, payload in ((observer.resume, "Pause"), (lambda: observer.time_scale(1), "SetTimeScale"),
                              (tank.pause, None), (observer.pause, "Pause"), (lambda: observer.step(1), "Step"),
                              (observer.reset, "Reset"), (tank.resume, None), (observer.resume, "Pause")):
            if payload is None:  # the player's own control, allowed: it raises nothing left by the observer's
                call()
                continue
            with pytest.raises(FishtankError) as refused:
                call()
            assert refused.value.code == "not_permitted" and refused.value.message.startswith(f"{payload} refused")
        assert [e.code for e in observer.errors] == ["not_permitted"] * 6 and tank.errors == []


def test_step_while_running_raises_not_paused_itself_though_a_snapshot_under_way_shows_the_steps_run(start_server):
    """Over a link slower than the snapshots one is under way when the Step goes out: it shows more steps than
    asked for, run by the running simulation, and arrives before the refusal."""
    server = start_server("--scene", "drop", "--balls", "500")
    link = fishtank_tools.SlowLink(server.port, 100_000)
    with Client("127.0.0.1", link.port) as tank:
        tank.snapshot()
        for _ in range(10):
            with pytest.raises(FishtankError) as running:
                tank.step(1)
            assert running.value.code == "not_paused"
        assert tank.pause().paused and [e.code for e in tank.errors] == ["not_paused"] * 10


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
    for timeout in (0, -1, float("inf"), 1e300, float("nan"), True, "5", None):
        with pytest.raises(ValueError) as refused:  # inf and 1e300: OverflowError in the socket's words before
            Client("127.0.0.1", 7878, timeout=timeout)
        assert str(refused.value) == ("timeout must be a positive number of seconds, at most 9223372036, got "
                                      f"{timeout!r}")
    with socket.socket() as probe:  # a port just freed: a timeout that passes the check gets as far as connecting
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    for timeout in (np.float32(5), np.int64(3), 0.5):
        with pytest.raises(FishtankError, match="connection refused"):
            Client("127.0.0.1", port, timeout=timeout)


def test_a_name_or_host_the_hello_cannot_carry_is_refused_before_connecting_and_a_name_of_64_bytes_is_not(
        start_server, monkeypatch):
    server = start_server("--balls", "10")
    with Client("127.0.0.1", server.port, name="\u00e9" * 32) as longest:  # 64 bytes in UTF-8: the server's limit
        assert longest.snapshot().scene == "tank"
    tried = []
    monkeypatch.setattr(socket, "create_connection", lambda address, timeout: tried.append(address))
    for name, words in ((None, "name must be a string of at most 64 bytes in UTF-8, got None"),
                        (5, "name must be a string of at most 64 bytes in UTF-8, got 5"),
                        (b"probe", "name must be a string of at most 64 bytes in UTF-8, got b'probe'"),
                        ("x" * 65, "name must be at most 64 bytes in UTF-8 (the server's limit), got 65 bytes"),
                        ("\u00e9" * 33, "name must be at most 64 bytes in UTF-8 (the server's limit), got 66 bytes"),
                        ("\ud800", "name must be text UTF-8 can encode")):
        with pytest.raises(ValueError) as refused:
            Client("127.0.0.1", server.port, name=name)
        assert str(refused.value).startswith(words)
    for host in (None, b"127.0.0.1", 127, ""):
        with pytest.raises(ValueError) as refused:
            Client(host, server.port)
        assert str(refused.value) == ('host must be a host name or an address as a string, e.g. "127.0.0.1", '
                                      f"got {host!r}")
    assert tried == []


def test_arguments_the_wire_cannot_carry_raise_value_error_at_once_and_the_next_refusal_is_the_right_one(
        start_server):
    server = start_server("--balls", "100")
    with Client("127.0.0.1", server.port) as tank:
        for bad in ((1, 2), "abc", "123", b"123", {1: 1, 2: 2, 3: 3}, {0, 1, 2}, (True, 0, 0), ("1", 0, 0),
                    np.zeros((1, 3)), np.array(["1", "2", "3"]), (1j, 0, 0)):
            with pytest.raises(ValueError) as refused:  # a string or a mapping passed as its characters or keys
                tank.move(bad)
            assert str(refused.value) == ("velocity must be three numbers (x, y, z) in m/s, as a tuple, list or "
                                          f"numpy array, got {bad!r}")
        for bad in ((float("nan"), 0, 0), (0, float("inf"), 0), (1e40, 0, 0), (0, 0, -10**400)):
            with pytest.raises(ValueError) as refused:  # beyond float32: FlatBuffers' OverflowError
                tank.move(bad)
            assert str(refused.value) == f"velocity must be finite, within a float32's range (3.4e38), got {bad!r}"
        for good in ([0, 0, 0], np.array([0.0, 0.0, 0.0]), (np.float32(0), np.int64(0), 0.0)):
            tank.move(good)
        tank.move((0, 0, 0))
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # numpy's overflow warning for 1e40 too
            for bad in (None, "abc", "0.5", True, 1e40, float("nan"), float("inf"), 0.05, 5, 1.0000001,
                        np.float64(1.0000001)):
                with pytest.raises(ValueError) as refused:
                    tank.time_scale(bad)
                assert str(refused.value) == ("time_scale's scale must be a number from 0.1 to 1 (simulated seconds "
                                              f"per wall second), got {bad!r}")
        for bad in (0, True, float("inf"), "1"):
            with pytest.raises(ValueError) as refused:
                tank.wait_for_player(timeout=bad)
            assert str(refused.value) == ("wait_for_player's timeout must be a positive number of seconds, at most "
                                          f"9223372036, got {bad!r}")
        # What the server takes is what it receives, a float32: 0.0999999999 arrives as 0.1, its lowest.
        for good, arrives in ((0.0999999999, 0.1), (np.float32(0.5), 0.5), (1, 1.0)):
            assert tank.time_scale(good).time_scale_set == arrives
        for call, bad in ((tank.add_balls, -5), (tank.add_balls, 0), (tank.add_balls, 1.5), (tank.step, 0), (tank.step, -1),
                          (tank.reset, -1), (lambda seed: tank.scene("drop", seed=seed), 2.5)):
            with pytest.raises(ValueError, match="must be a whole number from"):
                call(bad)
        # Beyond the wire's uint32 counts and uint64 seed: FlatBuffers' TypeError otherwise.
        counts, seeds = "from 1 to 4294967295", "from 0 to 18446744073709551615"
        reset, scene = (lambda seed: tank.reset(seed=seed)), (lambda seed: tank.scene("drop", seed=seed))
        for call, bad, what, allowed in ((tank.add_balls, 2**32, "add_balls' n", counts),
                                         (tank.add_balls, 2**40, "add_balls' n", counts),
                                         (tank.step, 100_001, "step's n", "from 1 to 100000"),  # the server's
                                         (tank.step, 2**40, "step's n", "from 1 to 100000"),
                                         (reset, 2**64, "seed", seeds), (reset, 2**70, "seed", seeds),
                                         (scene, 2**64, "seed", seeds)):
            with pytest.raises(ValueError) as refused:
                call(bad)
            assert str(refused.value) == f"{what} must be a whole number {allowed}, got {bad}"
        # Nothing of the above reached the server: the refusal an unknown scene raises is its own.
        with pytest.raises(FishtankError) as refused:
            tank.scene("cube")
        assert refused.value.code == "invalid_value" and "unknown scene 'cube'" in refused.value.message
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


def test_the_example_resumes_a_simulation_left_paused_and_says_so(start_server, tmp_path):
    server = start_server("--balls", "10")
    with Client("127.0.0.1", server.port) as other:
        other.pause()
    run = _example("--port", str(server.port), "--seconds", "1", "--out", str(tmp_path / "pile.png"))
    assert run.returncode == 0, run.stderr
    assert run.stderr.splitlines() == ["pile_height.py: the simulation was paused; resuming it to measure"]
    balls = int(re.search(r"with (\d+) balls", run.stdout)[1])
    assert balls > 0, run.stdout  # paused, none poured in
    with Client("127.0.0.1", server.port, player=False) as after:
        assert not after.snapshot().paused


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


def test_a_peer_that_does_not_speak_fishtank_raises_cannot_connect_saying_to_check_the_port():
    for answer, first_line in ((b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n", "HTTP/1.1 400 Bad Request"),
                               (b"SSH-2.0-OpenSSH_9.2\r\n", "SSH-2.0-OpenSSH_9.2"),
                               (b"\x10\x00\x00\x00" + bytes(16), "\\x10\\x00\\x00\\x00" + "\\x00" * 16)):
        port = _foreign_server(answer)
        with pytest.raises(FishtankError) as foreign:
            Client("127.0.0.1", port, timeout=5)
        assert foreign.value.code == "cannot_connect"
        assert foreign.value.message == (f"the peer at 127.0.0.1:{port} does not speak Fishtank's protocol (it sent "
                                         f"'{first_line}'); check the port: the server's 'listening on' line shows it")


def test_a_framing_fault_after_the_welcome_ends_the_connection_as_before():
    from fishtank.client import _frame
    from fishtank.wire import Payload, Vec3f, Welcome

    def welcome(b):
        Welcome.Start(b)
        Welcome.AddTankMin(b, Vec3f.CreateVec3f(b, -1, 0, -1))
        Welcome.AddTankMax(b, Vec3f.CreateVec3f(b, 1, 2, 1))
        Welcome.AddDt(b, 1e-3)
        return Welcome.End(b)

    with pytest.raises(ConnectionError, match="frame length 1347703880 is outside 8 .. 67108864 bytes"):
        with Client("127.0.0.1", _foreign_server(_frame(Payload.Payload.Welcome, welcome), b"HTTP/1.1 400 "),
                     timeout=5) as c:  # the constructor raises it where the reader got there first
            c.snapshot()


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
