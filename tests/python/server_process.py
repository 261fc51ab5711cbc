"""A real fishtank-server on an ephemeral 127.0.0.1 port, for the pytest suites (tests/python, tests/docs).
Its web viewer is off unless the caller gives --web-port (0: an ephemeral port too, then in web_port), so
that servers started side by side never contend for the default port 8080."""

import os
import re
import signal
import subprocess
import tempfile
import time


class Server:
    def __init__(self, executable, *args):
        self.log = tempfile.NamedTemporaryFile(prefix="fishtank-server-", suffix=".log", delete=False)
        web = "--web-port" in args
        self.process = subprocess.Popen(
            [str(executable), "--bind", "127.0.0.1", "--port", "0", *([] if web else ["--no-web"]), *args],
            stderr=self.log, stdout=subprocess.DEVNULL)
        self.web_port = None
        deadline = time.monotonic() + 15
        while time.monotonic() < deadline:
            text = self.text()
            found = re.search(r"listening on 127\.0\.0\.1:(\d+)", text)
            found_web = re.search(r"web viewer on http://127\.0\.0\.1:(\d+)/", text)
            if found and (found_web or not web):
                self.port = int(found.group(1))
                self.web_port = int(found_web.group(1)) if web else None
                return
            if self.process.poll() is not None:
                break
            time.sleep(0.05)
        self.stop()
        raise RuntimeError("fishtank-server did not start listening:\n" + self.text())

    def text(self):
        with open(self.log.name, encoding="utf-8", errors="replace") as f:
            return f.read()

    def stop(self):
        """SIGTERM, then the exit status (the server writes its --dump on the way out)."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        if os.path.exists(self.log.name):
            os.unlink(self.log.name)
        return self.process.returncode
