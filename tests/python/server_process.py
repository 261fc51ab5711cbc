"""A real fishtank-server on an ephemeral 127.0.0.1 port, for the pytest suites (tests/python, tests/docs),
started by scripts/fishtank_tools.py, the one Python reader of its 'listening on' line. Its web viewer is off
unless the caller gives --web-port (0: an ephemeral port too, then in web_port), so that servers started side
by side never contend for the default port 8080."""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, "scripts"))
import fishtank_tools  # noqa: E402  (after the path)


class Server(fishtank_tools.Server):
    def __init__(self, executable, *args):
        web = "--web-port" in args
        super().__init__(executable, "--bind", "127.0.0.1", "--port", "0", *([] if web else ["--no-web"]), *args,
                         timeout=15)
