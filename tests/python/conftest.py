"""A real fishtank-server on an ephemeral 127.0.0.1 port for each test (FISHTANK_SERVER names the executable;
server_process.py says how it starts)."""

import os

import pytest

import server_process


def Server(*args):
    """The suite's server: FISHTANK_SERVER on one thread."""
    return server_process.Server(os.environ["FISHTANK_SERVER"], "--threads", "1", *args)


@pytest.fixture
def start_server():
    started = []

    def start(*args):
        started.append(Server(*args))
        return started[-1]

    yield start
    for server in started:
        if server.process.poll() is None:
            server.stop()
