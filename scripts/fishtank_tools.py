#!/usr/bin/env python3
"""What the scripts share, defined once:

  Server        starts a fishtank-server, reads the port from its 'listening on'
                line (and the web viewer's from 'web viewer on'), stops it;
  SlowLink      a TCP proxy that carries a server's bytes at a set rate;
  variants()    the builds compared side by side and the flags each runs with;
  bench()       one --bench run of a variant, with the load average around it;
  interleaved() the order of interleaved rounds; spread() and round_ratios(),
                the per-round summaries (median, min, max over the rounds);
  machine()     what a figure was measured on: CPU, cores, date, commit.

The Python scripts import it; so does tests/python/server_process.py. As a
program (for the bash scripts):

  scripts/fishtank_tools.py listening LOG [--pid PID] [--timeout S]
      waits until the server writing LOG prints its 'listening on' line, then
      prints ADDRESS:PORT and, on a second line, the web viewer's URL (empty
      without one). Exit status 1: no line within S seconds (default 30; 0:
      as long as PID lives); 3: process PID ended first (scripts/run then
      shows the log).
  scripts/fishtank_tools.py variants   the variants of this machine, one per line
  scripts/fishtank_tools.py machine    the machine line a figure is headed with"""
import argparse
import collections
import csv
import dataclasses
import json
import math
import os
import re
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIGURES = os.path.join(ROOT, "docs", "figures")

# ------------------------------------------------------------------ the server

LISTENING = re.compile(r"^listening on (\S+):(\d+)$", re.M)
WEB = re.compile(r"^web viewer on (http://(\S+):(\d+)/)$", re.M)
STATUS = re.compile(r"balls\s+(\d+) \(\+(\d+) queued\)\s+(\d+) steps/s")
NETWORK_STATUS = re.compile(r"out ([\d.]+) MB/s\s+net cpu ([\d.]+) %.*snapshot (\d+) us to encode, "
                            r"([\d.]+) frames of (\d+) B mean")
# The web line follows the listening line at once; where none has come by then, the server has no web viewer.
WEB_LINE_GRACE_S = 0.5

Listening = collections.namedtuple("Listening", "host port web_url web_port")


def parse_listening(text):
    """The server's addresses from its log, or None before its 'listening on' line."""
    found = LISTENING.search(text)
    if not found:
        return None
    web = WEB.search(text)
    return Listening(found[1], int(found[2]), web[1] if web else None, int(web[3]) if web else None)


def wait_listening(read, alive, timeout, web=None):
    """Polls read() (the log so far) until the listening line, and the web line where web is True (None: where
    one comes within WEB_LINE_GRACE_S). Returns the Listening, or None when alive() turns false or the timeout
    (seconds; None: none) runs out."""
    deadline = None if timeout is None else time.monotonic() + timeout
    heard = None
    while deadline is None or time.monotonic() < deadline:
        found = parse_listening(read())
        if found and (found.web_port or web is False):
            return found
        if found and web is None:
            heard = heard or time.monotonic()
            if time.monotonic() - heard > WEB_LINE_GRACE_S:
                return found
        if not alive():
            return None
        time.sleep(0.02)
    return None


def status_fields(line):
    """A status line's figures (balls, queued, steps_per_s; with viewers connected also out_mb_s, net_cpu,
    encode_us, frames, snapshot_bytes), or None for other lines."""
    s = STATUS.search(line)
    if not s:
        return None
    fields = {"balls": int(s[1]), "queued": int(s[2]), "steps_per_s": int(s[3])}
    n = NETWORK_STATUS.search(line)
    if n:
        fields.update(out_mb_s=float(n[1]), net_cpu=float(n[2]), encode_us=int(n[3]), frames=float(n[4]),
                      snapshot_bytes=int(n[5]))
    return fields


class ServerError(RuntimeError):
    pass


