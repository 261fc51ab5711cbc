"""Every shell command that README.md and the user manual quote runs as shown,
or is excluded below with the reason. A command is a line of a ```sh block, or
an inline `span` that starts like one (scripts/..., build/..., a program with
flags, cd, PYTHONPATH=, xvfb-run, cmake, mpirun, lmp).

Each runs from a scratch folder (so what it writes lands there) with these
rewrites, which keep it a few seconds long and off other people's ports:
- build/, scripts/ and docs/ are this checkout's (FISHTANK_BUILD_DIR for build/);
  a program quoted by name alone is build/'s;
- servers run on --port 0 (and --no-web unless a web port is given) for --duration 1 at most (a trailing
  & is dropped); a recording starts at once (--record-from 0), of 60 balls where it waits for the pour;
- clients, viewers and Python examples go to a fresh server of 300 balls on one
  thread, for 1 s at most; a viewer runs under xvfb-run; otherhost is 127.0.0.1;
- benchmarks time small scenes: --balls 60 (10 000, the least, for wide), --steps 200 at most;
- DIR is a scene exported for LAMMPS;
- python3 is the interpreter running this suite (Debian's, where scripts/install-deps puts the packages).
The exported in.fishtank's own "Run ..." commands are run the same way (as root, with Open MPI's two
variables that allow it)."""

import os
import re
import shlex
import shutil
import subprocess
import sys

import pytest

from conftest import BUILD, DOCS, SOURCE, markdown, program

# Commands not run, and why. A new documented command runs unless it is listed here.
EXCLUDED = {
    "scripts/run": "builds into build/ while this suite runs from it, then holds a window open until it is closed",
    "scripts/run --balls 3000": "as scripts/run",
    "scripts/test": "runs this suite",
    "scripts/test -R restitution": "runs this suite (ctest's -R selects tests)",
    "scripts/test-tsan": "a ThreadSanitizer build and its tests, minutes; CI runs it after scripts/test",
    "scripts/test-asan": "an AddressSanitizer build and its tests, minutes; CI runs it after scripts/test",
    "cmake --preset release && cmake --build build": "configures and builds build/ while this suite runs from it",
    "cmake --build build": "builds build/ while this suite runs from it",
    "scripts/bench-loaded": "minutes by design (busy processes beside timed runs); its --self-test is a ctest test",
    "build/server/fishtank-bench-variants": "settles a 6000-ball tank and times every kernel set, minutes",
    "build/server/fishtank-bench-variants --benchmark_filter=step_tank --benchmark_repetitions=8 "
    "--benchmark_enable_random_interleaving=true": "as fishtank-bench-variants",
    "build/server/fishtank-bench-variants --benchmark_filter=step_wide --benchmark_repetitions=6 "
    "--benchmark_enable_random_interleaving=true": "as fishtank-bench-variants",
    "build/server/fishtank-bench-delta": "runs a 100 000-ball wide scene and settles a tank for its snapshots, half a minute",
    "build/server/fishtank-accuracy": "the accuracy sweeps, minutes (scripts/figures runs them)",
    "scripts/callgrind-step": "valgrind over every variant, minutes",
    "scripts/figures": "installs gnuplot, sweeps for minutes and rewrites docs/figures/",
    "scripts/headline": "every variant and LAMMPS in three rounds, 3-8 minutes; rewrites docs/figures/ and the tables of README and report",
    "scripts/figures-error-cost": "benchmarks two builds at up to 160 steps per contact, a quarter of an hour; rewrites docs/figures/",
    "scripts/figures-prefetch": "times the wide scene at up to 100 000 balls, a quarter of an hour; rewrites docs/figures/",
    "scripts/figures-capacity": "six benchmarks of the settled tank, a minute; rewrites docs/figures/",
    "scripts/figures-load": "the loaded benchmark for minutes; rewrites docs/figures/",
    "scripts/figures-perf": "about 12 minutes; rewrites docs/figures/",
    "scripts/figures-web": "a minute of headless Chromium; rewrites docs/figures/",
    "scripts/figures-web-observers": "a minute and a half of WebSocket observers; rewrites docs/figures/",
    "scripts/figures-slow-link": "40 s of a pour watched through throttled observers; rewrites docs/figures/",
    "scripts/abuse-table": "rebuilds the network tests and rewrites docs/figures/abuse.csv",
    "scripts/lammps-crosscheck": "times full scenes in fishtank-server and LAMMPS, minutes",
    "scripts/fuzz 60": "installs clang, builds a fuzzer and fuzzes for 60 s",
    "fishtank-client --add N": "N is a placeholder; the test client's section runs --add 1000",
}

