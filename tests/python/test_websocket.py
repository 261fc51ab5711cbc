"""The server's web side from outside, as a browser would meet it: the protocol over a WebSocket
at /ws (one frame per binary message, without the length prefix) with its Welcome, snapshots,
Acks and deltas; the WebSocket's size limit (close code 1009); and the static files, served
read-only from one folder: paths out of it get 404, methods other than GET and HEAD get 405,
an over-size header gets 431. Frames are built and read with the Python client's FlatBuffers code."""

import asyncio
import http.client
import os
import signal
import subprocess

import pytest
import websockets

from fishtank._frames import _ack_frame, _hello_frame
from fishtank.wire import Error, ErrorCode, Message, Payload, Snapshot

TOO_BIG = 1009  # RFC 6455: message too big


# A message as the WebSocket carries it: the TCP frame without its 4-byte length prefix.
def _hello(name="websocket test"):
    return _hello_frame(name, acknowledges=False)[4:]


def _ack(tick):
    return _ack_frame(tick)[4:]


def _message(body):
    assert isinstance(body, bytes), "the server sends binary messages only"
    assert body[4:8] == b"FTNK", "each message is one frame without its length prefix"
    return Message.Message.GetRootAs(body, 0)


def _snapshot(m):
    s = Snapshot.Snapshot()
    s.Init(m.Payload().Bytes, m.Payload().Pos)
    return s


def _connect(port, **options):
    return websockets.connect(f"ws://127.0.0.1:{port}/ws", compression=None, max_size=None, **options)


def _run(coroutine):
    return asyncio.run(asyncio.wait_for(coroutine, timeout=20))


def test_over_a_websocket_a_client_is_welcomed_and_gets_deltas_once_it_acknowledges(start_server):
    server = start_server("--balls", "300", "--web-port", "0")

    async def converse():
        async with _connect(server.web_port) as ws:
            await ws.send(_hello())
            kinds = []
            while True:
                m = _message(await ws.recv())
                kinds.append(m.PayloadType())
                if m.PayloadType() == Payload.Payload.Snapshot:
                    first = _snapshot(m)
                    break
            assert kinds[0] == Payload.Payload.Welcome and Payload.Payload.BallKinds in kinds
            assert first.BallCount() > 0 and first.PositionsLength() == 3 * first.BallCount()  # a keyframe: all
            await ws.send(_ack(first.Tick()))
            for _ in range(60):
                m = _message(await ws.recv())
                if m.PayloadType() != Payload.Payload.Snapshot:
                    continue
                s = _snapshot(m)
                if s.UnchangedLength() > 0:
                    return first.Tick(), s
            return first.Tick(), None

    acked, delta = _run(converse())
    assert delta is not None, "no delta within 60 snapshots of the Ack"
    assert delta.PositionsLength() == 0 and delta.BaseTick() == acked and delta.BallCount() > 0
    assert "upgraded to a WebSocket" in server.text()


def test_an_over_size_message_is_refused_with_close_code_1009_before_and_after_hello(start_server):
    server = start_server("--balls", "50", "--web-port", "0")

    async def close_code(messages):
        async with _connect(server.web_port) as ws:
            try:
                for message in messages:
                    await ws.send(message)
            except websockets.ConnectionClosed:
                return ws.close_code  # the server closed while this client was still sending
            with pytest.raises(websockets.ConnectionClosed):
                while True:
                    await ws.recv()
            return ws.close_code

    assert _run(close_code([bytes(2048)])) == TOO_BIG  # a Hello is at most 1 KiB
    # Beyond 1 MiB the server closes with 1009 while the client is still sending: its close frame may be
    # lost to the reset that unread bytes cause, so the server's log is what says which code it sent. The
    # client can see the reset before the server has written that line, so the log is waited on.
    _run(close_code([_hello(), bytes((1 << 20) + 1)]))
    server.wait_until(lambda s: s.text().count("closed with code 1009") == 2, 10, "two closes with code 1009")


def test_a_text_message_or_garbage_gets_the_protocols_error_and_an_end(start_server):
    server = start_server("--balls", "50", "--web-port", "0")

    async def refusal(message):
        async with _connect(server.web_port) as ws:
            await ws.send(message)
            received = []
            with pytest.raises(websockets.ConnectionClosed):
                while True:
                    received.append(_message(await ws.recv()))
            return [m.PayloadType() for m in received]

    assert _run(refusal("hello")) == [Payload.Payload.Error]
    assert _run(refusal(bytes(range(64)))) == [Payload.Payload.Error]
    assert "malformed_frame" in server.text()


def test_a_stopping_server_says_why_closes_with_1001_and_ends_the_session_on_the_close_handshake(start_server):
    server = start_server("--balls", "50", "--web-port", "0")

    async def stopped():
        async with _connect(server.web_port) as ws:
            await ws.send(_hello())
            await ws.recv()  # the Welcome
            server.process.send_signal(signal.SIGTERM)
            last = None
            with pytest.raises(websockets.ConnectionClosed) as closed:
                while True:
                    last = _message(await ws.recv())
            return last, closed.value.rcvd.code

    last, code = _run(stopped())
    assert last.PayloadType() == Payload.Payload.Error
    error = Error.Error()
    error.Init(last.Payload().Bytes, last.Payload().Pos)
    assert error.Code() == ErrorCode.ErrorCode.server_stopping
    assert code == 1001  # going away
    assert server.process.wait(timeout=10) == 0
    log = server.text()
    # Ended by the client's close frame, not by the grace period a client that never answers meets.
    assert "closed: disconnected by the server\n" in log and "had not closed its side" not in log, log
    server.stop()  # exited already: this removes its log


