"""scripts/fishtank_tools.py, which the scripts share: the per-round summaries give the median, min and max
and the ratios within each round; rounds alternate their order; the step kernel's instructions are read from
its own lines of a callgrind report; a real fishtank-server's port is read from
its 'listening on' line and answers; a server that cannot start says why."""

import http.client
import os
import socket
import subprocess
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, "scripts"))
import fishtank_tools as ft  # noqa: E402  (after the path)

SERVER = os.path.join(os.environ["FISHTANK_BUILD_DIR"], "server", "fishtank-server")
TOOLS = os.path.join(ft.ROOT, "scripts", "fishtank_tools.py")


def test_spread_is_the_median_min_and_max():
    assert ft.spread([3, 1, 2]) == (2, 1, 3)
    assert ft.spread(["4", "1", "3", "2"]) == (2.5, 1, 4)
    with pytest.raises(ValueError):
        ft.spread([])


def test_round_ratios_divide_within_each_round_and_skip_a_round_without_its_base():
    rows = [{"round": 1, "variant": "scalar", "rate": 10}, {"round": 1, "variant": "sse", "rate": 30},
            {"round": 2, "variant": "sse", "rate": 50}, {"round": 2, "variant": "scalar", "rate": 20},
            {"round": 3, "variant": "sse", "rate": 99}]
    ratios = ft.round_ratios(rows, lambda r: r["rate"], lambda r: r["variant"] == "sse",
                             lambda r: r["variant"] == "scalar")
    assert ratios == [3.0, 2.5]


def test_rounds_alternate_their_order():
    assert [c for _, c in ft.interleaved("abc", 3)] == list("abccbaabc")


def test_the_step_kernels_instructions_come_from_its_own_lines_not_from_a_callee_named_after_it():
    step = ("fishtank::Moved fishtank::(anonymous namespace)::step<fishtank::simd::sse41::F4>"
            "(fishtank::StepContext const&, unsigned int, unsigned int)")
    callee = ("fishtank::(anonymous namespace)::for_each_group_of_batch<0, fishtank::simd::sse41::F4, "
              "fishtank::(anonymous namespace)::step<fishtank::simd::sse41::F4>(fishtank::StepContext const&, "
              "unsigned int, unsigned int)::{lambda()#1}>(fishtank::StepContext const&)")
    annotated = "\n".join([
        "60,003,402 (100.0%)  *  ???:fishtank::World::step() [harness]",
        f"59,989,752 (99.98%)  >   ???:{step} (30x) [harness]",
        "",
        f"59,989,752 (99.98%)  *  ???:{step} [harness]",
        f" 5,220,000 ( 8.70%)  >   ???:{callee} (3,840x) [harness]",
        "",
        f" 5,220,000 ( 8.70%)  *  ???:{callee} [harness]",
    ])
    assert ft.step_kernel_cost(annotated, balls=6000) == pytest.approx(59989752 / (30 * 6000))
    assert ft.step_kernel_cost(annotated.replace("::step<", "::stepped<"), balls=6000) is None


def test_every_variant_on_more_than_one_thread_is_fixed_to_its_threads():
    cases = ft.variants(avx2_one_thread=True)
    assert cases[0].program == "fishtank-server-scalar"
    assert len({v.label for v in cases}) == len(cases)
    for v in cases:
        assert v.flags[:2] == ["--threads", str(v.threads)]
        assert ("--fixed-threads" in v.flags) == (v.threads > 1)


def test_the_listening_lines_are_parsed_with_and_without_the_web_viewer():
    assert ft.parse_listening("starting\n") is None
    assert ft.parse_listening("listening on 0.0.0.0:7878\n") == ("0.0.0.0", 7878, None, None)
    found = ft.parse_listening("listening on 127.0.0.1:41000\nweb viewer on http://127.0.0.1:41001/\n")
    assert found == ("127.0.0.1", 41000, "http://127.0.0.1:41001/", 41001)


def test_the_command_line_prints_the_address_and_url_from_a_log(tmp_path):
    log = tmp_path / "server.log"
    log.write_text("listening on 127.0.0.1:41000\nweb viewer on http://127.0.0.1:41001/\n")
    done = subprocess.run([sys.executable, TOOLS, "listening", str(log), "--timeout", "2"], capture_output=True,
                          text=True, timeout=30)
    assert done.returncode == 0 and done.stdout == "127.0.0.1:41000\nhttp://127.0.0.1:41001/\n"
    log.write_text("")
    done = subprocess.run([sys.executable, TOOLS, "listening", str(log), "--timeout", "0.2"], capture_output=True,
                          text=True, timeout=30)
    assert done.returncode == 1 and "no 'listening on' line" in done.stderr


def test_a_real_server_is_reached_on_the_ports_read_and_stopped_on_leaving():
    with ft.Server(SERVER, "--bind", "127.0.0.1", "--port", "0", "--web-port", "0", "--threads", "1", "--balls",
                   "10") as server:
        assert server.port > 0 and server.web_port > 0 and server.port != server.web_port
        socket.create_connection(("127.0.0.1", server.port), timeout=5).close()
        web = http.client.HTTPConnection("127.0.0.1", server.web_port, timeout=5)
        web.request("GET", "/")
        assert web.getresponse().status in (200, 404)  # 404 where the page is not built: HTTP all the same
        web.close()
        log = server.log_path
    assert server.process.poll() is not None and not os.path.exists(log)


def test_a_server_that_cannot_start_raises_with_its_message():
    with pytest.raises(ft.ServerError, match="balls"):
        ft.Server(SERVER, "--port", "0", "--no-web", "--balls", "-5", timeout=10)