class Server:
    """fishtank-server EXECUTABLE ARGS..., stdout and stderr in a log, started on return with its port read.
    As a context manager it is stopped on leaving (killed if an exception is leaving). The log is a temporary
    file removed on stop, unless log_path names the caller's."""

    def __init__(self, executable, *args, timeout=30, log_path=None):
        args = [str(a) for a in args]
        self._own_log = log_path is None
        if log_path is None:
            handle, log_path = tempfile.mkstemp(prefix="fishtank-server-", suffix=".log")
            os.close(handle)
        self.log_path = log_path
        with open(log_path, "w") as log:
            self.process = subprocess.Popen([str(executable), *args], stdout=log, stderr=subprocess.STDOUT)
        found = wait_listening(self.text, lambda: self.process.poll() is None, timeout, web="--no-web" not in args)
        if found is None:
            text = self.text()
            self.kill()
            raise ServerError(f"{os.path.basename(str(executable))} {' '.join(args)} did not start listening "
                              f"within {timeout} s:\n{text}")
        self.host, self.port, self.web_url, self.web_port = found

    @property
    def endpoint(self):
        """ADDRESS:PORT to connect to (a server bound to every address is reached on loopback)."""
        return f"{'127.0.0.1' if self.host == '0.0.0.0' else self.host}:{self.port}"

    def text(self):
        with open(self.log_path, encoding="utf-8", errors="replace") as f:
            return f.read()

    def lines(self):
        return self.text().splitlines()

    def status(self, since=0):
        """status_fields of each status line from line number `since` of the log on."""
        return [s for s in map(status_fields, self.lines()[since:]) if s]

    def wait_until(self, ready, timeout, what):
        """Polls ready(self) each half second; ServerError naming `what` when it exits or time runs out first."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if ready(self):
                return
            if self.process.poll() is not None:
                raise ServerError(f"the server exited before {what}:\n{self.text()[-3000:]}")
            time.sleep(0.5)
        raise ServerError(f"the server did not reach {what} within {timeout} s")

    def wait_poured(self, balls, timeout):
        """Until a status line shows every one of `balls` in the tank and none queued."""
        def poured(server):
            status = server.status()
            return bool(status) and status[-1]["balls"] == balls and status[-1]["queued"] == 0
        self.wait_until(poured, timeout, f"{balls} balls poured")

    def stop(self):
        """SIGTERM, then the exit status (the server writes --dump and --export files on the way out)."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self._remove_log()
        return self.process.returncode

    def kill(self):
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        self._remove_log()

    def _remove_log(self):
        if self._own_log and os.path.exists(self.log_path):
            os.unlink(self.log_path)

    def __enter__(self):
        return self

    def __exit__(self, kind, value, trace):
        if kind is None:
            self.stop()
        else:
            self.kill()


class SlowLink:
    """A TCP proxy on 127.0.0.1 for one client: the server's bytes reach it at `rate` bytes a second, its own
    the server at once. A slow link, whose queue forms in the proxy's sockets as in a router's."""

    def __init__(self, server_port, rate):
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.port = self._listener.getsockname()[1]
        self._server_port, self._rate = server_port, rate
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        client, _ = self._listener.accept()
        self._listener.close()
        upstream = socket.create_connection(("127.0.0.1", self._server_port))
        threading.Thread(target=self._pump, args=(client, upstream, None), daemon=True).start()
        self._pump(upstream, client, self._rate)

    @staticmethod
    def _pump(source, sink, rate):
        start, carried = time.monotonic(), 0
        try:
            while chunk := source.recv(4096):
                sink.sendall(chunk)
                carried += len(chunk)
                if rate:
                    time.sleep(max(0.0, start + carried / rate - time.monotonic()))
        except OSError:
            pass  # either side closed
        finally:
            sink.close()


# ------------------------------------------------------------------ variants and benchmarks

def cores():
    """The CPUs this process may run on (what nproc prints)."""
    return len(os.sched_getaffinity(0))


def cpu_flags():
    with open("/proc/cpuinfo") as f:
        found = re.search(r"^flags\s*:(.*)$", f.read(), re.M)
    return set(found[1].split()) if found else set()


def has_avx2():
    return "avx2" in cpu_flags()


@dataclasses.dataclass(frozen=True)
class Variant:
    label: str    # no commas: it is a CSV field and a gnuplot key
    program: str  # under BUILD/server
    threads: int

    @property
    def flags(self):
        # --fixed-threads: the thread tuner would step on one thread when that measures faster, and the
        # row would no longer be what its label says.
        return ["--threads", str(self.threads)] + (["--fixed-threads"] if self.threads > 1 else [])

    @property
    def simd(self):
        """The kernel set the program steps with: "scalar", "sse" or "avx2"."""
        return {"fishtank-server-scalar": "scalar", "fishtank-server": "sse", "fishtank-server-avx2": "avx2"}[self.program]

    def bench_command(self, build, *args):
        return [os.path.join(build, "server", self.program), "--bench", *map(str, args), *self.flags]


