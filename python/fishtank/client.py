"""A blocking client for fishtank-server's protocol (protocol/fishtank.fbs).

Frames are built and read in fishtank._frames, a script's arguments checked in
fishtank._arguments. The controls wait until a snapshot shows their effect, so a script reads
like the experiment it runs; a refusal from the server raises FishtankError.

A thread of the client's own reads the connection and answers each snapshot
with an Ack asking for the next in full (the client decodes no deltas), so the
server paces it by what its link carries, as it does a viewer, and a program
may take as long as it likes between calls: snapshot() returns the newest.
"""

import re
import socket
import struct
import threading
import time
from dataclasses import dataclass

import numpy as np

from fishtank._arguments import (_MAX_STEPS, _UINT32_MAX, _UINT64_MAX, _client_name, _seconds, _time_scale, _velocity,
                                 _whole_number)
from fishtank._frames import (_IDENTIFIER, _MAX_FRAME_BYTES, _ack_frame, _decimal, _frame, _hello_frame, _table,
                              _text, _vec, dequantize)
from fishtank.wire import (AddBalls, BallKinds, Error, ErrorCode, InLine, Message, Pause, Payload, Ping,
                           PlayerGranted, PlayerInput, Pong, Reset, SetTimeScale, Snapshot as WireSnapshot, Step,
                           Vec3f, Welcome)

_ERROR_NAMES = {value: name for name, value in vars(ErrorCode.ErrorCode).items() if not name.startswith("_")}
_SCENES = "tank, wide, dam-break or drop"
# "host:port" or "[v6]:port" in one string; an unbracketed IPv6 literal ("::1") has more than one colon.
_HOST_WITH_PORT = re.compile(r"\[([^\]]+)\]:(\d+)|([^:\[\]]+):(\d+)")


class FishtankError(RuntimeError):
    """The server refused something, or could not be reached.

    code is the protocol's ErrorCode name (e.g. "not_paused") for a refusal, "cannot_connect" when no
    connection could be made and "timeout" when the server did not answer in time; message says what
    to do about it.
    """

    def __init__(self, code, message):
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message


@dataclass
class Snapshot:
    """The world at one moment. Ball ids are 0 .. n-1 (ids[i] == i), kinds index Client.kinds."""

    positions: np.ndarray  # (n, 3) float32, metres, dequantised as the viewer does
    kinds: np.ndarray  # (n,) uint8
    ids: np.ndarray  # (n,) uint32
    player_ids: np.ndarray  # (p,) uint32
    player_positions: np.ndarray  # (p, 3) float32
    sim_time: float  # simulated seconds since the server started (a reset does not rewind it)
    physics_steps: int
    paused: bool
    scene: str
    scene_start: int  # +1 per scene (re)start
    time_scale: float  # achieved: simulated seconds per wall second
    time_scale_set: float  # asked for
    steps_per_s: float
    kinetic_energy_per_ball: float  # joules
    contacts: int
    max_overlap: float  # largest overlap, a fraction of the smaller radius; beyond 0.1 k is too soft
    tank_min: np.ndarray  # (3,) float32
    tank_max: np.ndarray


def _server_command(host, port):
    """The command that starts a server answering at host:port: it listens on 127.0.0.1 unless given --bind
    (common/server_hint.h says the same for the viewer)."""
    if host in ("127.0.0.1", "localhost"):
        bind = ""
    elif host == "::1":
        bind = " --bind ::1"
    else:
        bind = " --bind ::" if ":" in host else " --bind 0.0.0.0"
    return f"build/server/fishtank-server{bind} --port {port}"