@pytest.fixture
def web_root(tmp_path):
    """A page folder with a file, a subfolder, and a symlink and a file beside it that lead out of it."""
    root = tmp_path / "root"
    (root / "sub").mkdir(parents=True)
    (root / "index.html").write_text("<title>fishtank</title>")
    (root / "sub" / "app.js").write_text("console.log(1);")
    secret = tmp_path / "secret.txt"
    secret.write_text("not for the web")
    os.symlink(secret, root / "sub" / "link.txt")
    os.symlink(tmp_path, root / "up")
    return root


def _request(port, method, path, headers=None):
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    connection.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
    connection.putheader("Host", "127.0.0.1")
    for name, value in (headers or {}).items():
        connection.putheader(name, value)
    connection.endheaders()
    response = connection.getresponse()
    body = response.read()
    connection.close()
    return response.status, dict(response.getheaders()), body


def test_files_are_served_from_the_web_root_and_nothing_outside_it(start_server, web_root):
    server = start_server("--balls", "0", "--web-port", "0", "--web-root", str(web_root))
    port = server.web_port
    status, headers, body = _request(port, "GET", "/")
    assert status == 200 and body == b"<title>fishtank</title>" and headers["Content-Type"].startswith("text/html")
    status, headers, body = _request(port, "GET", "/sub/app.js?v=2")
    assert status == 200 and body == b"console.log(1);" and headers["Content-Type"].startswith("text/javascript")
    status, headers, body = _request(port, "HEAD", "/sub/app.js")
    assert status == 200 and headers["Content-Length"] == "15" and body == b""
    for outside in ("/../secret.txt", "/sub/../../secret.txt", "/%2e%2e/secret.txt", "/%2E%2E%2Fsecret.txt",
                    "/sub/%2e%2e%2f%2e%2e%2fsecret.txt", "/sub/link.txt", "/up/secret.txt", "/nothing.js",
                    "/%zz", "/sub%00/app.js"):
        status, _, body = _request(port, "GET", outside)
        assert status == 404, outside
        assert b"not for the web" not in body


def test_other_methods_get_405_upgrades_elsewhere_404_ws_without_upgrade_426_and_an_over_size_header_431(
        start_server, web_root):
    server = start_server("--balls", "0", "--web-port", "0", "--web-root", str(web_root))
    port = server.web_port
    for method in ("POST", "PUT", "DELETE", "OPTIONS"):
        status, headers, _ = _request(port, method, "/index.html")
        assert status == 405 and headers["Allow"] == "GET, HEAD", method
    upgrade = {"Upgrade": "websocket", "Connection": "Upgrade", "Sec-WebSocket-Version": "13",
               "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ=="}
    assert _request(port, "GET", "/index.html", upgrade)[0] == 404
    assert _request(port, "GET", "/ws", {"X-Filler": "a" * 20000})[0] == 431
    status, headers, body = _request(port, "GET", "/ws")  # the socket's address opened in a browser
    assert status == 426 and headers["Upgrade"] == "websocket" and b"open / instead" in body
    status, _, body = _request(port, "GET", "/no-such-file.html")
    assert status == 404 and b'the viewer is at <a href="/">/</a>' in body


def test_without_a_built_page_the_server_says_how_to_build_it_and_ws_still_works(start_server, tmp_path):
    server = start_server("--balls", "10", "--web-port", "0", "--web-root", str(tmp_path))  # no index.html in it
    status, _, body = _request(server.web_port, "GET", "/")
    assert status == 404 and b"not built" in body and b"--web-root" in body
    assert str(tmp_path).encode() not in body  # the server's folders are not shown to whoever asks
    assert "not built" in server.text()

    async def welcomed():
        async with _connect(server.web_port) as ws:
            await ws.send(_hello())
            return _message(await ws.recv()).PayloadType()

    assert _run(welcomed()) == Payload.Payload.Welcome


def test_a_web_port_in_use_is_refused_with_a_message_naming_both_flags(start_server):
    first = start_server("--balls", "0", "--web-port", "0")
    second = subprocess.run([os.environ["FISHTANK_SERVER"], "--bind", "127.0.0.1", "--port", "0", "--balls", "0",
                             "--web-port", str(first.web_port)], capture_output=True, text=True, timeout=30)
    assert second.returncode == 1
    assert f"127.0.0.1:{first.web_port}" in second.stderr
    assert "--web-port" in second.stderr and "--no-web" in second.stderr


def test_each_port_given_to_the_other_kind_of_client_answers_in_its_kind_with_the_right_port(start_server):
    """A browser pointed at the TCP port, or a Python client at the web port, learns which port it wanted."""
    from fishtank import Client, FishtankError

    server = start_server("--balls", "10", "--web-port", "0")
    status, _, body = _request(server.port, "GET", "/")
    assert status == 400
    assert f"The browser viewer is on port {server.web_port} of this machine".encode() in body
    with pytest.raises(FishtankError) as wrong:
        Client("127.0.0.1", server.web_port)
    assert wrong.value.code == "wrong_port" and f"connect to its port {server.port} " in wrong.value.message


def test_fishtank_client_at_the_web_port_says_the_servers_reason_and_no_start_a_server_hint(start_server):
    client = os.path.join(os.path.dirname(os.environ["FISHTANK_SERVER"]), "..", "client", "fishtank-client")
    if not os.path.exists(client):
        pytest.skip("fishtank-client is not built here (the sanitizer builds leave it out)")
    server = start_server("--balls", "10", "--web-port", "0")
    cli = subprocess.run([client, "--connect", f"127.0.0.1:{server.web_port}", "--duration", "1"],
                         capture_output=True, text=True, timeout=30)
    assert cli.returncode == 1
    assert "the server closed the connection (wrong_port: " in cli.stderr and f"port {server.port} " in cli.stderr
    assert "To start a server here" not in cli.stderr  # one is there