def variants(avx2_one_thread=False):
    """The builds side by side, slowest first: the scalar build, SSE on one thread and on every core, AVX2 on
    every core where the processor has it (and on one thread, if asked: the report's variants figure)."""
    n = cores()
    cases = [Variant("scalar", "fishtank-server-scalar", 1), Variant("SSE 1 thread", "fishtank-server", 1)]
    if n > 1:
        cases.append(Variant(f"SSE {n} threads", "fishtank-server", n))
    if has_avx2():
        if avx2_one_thread or n == 1:
            cases.append(Variant("AVX2 1 thread", "fishtank-server-avx2", 1))
        if n > 1:
            cases.append(Variant(f"AVX2 {n} threads", "fishtank-server-avx2", n))
    return cases


def simd_variants_on_every_core():
    """The SIMD builds on every core (--fixed-threads): the variants whose rate the tolerance turns into capacity."""
    return [v for v in variants() if v.threads == cores() and v.simd != "scalar"]


def build_targets(build, *extra):
    """Brings the server variants (and `extra` targets) up to date in build."""
    if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
        sys.exit(f"{os.path.basename(sys.argv[0])}: {build} is not a configured build; make one with "
                 "cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release")
    targets = ["fishtank-server", "fishtank-server-scalar"] + (["fishtank-server-avx2"] if has_avx2() else [])
    subprocess.run(["cmake", "--build", build, "--target", *targets, *extra], check=True, stdout=subprocess.DEVNULL)


# The settled benchmark tank every variant comparison times.
TANK = ["--scene", "tank", "--balls", "6000", "--steps", "4000"]


def bench(build, variant, *args):
    """--bench's JSON report of one run, with the 1-minute load average before and after it."""
    return bench_command(variant.bench_command(build, *args))


def bench_command(cmd):
    """The JSON report of one --bench command line, with the 1-minute load average before and after it."""
    before = os.getloadavg()[0]
    done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed (exit status {done.returncode}):\n{done.stderr[-3000:]}")
    report = json.loads(done.stdout)
    report["load_before"], report["load_after"] = before, os.getloadavg()[0]
    return report


# ------------------------------------------------------------------ per-round summaries

def interleaved(cases, rounds):
    """(round, case) in the order to run them: each round runs every case once, in the opposite order to the
    round before, so a drift of the machine spreads over all cases."""
    cases = list(cases)
    for rnd in range(1, rounds + 1):
        for case in (cases if rnd % 2 else reversed(cases)):
            yield rnd, case


Spread = collections.namedtuple("Spread", "median min max")


def spread(values):
    """Median, min and max of the values (one per round)."""
    values = [float(v) for v in values]
    if not values:
        raise ValueError("spread of no values")
    return Spread(statistics.median(values), min(values), max(values))


def round_ratios(rows, value, numerator, denominator):
    """For each round that has both: value of the row numerator(row) picks over value of the row
    denominator(row) picks in the same round. rows carry a 'round'."""
    over = {str(r["round"]): value(r) for r in rows if denominator(r)}
    return [value(r) / over[str(r["round"])] for r in rows if numerator(r) and str(r["round"]) in over]


def write_csv(path, rows, columns=None):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns or list(rows[0]), lineterminator="\n")
        w.writeheader()
        w.writerows(rows)


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def step_kernel_instructions(callgrind_out, balls):
    """Instructions per ball-step of the step kernel (kernels_*.cpp's step<...>) in a callgrind profile: its
    inclusive count over its calls and the balls. None where the profile holds no step kernel."""
    report = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--tree=calling", callgrind_out],
                            check=True, stdout=subprocess.PIPE, text=True).stdout
    return step_kernel_cost(report, balls)


def step_kernel_cost(report, balls):
    """step_kernel_instructions from callgrind_annotate's --inclusive=yes --tree=calling report."""
    # In the calling tree the kernel appears as "<Ir> (..%)  >   ???:<type> ...step<...>(...) (<calls>x) [...]"
    # under its caller and as "<Ir> (..%)  *  ???:<type> ...step<...>(...) [...]" on its own line; a function
    # it calls that was not inlined names it only inside its own name, which does not count.
    cost = calls = None
    for line in report.splitlines():
        m = re.match(r"\s*([\d,]+) \([^)]*\)\s+([>*])\s+[^ (]*?:(?:[\w:]+ )?"
                     r"fishtank::\(anonymous namespace\)::step[<(]", line)
        if not m:
            continue
        if m.group(2) == ">":
            calls = int(re.search(r"\((\d[\d,]*)x\)", line).group(1).replace(",", ""))
        else:
            cost = int(m.group(1).replace(",", ""))
    return cost / (calls * balls) if cost and calls else None


# ------------------------------------------------------------------ LAMMPS's collisions