class Client:
    """One connection to fishtank-server.

    player=True asks for a player sphere (move() needs one; under the server's
    default --control policy only clients with one may pause, step, reset,
    switch scene or set the time scale).
    """

    def __init__(self, host="127.0.0.1", port=7878, player=True, name="fishtank-python", timeout=10.0):
        # Checked here: the socket layer would wrap 70000 to another port, or fail in its own words.
        port = _whole_number(port, "port", 1, 65535)
        self.timeout = _seconds(timeout, "timeout")
        name = _client_name(name)
        # None would connect to this machine, bytes would be written as "b'...'" in every message.
        if not isinstance(host, str) or not host:
            raise ValueError(f'host must be a host name or an address as a string, e.g. "127.0.0.1", got {host!r}')
        # "[::1]" as the server's listening line and --connect write an IPv6 address; the socket wants "::1".
        if len(host) > 2 and host[0] == "[" and host[-1] == "]":
            host = host[1:-1]
        # Refused before any look-up, which would only say the name does not resolve.
        if joined := _HOST_WITH_PORT.fullmatch(host):
            alone, digits = (joined[1], joined[2]) if joined[1] else (joined[3], joined[4])
            raise FishtankError("cannot_connect", f"{host} is a host and a port in one string; give the port as "
                                f'the second argument: Client("{alone}", {int(digits)})')
        self._wants_player = bool(player)
        self.address = f"[{host}]:{port}" if ":" in host else f"{host}:{port}"
        self._sock = self._connect(host, port)
        self._sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        # What the reader thread writes, the caller reads under this; it is notified of every frame.
        self._changed = threading.Condition()
        self._send_lock = threading.Lock()  # the caller's frames and the reader's Acks
        self._kinds = np.zeros(0, dtype=np.uint8)  # replaced, never changed: a snapshot keeps the one it came with
        self._newest = None  # the newest snapshot received, not yet returned by snapshot(): (table, kinds)
        self._last = None  # the newest snapshot received
        self._received = 0  # snapshots received
        self._sequence = 0
        self._pong = None  # (its stamp, snapshots received before it)
        self._ended = None  # why the reader stopped, raised to the caller
        self._closing = False
        self.errors = []  # every FishtankError the server sent, oldest first
        self._unraised = []  # refusals not yet raised to the caller
        self.welcome = None
        self.ahead_in_line = None  # in line for a sphere: how many clients are before this one (InLine)
        # Not _send: its wait for the reader's reason would wait for a reader not started yet.
        self._send_frame(_hello_frame(name, player))
        self._reader = threading.Thread(target=self._read, name=f"fishtank reader {self.address}", daemon=True)
        self._reader.start()
        try:
            self._wait(lambda: self.welcome is not None, time.monotonic() + timeout)
        except BaseException:
            self.close()
            raise
        w = self.welcome  # player_id and may_control: the reader set them, and keeps them
        self.dt = w.Dt()
        self.steps_per_contact = w.StepsPerContact()  # contact duration of the lightest pair / dt
        self.tolerance = _decimal(w.Tolerance())  # the per-collision error dt was chosen for; 0: dt given
        self.control_policy = _text(w.ControlPolicy())
        self.kinds = [(w.BallKinds(k).Diameter(), w.BallKinds(k).Mass()) for k in range(w.BallKindsLength())]
        self._tank = (_vec(w.TankMin()), _vec(w.TankMax()))

    # ---- the API ----

    def snapshot(self):
        """The newest snapshot, waiting for one newer than the last returned if none has arrived."""
        return self._decode_snapshot(*self._wait(self._take_newest, time.monotonic() + self.timeout))

    def wait_for_player(self, timeout=None):
        """Waits until this client holds a player sphere and returns its id: at once where it has one, else once
        a sphere another client frees comes to it, first in line. Raises FishtankError "no_player" where it is
        not in line (it asked for none, or the server has none) and "timeout" where none came in time (default:
        the client's timeout)."""
        seconds = self.timeout if timeout is None else _seconds(timeout, "wait_for_player's timeout")

        def holds():
            # The refusal and the place in line come before any snapshot, so a snapshot without them means no line.
            if self.player_id is None and self.ahead_in_line is None and self._last is not None:
                raise FishtankError("no_player", self._not_in_line_text())
            return self.player_id is not None

        def no_sphere_came():
            if self.ahead_in_line is None:  # no word of the line yet: the server did not answer
                return self._timed_out()
            place = "next in line" if self.ahead_in_line == 0 else f"in line, {self.ahead_in_line} before it"
            return FishtankError("timeout", f"no player sphere came to this client within {seconds:g} s: it is "
                                 f"{place}, and no sphere was freed (one is when its client leaves, or leaves it "
                                 "unused for the server's --player-idle); give wait_for_player(timeout=) more "
                                 "seconds")

        self._wait(holds, time.monotonic() + seconds, no_sphere_came)
        return self.player_id

    def move(self, velocity):
        """Sets the player sphere's velocity (metres per second, x y z); it keeps it until the next move()."""
        self._check_open()  # before the sphere: a closed client says it is closed
        if self.player_id is None:  # the reader takes a sphere freed by another (PlayerGranted) as it comes
            freed = next((e for e in reversed(self.errors) if e.code == "player_idle"), None)
            raise FishtankError("no_player",
                                "this client has no player sphere to move" + (f" ({freed})" if freed else ""))
        # Checked here, not refused by the server later: move() does not wait, so a refusal would be raised
        # by whichever call came next.
        x, y, z = _velocity(velocity)
        self._sequence += 1

        def build(b):
            PlayerInput.Start(b)
            PlayerInput.AddSequence(b, self._sequence)
            PlayerInput.AddVelocity(b, Vec3f.CreateVec3f(b, x, y, z))
            return PlayerInput.End(b)

        self._send(_frame(Payload.Payload.PlayerInput, build))
        self._check_refusals()

    def add_balls(self, n):
        """Asks the server to pour n more balls in from the top; raises FishtankError if it took fewer."""
        n = _whole_number(n, "add_balls' n", 1, _UINT32_MAX)
        self._send(_frame(Payload.Payload.AddBalls, lambda b: _table(b, AddBalls, AddCount=n)))
        self._round_trip()

    def pause(self):
        """Pauses the simulation for everyone and waits until a snapshot shows it."""
        return self._control(_frame(Payload.Payload.Pause, lambda b: _table(b, Pause, AddPaused=True)),
                             lambda s: s.paused)

    def resume(self):
        return self._control(_frame(Payload.Payload.Pause, lambda b: _table(b, Pause, AddPaused=False)),
                             lambda s: not s.paused)

    def step(self, n=1):
        """Runs n steps while paused and returns the snapshot taken once they are done. The timeout counts from
        the last snapshot that showed steps done: a long step takes as long as its steps need."""
        n = _whole_number(n, "step's n", 1, _MAX_STEPS)
        before = self._current().physics_steps

        def steps_done(s):
            return (s.physics_steps - before) % 2**32

        return self._control(_frame(Payload.Payload.Step, lambda b: _table(b, Step, AddCount=n)),
                             lambda s: steps_done(s) >= n, progress=steps_done)

    def reset(self, seed=None):
        """Starts the running scene again (with this seed, or the scene's last) and returns its first snapshot."""
        return self._restart(None, seed)

    def scene(self, name, seed=None):
        """Switches everyone to the named scene (tank, wide, dam-break, drop) and returns its first snapshot."""
        # None would send no name, which the server takes as the running scene: that is reset()'s job.
        if not isinstance(name, str):
            raise ValueError(f"scene's name must be a string ({_SCENES}), got {name!r}; reset() starts the "
                             "running scene again")
        return self._restart(name, seed)

    def time_scale(self, scale):
        """Asks for simulated seconds per wall second, 0.1 .. 1, and waits until a snapshot shows it asked for."""
        scale = _time_scale(scale)
        return self._control(_frame(Payload.Payload.SetTimeScale,
                                    lambda b: _table(b, SetTimeScale, AddScale=scale)),
                             lambda s: s.time_scale_set == _decimal(scale))

    def close(self):
        self._closing = True
        try:
            self._sock.shutdown(socket.SHUT_RDWR)  # wakes the reader: a close alone may leave it in recv()
        except OSError:
            pass  # the server closed it already
        self._sock.close()
        self._reader.join(self.timeout)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # ---- connecting ----

    def _connect(self, host, port):
        try:
            return socket.create_connection((host, port), timeout=self.timeout)
        except ConnectionRefusedError:
            raise FishtankError("cannot_connect", f"nothing listens at {self.address} (connection refused); start a "
                                f"server there with {_server_command(host, port)}, or use the port "
                                "its 'listening on' line shows") from None
        except socket.gaierror as e:
            raise FishtankError("cannot_connect", f"cannot resolve {host}: {e.strerror or e}; check the host name, "
                                "or give its IP address") from None
        except TimeoutError:
            raise FishtankError("timeout", f"no answer from {self.address} within {self.timeout:g} s; check "
                                "the address, and that a server on another machine was started with "
                                "--bind 0.0.0.0") from None
        except OSError as e:
            raise FishtankError("cannot_connect", f"cannot connect to {self.address}: {e.strerror or e}") from None

    # ---- sending ----

    def _restart(self, name, seed):
        seed = None if seed is None else _whole_number(seed, "seed", 0, _UINT64_MAX)
        before = self._current().scene_start

        def build(b):
            text = b.CreateString(name) if name is not None else None
            Reset.Start(b)
            if text is not None:
                Reset.AddScene(b, text)
            if seed is not None:
                Reset.AddSeed(b, seed)
            return Reset.End(b)

        return self._control(_frame(Payload.Payload.Reset, build), lambda s: s.scene_start != before)

    def _control(self, frame, done, progress=None):
        """Sends a control and returns the first snapshot after it that satisfies done. Its refusal is raised
        here, not by a later call: the round trip waits for it where done holds without the control (a resume
        while running, a step's count run by a running simulation)."""
        self._send(frame)
        self._round_trip()
        return self._wait_for(done, progress)

    def _send(self, frame):
        """Sends for the caller: a connection that has ended raises why it ended (the server's last Error), not
        a bare broken pipe, and not only from the second send after it."""
        self._check_open()  # the socket is gone: a send would fail with a bad file descriptor
        with self._changed:
            self._raise_ended()
        try:
            self._send_frame(frame)
            return
        except TimeoutError:
            raise self._timed_out() from None
        except OSError as e:
            failure = e
        with self._changed:  # the reader is about to learn why (the server's farewell, or the reset)
            if self._changed.wait_for(lambda: self._ended is not None, timeout=1.0):
                self._raise_ended()
        raise ConnectionError(f"the connection to {self.address} failed: {failure.strerror or failure}")

    def _send_frame(self, frame):
        with self._send_lock:
            self._sock.sendall(frame)

    # ---- receiving: the caller's side ----

    def _wait(self, ready, deadline, timed_out=None):
        """Waits until ready() (called under the lock) returns something true, and returns that; raises why the
        connection ended, or at the deadline timed_out() (under the lock), by default FishtankError "timeout"."""
        with self._changed:
            while True:
                self._check_open()  # what arrived before close() is not an answer to a later call
                self._raise_ended()  # nor what arrived before the connection ended: a snapshot not yet taken
                value = ready()
                if value:
                    return value
                left = deadline - time.monotonic()
                if left <= 0:
                    raise (timed_out or self._timed_out)()
                self._changed.wait(left)

    def _take_newest(self):
        s, self._newest = self._newest, None
        return s

    def _raise_refusal(self):
        """Raises the oldest refusal not raised yet, forgetting any after it (under the lock): each call waits for
        the refusals of what it sent, so those after it answered the same call (an AddBalls' rate_limited, then
        its tank_full); all are in errors."""
        if self._unraised:
            error = self._unraised[0]
            self._unraised.clear()
            raise error

    def _take_refusal_or_newest(self):
        self._raise_refusal()
        return self._take_newest()

    def _current(self):
        """The newest snapshot received so far."""
        if self._last is None:
            self.snapshot()
        return self._decode_snapshot(*self._last)

    def _wait_for(self, done, progress=None):
        """Waits for a snapshot that satisfies done (returned), or a refusal from the server (FishtankError).
        Where progress(snapshot) changes, the timeout counts again from that snapshot."""
        deadline = time.monotonic() + self.timeout
        last = None
        while True:
            s = self._decode_snapshot(*self._wait(self._take_refusal_or_newest, deadline))
            if done(s):
                return s
            if progress and (now := progress(s)) != last:
                last, deadline = now, time.monotonic() + self.timeout

    def _round_trip(self):
        """Waits for a Pong, so that any immediate refusal of what was sent before has arrived."""
        stamp = int(time.monotonic() * 1e6) % 2**32
        self._send(_frame(Payload.Payload.Ping, lambda b: _table(b, Ping, AddClientTimeUs=stamp)))
        deadline = time.monotonic() + self.timeout
        _, before = self._wait(lambda: self._pong if self._pong and self._pong[0] == stamp else None, deadline)
        # A physics-thread answer (AddBalls' tank_full, Step's not_paused, Reset's superseded) is posted to the
        # session before any snapshot published after the command was applied (physics_link.cpp), and a session
        # writes its replies before its snapshot (session.cpp). The second snapshot after the Pong was offered
        # after the first went out, after the Pong: surely later than that.
        self._wait(lambda: self._received >= before + 2, deadline)
        with self._changed:
            self._take_newest()
        self._check_refusals()

    def _check_refusals(self):
        with self._changed:
            self._raise_refusal()
            self._raise_ended()

    def _raise_ended(self):
        """Where the connection has ended (under the lock): its last refusal first, if not raised yet (the code
        that ended it, as FishtankError), then why it ended, at every later call."""
        if self._ended is not None:
            self._raise_refusal()
            raise self._ended

    # ---- receiving: the reader thread ----

    def _read(self):
        """Reads frames until the connection ends, then leaves why in _ended for the caller."""
        buffer = bytearray()
        try:
            while True:
                try:
                    chunk = self._sock.recv(1 << 20)
                except TimeoutError:  # the caller's waits have deadlines of their own
                    continue
                if not chunk:  # the frames before it, handled on this thread, hold any reason the server gave
                    self._let_go()
                    raise ConnectionError("the server closed the connection" + self._last_error_text())
                buffer += chunk
                while (frame := self._next_frame(buffer)) is not None:
                    tick = self._handle(Message.Message.GetRootAs(frame, 4))
                    if tick is not None:
                        self._acknowledge(tick)
        except Exception as e:  # noqa: BLE001  (whatever ended it is the caller's to see)
            if self._closing:
                e = ConnectionError("this client was closed")
            elif isinstance(e, OSError) and not isinstance(e, ConnectionError):
                e = ConnectionError(f"the connection to {self.address} failed: {e.strerror or e}")
            with self._changed:
                self._ended = e
                self._changed.notify_all()

    def _let_go(self):
        """Ends this side too: the server waits for it (a grace) before its socket, and a stopping server's
        process, let go."""
        try:
            self._sock.shutdown(socket.SHUT_WR)
        except OSError:
            pass  # already gone

    def _acknowledge(self, tick):
        """Ack with want_keyframe: this client holds no base to decode a delta against, so the next comes in full."""
        try:
            self._send_frame(_ack_frame(tick, want_keyframe=True))
        except OSError:
            pass  # the server closed the connection: the frames before that say why, and then recv() ends

    def _timed_out(self):
        return FishtankError("timeout", f"no answer from the server at {self.address} within {self.timeout:g} s; "
                             "it may be stopped or overloaded (its status line says which), or give "
                             "Client(..., timeout=) more seconds")

    def _last_error_text(self):
        return f" ({self.errors[-1]})" if self.errors else ""

    def _check_open(self):
        if self._closing:
            raise ConnectionError("this client was closed")

    def _not_in_line_text(self):
        """Why this client has no sphere and waits for none: only the refusals about spheres say why."""
        if not self._wants_player:
            return "this client is not in line for a player sphere: it asked for none (Client(..., player=False))"
        reason = next((e for e in reversed(self.errors) if e.code in ("player_limit", "player_idle")), None)
        return "this client is not in line for a player sphere" + (f" ({reason})" if reason else "")

    def _next_frame(self, buffer):
        """_split_frame, where a peer that answers the Hello with no Fishtank frame is not a server to talk to."""
        try:
            return self._split_frame(buffer)
        except ConnectionError:
            if self.welcome is not None:  # a fault after the handshake: the connection ended, not the wrong peer
                raise
            said = bytes(buffer[:48]).splitlines()[0] if buffer else b""
            raise FishtankError("cannot_connect", f"the peer at {self.address} does not speak Fishtank's protocol "
                                f"(it sent {repr(said)[1:]}); check the port: the server's 'listening on' line "
                                "shows it") from None

    @staticmethod
    def _split_frame(buffer):
        """Takes one complete frame off the front of the buffer; None when none is complete."""
        if len(buffer) < 4:
            return None
        (length,) = struct.unpack_from("<I", buffer)
        if length < 8 or length > _MAX_FRAME_BYTES:
            raise ConnectionError(f"frame length {length} is outside 8 .. {_MAX_FRAME_BYTES} bytes")
        if len(buffer) < 4 + length:
            return None
        frame = bytes(buffer[: 4 + length])
        if frame[8:12] != _IDENTIFIER:  # left in the buffer: what the peer sent tells what it is
            raise ConnectionError("not a Fishtank frame (file identifier is not FTNK)")
        del buffer[: 4 + length]
        return frame

    def _handle(self, m):
        """Takes one frame in, under the lock, and wakes the caller; returns a snapshot's tick, to acknowledge."""
        kind = m.PayloadType()
        table = m.Payload()
        if table is None:
            return None
        tick = None
        with self._changed:
            if kind == Payload.Payload.Welcome:
                self.welcome = Welcome.Welcome()
                self.welcome.Init(table.Bytes, table.Pos)
                self.player_id = self.welcome.PlayerId() if self.welcome.HasPlayer() else None
                self.may_control = self.welcome.MayControl()
            elif kind == Payload.Payload.BallKinds:
                k = BallKinds.BallKinds()
                k.Init(table.Bytes, table.Pos)
                first = k.FirstNewBall()
                if first > len(self._kinds):
                    raise ConnectionError("the server skipped ball kinds")
                # Earlier than the kinds known: a scene started again, ids restart.
                self._kinds = np.concatenate([self._kinds[:first], k.KindsAsNumpy()]).astype(np.uint8)
            elif kind == Payload.Payload.Snapshot:
                s = WireSnapshot.Snapshot()
                s.Init(table.Bytes, table.Pos)
                # Decoded when the caller takes it: most are replaced by a newer one before that.
                self._newest = self._last = (s, self._kinds)
                self._received += 1
                tick = s.Tick()
            elif kind == Payload.Payload.Error:
                e = Error.Error()
                e.Init(table.Bytes, table.Pos)
                error = FishtankError(_ERROR_NAMES.get(e.Code(), str(e.Code())), _text(e.Message()))
                self.errors.append(error)
                if self.welcome is None:
                    raise error
                if error.code == "player_idle":  # the sphere was freed; the client observes
                    self.player_id = None
                    self.may_control = self.welcome.ObserversMayControl()
                # player_limit and player_idle say this client observes (in line, or its sphere freed) and
                # refuse nothing asked: raised by the next call they would pass for its refusal; move() and
                # wait_for_player() say them. server_stopping: the ConnectionError of every later call carries it.
                if error.code not in ("player_limit", "player_idle", "server_stopping"):
                    self._unraised.append(error)
            elif kind == Payload.Payload.PlayerGranted:
                g = PlayerGranted.PlayerGranted()
                g.Init(table.Bytes, table.Pos)
                self.player_id = g.PlayerId()
                self.may_control = g.MayControl()
                self.ahead_in_line = None
            elif kind == Payload.Payload.InLine:
                line = InLine.InLine()
                line.Init(table.Bytes, table.Pos)
                self.ahead_in_line = line.Ahead()
            elif kind == Payload.Payload.Pong:
                p = Pong.Pong()
                p.Init(table.Bytes, table.Pos)
                self._pong = (p.ClientTimeUs(), self._received)
            self._changed.notify_all()
        return tick

    def _decode_snapshot(self, s, kinds):
        n = s.BallCount()
        lo, hi = (_vec(s.TankMin()), _vec(s.TankMax())) if s.TankMin() is not None else self._tank
        q = s.PositionsAsNumpy() if n else np.zeros(0, dtype=np.uint16)
        if len(q) != 3 * n or len(kinds) < n:
            raise ConnectionError("a snapshot's positions or kinds do not match its ball count")
        players = s.PlayerPositionsLength()
        return Snapshot(
            positions=dequantize(q.reshape(n, 3), lo, hi),
            kinds=kinds[:n].copy(),
            ids=np.arange(n, dtype=np.uint32),
            player_ids=s.PlayerIdsAsNumpy().astype(np.uint32) if players else np.zeros(0, dtype=np.uint32),
            player_positions=np.array([_vec(s.PlayerPositions(i)) for i in range(players)],
                                      dtype=np.float32).reshape(players, 3),
            sim_time=s.SimTime(),
            physics_steps=s.PhysicsSteps(),
            paused=s.Paused(),
            scene=_text(s.Scene()),
            scene_start=s.SceneStart(),
            time_scale=_decimal(s.TimeScale()),
            time_scale_set=_decimal(s.TimeScaleSet()),
            steps_per_s=s.StepsPerS(),
            kinetic_energy_per_ball=s.KineticEnergyPerBall(),
            contacts=s.Contacts(),
            max_overlap=s.MaxOverlap(),
            tank_min=lo,
            tank_max=hi,
        )