COMMAND_START = re.compile(r"(scripts/|build/\S*[^/]( |$)|fishtank-[\w-]+ --|cd |PYTHONPATH=|xvfb-run |cmake |mpirun |lmp )")
PROGRAMS = ("fishtank-server", "fishtank-server-scalar", "fishtank-server-avx2", "fishtank-viewer", "fishtank-client")
XVFB = 'xvfb-run -a -s "-screen 0 1280x1024x24"'
MAX_SECONDS = 1
BENCH_BALLS = 60  # a tank benchmark settles for up to 300 simulated seconds: few balls keep that short


def documented():
    """(document, command) for every command quoted, in order, once each."""
    seen = {}
    for doc in DOCS:
        text = markdown(doc)
        for block in re.findall(r"```(?:sh|bash)\n(.*?)```", text, re.S):
            for line in block.splitlines():
                command = re.sub(r"\s+#\s.*$", "", line).strip()
                if command:
                    seen.setdefault(command, doc)
        for span in re.findall(r"`([^`\n]+)`", text):
            folder = span.startswith("build/") and (BUILD / span.removeprefix("build/")).is_dir()
            if COMMAND_START.match(span) and not folder:
                seen.setdefault(span.strip(), doc)
    return [(doc, command) for command, doc in seen.items()]


def set_flag(words, flag, value):
    """words with flag set to value: replaced where given, appended where not."""
    if flag in words:
        words[words.index(flag) + 1] = value
    else:
        words += [flag, value]


def cap_flag(words, flag, most):
    if flag in words and float(words[words.index(flag) + 1]) > most:
        words[words.index(flag) + 1] = str(most)


def limit_duration(words):
    cap_flag(words, "--duration", MAX_SECONDS)
    if "--duration" not in words:
        words += ["--duration", str(MAX_SECONDS)]


def rewrite_program(words, port):
    """One program's words, rewritten as the module's docstring says."""
    name = os.path.basename(words[0])
    if name in PROGRAMS:
        words[0] = str(program(name))
    if name.startswith("fishtank-server"):
        if "--bench" in words:
            balls = int(words[words.index("--balls") + 1]) if "--balls" in words else 6000
            set_flag(words, "--balls", str(min(balls, 10000 if "wide" in words else BENCH_BALLS)))
            cap_flag(words, "--steps", 200)
        elif "--help" not in words:
            set_flag(words, "--port", "0")
            if "--web-port" not in words and "--no-web" not in words:
                words.append("--no-web")  # the default web port 8080 may be taken (a server the reader runs)
            set_flag(words, "--threads", "1")
            limit_duration(words)
            if "--record-from" in words:  # the second it names lies past the second the server runs
                set_flag(words, "--record-from", "0")
                if "--record-constant-count" in words:
                    set_flag(words, "--balls", "60")  # poured in well within that second
    elif name in ("fishtank-client", "fishtank-viewer"):
        if "--connect" not in words:
            words += ["--connect", f"127.0.0.1:{port}"]
        limit_duration(words)
    elif name.endswith(".py") or (len(words) > 1 and words[1].endswith(".py")):
        script = words[1] if words[0] == "python3" else words[0]
        if script.startswith(str(SOURCE / "docs" / "examples")):
            set_flag(words, "--port", str(port))
            set_flag(words, "--seconds", str(MAX_SECONDS))
    elif name == "bench-variants":
        words += ["--balls", str(BENCH_BALLS), "--steps", "200", "--build", str(BUILD)]
    return words


