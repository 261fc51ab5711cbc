"""What the documentation tests share: where the sources and the programs are
(FISHTANK_SOURCE_DIR, FISHTANK_BUILD_DIR), the Markdown of README.md and the
manual, and a real fishtank-server on an ephemeral 127.0.0.1 port."""

import os
import re
import signal
import subprocess
import tempfile
import time
from pathlib import Path

import pytest

SOURCE = Path(os.environ.get("FISHTANK_SOURCE_DIR", Path(__file__).resolve().parents[2]))
BUILD = Path(os.environ.get("FISHTANK_BUILD_DIR", SOURCE / "build"))
DOCS = ["README.md", "docs/user-manual.md"]  # the documents a new user reads first


def program(name):
    """build/<dir>/<name> for fishtank-server, -viewer, -client and their siblings."""
    folder = {"viewer": "viewer", "client": "client"}.get(name.split("-")[1], "server")
    return BUILD / folder / name


def markdown(doc):
    return (SOURCE / doc).read_text(encoding="utf-8")


class Server:
    """fishtank-server --port 0 plus args; its port is read from its "listening on" line."""

    def __init__(self, *args):
        self.log = tempfile.NamedTemporaryFile(prefix="fishtank-server-", suffix=".log", delete=False)
        self.process = subprocess.Popen([str(program("fishtank-server")), "--bind", "127.0.0.1", "--port", "0", *args],
                                        stderr=self.log, stdout=subprocess.DEVNULL)
        deadline = time.monotonic() + 15
        while time.monotonic() < deadline:
            found = re.search(r"listening on 127\.0\.0\.1:(\d+)", self.text())
            if found:
                self.port = int(found.group(1))
                return
            if self.process.poll() is not None:
                break
            time.sleep(0.05)
        self.stop()
        raise RuntimeError("fishtank-server did not start listening:\n" + self.text())

    def text(self):
        return Path(self.log.name).read_text(encoding="utf-8", errors="replace")

    def stop(self):
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        os.unlink(self.log.name)


@pytest.fixture
def server():
    started = []

    def start(*args):
        started.append(Server(*args))
        return started[-1]

    yield start
    for s in started:
        s.stop()