COLLISION_RESTITUTIONS = [0.05, 0.3, 0.6, 0.9, 1.0]  # the product's collision sweep (server/accuracy/collisions.h)
COLLISION_SPEEDS = [0.1, 1.0, 5.0, 20.0]             # approach speeds, m/s, as that sweep
COLLISION_PHASES = 20                                 # onsets spread over one step, as that sweep
KINDS = [(1.0, 1.0), (2.0, 2.0), (3.0, 3.0)]          # diameter, mass (common/tank.h)


def lammps_damping(k, e, m_eff):
    """c = 2 zeta sqrt(k m_eff), as the exported scene's pair_coeff (server/export/lammps_export.cpp)."""
    zeta = -math.log(e) / math.sqrt(math.pi ** 2 + math.log(e) ** 2) if e < 1 else 0.0
    return 2.0 * zeta * math.sqrt(k * m_eff)


def lammps_head_on(folder, k, t_c, steps_per_contact, restitutions=COLLISION_RESTITUTIONS):
    """Every isolated head-on collision of the product's sweep (size pairs, speeds, onset phases; no gravity)
    in LAMMPS's pair granular hooke, for each e and n in steps_per_contact (dt = t_c / n), in one lmp run in
    folder (made). Rows: restitution, steps_per_contact, diameter_a, diameter_b, speed, phase, measured."""
    os.makedirs(folder)
    pairs = [(a, b, v, phase) for a in range(3) for b in range(a, 3) for v in COLLISION_SPEEDS
             for phase in range(COLLISION_PHASES)]
    side = math.ceil(math.sqrt(len(pairs)))
    spacing = 8.0  # apart in y and z: the largest pair spans 6 m in x only
    script = []
    for n in steps_per_contact:
        dt = t_c / n
        atoms, velocities = [], []
        for i, (a, b, v, phase) in enumerate(pairs):
            (da, ma), (db, mb) = KINDS[a], KINDS[b]
            gap = v * dt * (2 + phase / COLLISION_PHASES)  # the contact starts in the third step, at this phase of it
            y, z = spacing * (i % side), spacing * (i // side)
            for j, (kind, d, m, x, vx) in enumerate(((a, da, ma, -da / 2 - gap / 2, v / 2),
                                                     (b, db, mb, db / 2 + gap / 2, -v / 2))):
                atoms.append(f"{2 * i + j + 1} {kind + 1} {d} {m / (math.pi / 6 * d ** 3):.12g} {x:.12g} {y} {z}")
                velocities.append(f"{2 * i + j + 1} {vx} 0 0 0 0 0")
        with open(os.path.join(folder, f"data.{n}"), "w") as f:
            f.write(f"head-on pairs, dt = t_c/{n}\n\n{len(atoms)} atoms\n3 atom types\n\n-10 10 xlo xhi\n"
                    f"-5 {spacing * side} ylo yhi\n-5 {spacing * side} zlo zhi\n\nAtoms # sphere\n\n"
                    + "\n".join(atoms) + "\n\nVelocities\n\n" + "\n".join(velocities) + "\n")
        for e in restitutions:
            script += ["clear", "units si", "atom_style sphere", "boundary f f f", "comm_modify vel yes",
                       f"read_data data.{n}", "pair_style granular"]
            for a in range(3):
                for b in range(a, 3):
                    m_eff = KINDS[a][1] * KINDS[b][1] / (KINDS[a][1] + KINDS[b][1])
                    script.append(f"pair_coeff {a + 1} {b + 1} hooke {k} {lammps_damping(k, e, m_eff):.12g} "
                                  "tangential linear_nohistory 0.0 0.0 damping velocity")
            # the heaviest pair's contact lasts sqrt(3) t_c: 3 t_c covers onset, contact and parting
            script += ["neighbor 0.5 bin", "fix integrate all nve/sphere", f"timestep {dt!r}", "thermo 0",
                       f"run {3 * n + 10}", f"write_dump all custom final.{n}.{e} id x vx modify sort id"]
    with open(os.path.join(folder, "in.collisions"), "w") as f:
        f.write("\n".join(script) + "\n")
    done = subprocess.run(["lmp", "-in", "in.collisions", "-log", "none", "-screen", "none"], cwd=folder,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"lmp failed on the collision sweep ({folder}):\n{done.stdout[-3000:]}")
    rows = []
    for n in steps_per_contact:
        for e in restitutions:
            with open(os.path.join(folder, f"final.{n}.{e}")) as f:
                lines = f.read().splitlines()
            start = lines.index(next(l for l in lines if l.startswith("ITEM: ATOMS"))) + 1
            state = [tuple(map(float, l.split()[1:])) for l in lines[start:]]
            for i, (a, b, v, phase) in enumerate(pairs):
                (xa, va), (xb, vb) = state[2 * i], state[2 * i + 1]
                if xb - xa < (KINDS[a][0] + KINDS[b][0]) / 2:
                    raise RuntimeError(f"a LAMMPS pair is still in contact at the end of its run (n = {n}, e = {e})")
                rows.append({"restitution": e, "steps_per_contact": n, "diameter_a": KINDS[a][0],
                             "diameter_b": KINDS[b][0], "speed": v, "phase": phase / COLLISION_PHASES,
                             "measured": (vb - va) / v})
    return rows


# ------------------------------------------------------------------ the machine

def cpu_model():
    with open("/proc/cpuinfo") as f:
        found = re.search(r"^model name\s*:\s*(.*)$", f.read(), re.M)
    return found[1].strip() if found else "unknown CPU"


def commit():
    """The short commit of this checkout, with '+dirty' where files differ from it."""
    def git(*args):
        return subprocess.run(["git", "-C", ROOT, *args], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                              text=True).stdout.strip()
    head = git("rev-parse", "--short", "HEAD") or "unknown"
    return head + ("+dirty" if git("status", "--porcelain") else "")


def machine():
    """What a figure was measured on, taken when the measurement starts."""
    return {"cpu": cpu_model(), "cores": cores(), "avx2": has_avx2(),
            "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "commit": commit()}


def machine_line(m):
    return f"{m['cpu']}, {m['cores']} cores, AVX2 {'yes' if m['avx2'] else 'no'}; {m['date']}; commit {m['commit']}"


def record_conditions(part, m, detail=""):
    """One line per figure in docs/figures/perf-conditions.txt, replacing that figure's last: when, at which
    commit and on what machine m (machine(), taken as the measurement started) it was measured."""
    path = os.path.join(FIGURES, "perf-conditions.txt")
    kept = []
    if os.path.exists(path):
        with open(path) as f:
            kept = [line for line in f.read().splitlines() if not line.startswith(part + ":")]
    kept.append(f"{part}: {m['date']}, commit {m['commit']}, {detail + ', ' if detail else ''}"
                f"{m['cpu']}, {m['cores']} cores, avx2 {'yes' if m['avx2'] else 'no'}")
    with open(path, "w") as f:
        f.write("\n".join(sorted(kept)) + "\n")


# ------------------------------------------------------------------ as a program

def main(argv):
    parser = argparse.ArgumentParser(prog="scripts/fishtank_tools.py", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    listen = sub.add_parser("listening", help="wait for a server's 'listening on' line and print its addresses")
    listen.add_argument("log", help="the log the server's stderr goes to")
    listen.add_argument("--pid", type=int, help="the server's process: stop waiting (exit 3) once it has ended")
    listen.add_argument("--timeout", type=float, default=30.0,
                        help="seconds to wait (default 30; 0: as long as --pid lives)")
    sub.add_parser("variants", help="the variants compared on this machine, with their flags")
    sub.add_parser("machine", help="CPU, cores, date and commit")
    conditions = sub.add_parser("conditions", help="record this machine, date and commit for a figure in "
                                "docs/figures/perf-conditions.txt (for the scripts not in Python)")
    conditions.add_argument("figure", help="the figure's name, e.g. abuse")
    args = parser.parse_args(argv)
    if args.command == "listening":
        if args.timeout < 0 or (args.timeout == 0 and args.pid is None):
            parser.error("--timeout must be positive, or 0 with --pid")

        def read():
            try:
                with open(args.log, encoding="utf-8", errors="replace") as f:
                    return f.read()
            except FileNotFoundError:
                return ""

        def alive():
            if args.pid is None:
                return True
            try:
                with open(f"/proc/{args.pid}/stat") as f:
                    # a child the caller has not reaped yet is a zombie: ended all the same
                    return f.read().rsplit(")", 1)[1].split()[0] != "Z"
            except FileNotFoundError:
                return False

        found = wait_listening(read, alive, args.timeout or None)
        if found is None:
            if not alive():
                return 3
            print(f"fishtank_tools: no 'listening on' line in {args.log} within {args.timeout:g} s", file=sys.stderr)
            return 1
        print(f"{found.host}:{found.port}")
        print(found.web_url or "")
    elif args.command == "variants":
        for v in variants():
            print(f"{v.label}: {v.program} {' '.join(v.flags)}")
    elif args.command == "conditions":
        record_conditions(args.figure, machine())
    else:
        print(machine_line(machine()))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
