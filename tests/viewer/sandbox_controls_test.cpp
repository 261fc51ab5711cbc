// The sandbox keys turn into the right commands: P toggles against what the
// newest snapshot says, O pauses first when running, [ and ] walk the time
// scale ladder and stop at its ends, 1-4 choose the scenes by name.

#include "viewer/sandbox_controls.h"

#include <catch2/catch.hpp>

using namespace fishtank;
using namespace fishtank::viewer;

namespace {
// The payload types of frames, in order.
std::vector<wire::Payload> types(const std::vector<protocol::Frame>& frames) {
  std::vector<wire::Payload> out;
  for (const protocol::Frame& f : frames)
    out.push_back(
        protocol::decode_frame(f.data(), f.size(), protocol::Direction::to_server).message->payload_type());
  return out;
}
}  // namespace

TEST_CASE("P pauses a running server and resumes a paused one, O pauses before its step when running") {
  Snapshot running, paused;
  paused.paused = true;
  SandboxKeys p;
  p.toggle_pause = true;
  const auto to_pause = sandbox_frames(p, &running);
  REQUIRE(types(to_pause) == std::vector<wire::Payload>{wire::Payload::Pause});
  CHECK(protocol::decode_frame(to_pause[0].data(), to_pause[0].size(), protocol::Direction::to_server)
            .message->payload_as_Pause()
            ->paused());
  SandboxKeys o;
  o.single_step = true;
  CHECK(types(sandbox_frames(o, &running)) ==
        std::vector<wire::Payload>{wire::Payload::Pause, wire::Payload::Step});
  CHECK(types(sandbox_frames(o, &paused)) == std::vector<wire::Payload>{wire::Payload::Step});
  CHECK(sandbox_frames(p, nullptr).empty());  // nothing known yet: nothing sent
}

TEST_CASE("the slower and faster keys walk the time scale ladder 0.1, 0.25, 0.5, 1 and stop at its ends") {
  CHECK(next_time_scale(1.0f, -1) == 0.5f);
  CHECK(next_time_scale(0.5f, -1) == 0.25f);
  CHECK(next_time_scale(0.1f, -1) == 0.1f);
  CHECK(next_time_scale(0.1f, +1) == 0.25f);
  CHECK(next_time_scale(1.0f, +1) == 1.0f);
  CHECK(next_time_scale(0.3f, -1) == 0.25f);  // set elsewhere, off the ladder
  CHECK(next_time_scale(0.3f, +1) == 0.5f);
}

TEST_CASE("number keys choose the scenes by name, R restarts the one running") {
  Snapshot s;
  SandboxKeys three;
  three.scene = 2;
  const auto frames = sandbox_frames(three, &s);
  REQUIRE(frames.size() == 1);
  const auto r = protocol::decode_frame(frames[0].data(), frames[0].size(), protocol::Direction::to_server);
  CHECK(r.message->payload_as_Reset()->scene()->str() == "dam-break");
  SandboxKeys reset;
  reset.reset = true;
  const auto again = sandbox_frames(reset, &s);
  const auto a = protocol::decode_frame(again[0].data(), again[0].size(), protocol::Direction::to_server);
  CHECK(a.message->payload_as_Reset()->scene() == nullptr);
}
