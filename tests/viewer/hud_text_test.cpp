// The HUD tells the truth: figures left over from a lost connection are marked
// as such with their age, and the threads and time scale are the server's.

#include "viewer/hud_text.h"

#include <catch2/catch.hpp>

#include "common/server_hint.h"

using namespace fishtank::viewer;
using fishtank::connection_advice;
using fishtank::server_command_hint;

TEST_CASE("an overlap beyond a tenth of the smaller radius is a warning, a lighter one a plain figure") {
  const float resting = 1e-4f;  // J per ball
  const OverlapText light = overlap_text(0.042f, resting);
  CHECK(light.text == "4.2 % of the smaller radius");
  CHECK_FALSE(light.warn);
  CHECK_FALSE(overlap_text(0.10f, resting).warn);  // the limit itself is still accepted
  const OverlapText deep = overlap_text(0.52f, resting);
  CHECK(deep.warn);
  CHECK(deep.text == "52.0 % of the smaller radius: stiffness too soft for the load");
}

TEST_CASE("while balls still fly in, a deep overlap is an impact's: a plain figure, not a warning") {
  const OverlapText pour = overlap_text(0.184f, 191.0f);  // the default pour two seconds in
  CHECK_FALSE(pour.warn);
  CHECK(pour.text == "18.4 % of the smaller radius");
  CHECK(overlap_text(0.184f, 5e-3f).warn);  // the same overlap once they rest
}

TEST_CASE("the step row says how dt was chosen: from the tolerance, given, or not said") {
  CHECK(step_text(1.08e-3f, 13.0f, 0.005f) ==
        "1.08 ms, 13 steps per contact: each collision's e within 0.005");
  CHECK(step_text(0.7e-3f, 20.04f, 0.0f) == "0.7 ms (given), 20.0 steps per contact");
  CHECK(step_text(1.08e-3f, 0.0f, 0.0f) == "1.08 ms");  // a server from before the fields
  CHECK(step_text(0.0f, 13.0f, 0.005f) == "-");
}

TEST_CASE("while connected the server's figures are live") {
  const Freshness f = figures_freshness(true, 100.0, 99.98);
  CHECK(f.live);
  CHECK(f.note.empty());
  CHECK(figures_freshness(true, 100.0, -1.0).live);  // welcomed, first snapshot still on its way
}

TEST_CASE("after a disconnect the figures are greyed and their age counts up in whole seconds") {
  const double last = 1000.25;
  CHECK_FALSE(figures_freshness(false, last + 0.1, last).live);
  CHECK(figures_freshness(false, last + 0.1, last).note == "disconnected, last update 0 s ago");
  CHECK(figures_freshness(false, last + 1.0, last).note == "disconnected, last update 1 s ago");
  CHECK(figures_freshness(false, last + 7.9, last).note == "disconnected, last update 7 s ago");
  CHECK(figures_freshness(false, last + 125.0, last).note == "disconnected, last update 125 s ago");
}

TEST_CASE("never connected: nothing is live and nothing claims an update") {
  const Freshness f = figures_freshness(false, 5.0, -1.0);
  CHECK_FALSE(f.live);
  CHECK(f.note == "not connected, no update yet");
}

TEST_CASE("the threads line says how many step out of how many the server has") {
  CHECK(threads_text(1, 2) == "stepping on 1 of 2 threads");
  CHECK(threads_text(2, 2) == "stepping on 2 of 2 threads");
  CHECK(threads_text(1, 1) == "stepping on 1 of 1 thread");
  CHECK(threads_text(0, 4) == "4 threads at most");  // a server that does not say
}

TEST_CASE("the time scale reads real time at 1, slow motion with its factor below, nothing when unknown") {
  CHECK(time_scale_text(1.0f) == "real time");
  CHECK(time_scale_text(0.99f) == "real time");  // pacing jitter, not slow motion
  CHECK(time_scale_text(1.02f) == "real time");
  CHECK(time_scale_text(0.42f) == "slow motion \u00d70.42");
  CHECK(time_scale_text(0.05f) == "slow motion \u00d70.05");
  CHECK(time_scale_text(0.0f) == "-");
}

TEST_CASE("a time scale people set is not slow motion, a shortfall against it is, and paused says so") {
  CHECK(time_scale_text(0.5f, 0.5f) == "\u00d70.50 as set");
  CHECK(time_scale_text(0.49f, 0.5f) == "\u00d70.50 as set");  // jitter
  CHECK(time_scale_text(0.30f, 0.5f) == "slow motion \u00d70.30 (\u00d70.50 set)");
  CHECK(time_scale_text(1.0f, 0.0f) == "real time");  // a server that does not say runs at 1
  CHECK(time_scale_text(0.0f, 1.0f, true) == "paused");
}

TEST_CASE("the control line says first whether this viewer may, then the server's policy") {
  CHECK(control_text(true, "players may") == "yours (P O R [ ] 1-4): players may");
  CHECK(control_text(false, "observers may not") == "not yours: observers may not");
}

TEST_CASE("in line for a sphere, the Player line says next, or how many are ahead") {
  CHECK(in_line_text(0) == "observing, next in line for a sphere");
  CHECK(in_line_text(3) == "observing, in line for a sphere: 3 ahead of you");
}

TEST_CASE("while no server answers, the hint is the exact command that starts one at the address tried") {
  CHECK(server_command_hint("127.0.0.1", "7913") ==
        "To start a server here: build/server/fishtank-server --port 7913");
  CHECK(server_command_hint("localhost", "7878") ==
        "To start a server here: build/server/fishtank-server --port 7878");
  CHECK(server_command_hint("otherhost", "7913") ==
        "To start a server on otherhost: build/server/fishtank-server --bind 0.0.0.0 --port 7913");
  // The server listens on 127.0.0.1 unless told: IPv6 addresses need their own --bind.
  CHECK(server_command_hint("::1", "7878") ==
        "To start a server here: build/server/fishtank-server --bind ::1 --port 7878");
  CHECK(server_command_hint("fe80::1", "7878") ==
        "To start a server on fe80::1: build/server/fishtank-server --bind :: --port 7878");
}

TEST_CASE(
    "a name that does not resolve is to be checked, any other failure gets the command that starts a "
    "server") {
  CHECK(connection_advice("nohost", "7878", "cannot resolve nohost: Host not found (authoritative)") ==
        "Check the host name, or give its IP address.");
  CHECK(connection_advice("127.0.0.1", "7913", "cannot connect: Connection refused") ==
        server_command_hint("127.0.0.1", "7913"));
}
