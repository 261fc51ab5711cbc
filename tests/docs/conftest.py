"""What the documentation tests share: where the sources and the programs are
(FISHTANK_SOURCE_DIR, FISHTANK_BUILD_DIR), the Markdown of README.md and the
manual, and a real fishtank-server on an ephemeral 127.0.0.1 port."""

import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
import server_process  # noqa: E402  (tests/python, shared with the Python client's suite)

SOURCE = Path(os.environ.get("FISHTANK_SOURCE_DIR", Path(__file__).resolve().parents[2]))
BUILD = Path(os.environ.get("FISHTANK_BUILD_DIR", SOURCE / "build"))
DOCS = ["README.md", "docs/user-manual.md"]  # the documents a new user reads first


def program(name):
    """build/<dir>/<name> for fishtank-server, -viewer, -client and their siblings."""
    folder = {"viewer": "viewer", "client": "client"}.get(name.split("-")[1], "server")
    return BUILD / folder / name


def markdown(doc):
    return (SOURCE / doc).read_text(encoding="utf-8")


def Server(*args):
    """fishtank-server of this build (tests/python/server_process.py)."""
    return server_process.Server(program("fishtank-server"), *args)


@pytest.fixture
def server():
    started = []

    def start(*args):
        started.append(Server(*args))
        return started[-1]

    yield start
    for s in started:
        s.stop()