def needs_server(command):
    return bool(re.search(r"fishtank-(client|viewer)|PYTHONPATH=", command))


def prepare(command, port, lammps_dir):
    """The command as it runs here."""
    text = command.removesuffix("&").strip().replace("...", "")
    text = text.replace("otherhost", "127.0.0.1").replace("7878", str(port))
    text = re.sub(r"\bDIR\b", shlex.quote(str(lammps_dir)), text)
    # one pass, so that a checkout path put in (which may hold "scripts/") is not rewritten again
    text = re.sub(r"(?<![\w/.$])(build|scripts|docs)/",
                  lambda m: str(BUILD if m.group(1) == "build" else SOURCE / m.group(1)) + "/", text)
    parts = []
    for part in re.split(r"\s*&&\s*", text):
        words = shlex.split(part)
        env = []
        while re.match(r"\w+=", words[0]):
            env.append(words.pop(0))
        prefix = []
        if words[0] == "xvfb-run":
            at = next(i for i, w in enumerate(words) if "fishtank-" in w)
            prefix, words = words[:at], words[at:]
        words = rewrite_program(words, port)
        if os.path.basename(words[0]) == "fishtank-viewer" and not prefix:
            prefix = shlex.split(XVFB)
        parts.append(" ".join(w if w.startswith("$(") else shlex.quote(w) for w in env + prefix + words))
    return " && ".join(parts)


@pytest.fixture(scope="module")
def lammps_dir(tmp_path_factory):
    """A small scene exported for LAMMPS: what DIR stands for."""
    folder = tmp_path_factory.mktemp("lammps") / "scene"
    subprocess.run([str(program("fishtank-server")), "--port", "0", "--no-web", "--threads", "1", "--balls", "300",
                    "--duration", "1", "--export-lammps", str(folder), "--lammps-steps", "200"], check=True,
                   capture_output=True, timeout=60)
    return folder


def run(prepared, cwd, source):
    # python3 is the interpreter running these tests, Debian's with the packages the client needs,
    # as it is on the fresh machine the docs are written for.
    path = os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", "")
    done = subprocess.run(["bash", "-c", prepared], cwd=cwd, capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, PATH=path))
    assert done.returncode == 0, f"{source}: {prepared}\nexit status {done.returncode}\n{done.stdout[-3000:]}{done.stderr[-3000:]}"


def skip_without_what_it_needs(command):
    if command in EXCLUDED:
        pytest.skip(EXCLUDED[command])
    if "avx2" in command and "avx2" not in open("/proc/cpuinfo").read():
        pytest.skip("this processor has no AVX2")
    for tool in ("lmp", "mpirun"):
        if re.search(rf"(^|&& ){tool} ", command) and shutil.which(tool) is None:
            pytest.skip(f"{tool} is not installed (scripts/install-deps lammps)")


@pytest.mark.parametrize("doc,command", documented(), ids=[c for _, c in documented()])
def test_the_documented_command_runs(doc, command, server, lammps_dir, tmp_path):
    skip_without_what_it_needs(command)
    port = server("--balls", "300", "--threads", "1").port if needs_server(command) else 7878
    run(prepare(command, port, lammps_dir), tmp_path, f"{doc} quotes `{command}`, run here as")


def test_every_exclusion_is_a_command_the_docs_still_quote():
    quoted = {command for _, command in documented()}
    assert not set(EXCLUDED) - quoted, "no longer documented: " + ", ".join(sorted(set(EXCLUDED) - quoted))


def test_the_exported_scripts_own_run_commands_run(lammps_dir, tmp_path):
    commands = re.findall(r"^# Run [^:]*:\s+(.*)$", (lammps_dir / "in.fishtank").read_text(), re.M)
    assert len(commands) == 2, "in.fishtank should say how to run it on one core and on every core"
    # As the file says, Open MPI asks root (this suite in CI) to allow it: here by its two variables.
    as_root = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 " if os.geteuid() == 0 else ""
    for command in commands:
        skip_without_what_it_needs(command)
        run(f"cd {shlex.quote(str(lammps_dir))} && {as_root}{command}", tmp_path, "in.fishtank")
