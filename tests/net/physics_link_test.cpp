// The physics thread's side of the network (PhysicsLink), driven directly: the
// commands queued between two step boundaries, and the answers it hands back.

#include "server/net/physics_link.h"

#include <catch2/catch.hpp>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "server/physics/world_measures.h"

using namespace fishtank;
using namespace fishtank::net;

namespace {

struct Link {
  CommandQueue queue;
  std::atomic<int> viewers{0};
  RunControl control;
  ActiveScene scene{SceneChoice{"tank", 1, 200, 0}};
  std::vector<Reply> replies;
  std::vector<SharedSnapshot> published;
  World world;
  PhysicsLink link;

  Link()
      : world(params(), kSseKernels, 1, 1),
        link(
            queue, viewers, PhysicsLinkOptions{}, control, scene, [this](Reply r) { replies.push_back(std::move(r)); },
            [this](SharedSnapshot s) { published.push_back(std::move(s)); }) {
    REQUIRE(scene.start(world).empty());
  }
  PhysicsParams params() const {
    PhysicsParams p;
    p.tank = scene.first_tank();
    return p;
  }
  void reset(std::uint32_t client, const std::string& scene_name) {
    REQUIRE(queue.push(Command{client, ResetCommand{scene_name, std::nullopt}}));
  }
  // The refusals of client's controls, in order.
  std::vector<ControlRefusedReply::Why> refusals_of(std::uint32_t client) const {
    std::vector<ControlRefusedReply::Why> out;
    for (const Reply& r : replies)
      if (const auto* refused = std::get_if<ControlRefusedReply>(&r.result); refused && r.client_id == client)
        out.push_back(refused->why);
    return out;
  }
};

}  // namespace

TEST_CASE(
    "of resets queued at one step boundary only the last is carried out, and another client's earlier one is told",
    "[net][sandbox]") {
  Link l;
  const std::uint32_t starts = l.scene.start_count();
  l.reset(1, "drop");
  l.reset(1, "wide");
  l.reset(2, "dam-break");
  l.link.at_step_boundary(l.world, LoopStatus{});

  CHECK(l.scene.start_count() == starts + 1);
  CHECK(l.scene.name() == "dam-break");
  // Client 1's switches did not happen and it hears so, once for each; client 2's did, without a word.
  CHECK(l.refusals_of(1) == std::vector<ControlRefusedReply::Why>{ControlRefusedReply::Why::superseded,
                                                                  ControlRefusedReply::Why::superseded});
  CHECK(l.refusals_of(2).empty());
}

TEST_CASE("a client's own later reset replaces its earlier one without a refusal", "[net][sandbox]") {
  Link l;
  l.reset(3, "drop");
  l.reset(3, "wide");
  l.link.at_step_boundary(l.world, LoopStatus{});
  CHECK(l.scene.name() == "wide");
  CHECK(l.replies.empty());
}

TEST_CASE(
    "a reset at the next step boundary, before four times the last one's restart has passed, is refused as too "
    "soon and changes nothing",
    "[net][sandbox]") {
  Link l;
  // A restart of 200 balls is quick, so its spacing is short: a thread descheduled between the two boundaries
  // could outlast it, so the pair is tried a few times.
  bool refused = false;
  for (int attempt = 0; attempt < 5 && !refused; ++attempt) {
    if (attempt > 0) std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the last restart's spacing
    l.replies.clear();
    l.reset(4, "drop");
    l.link.at_step_boundary(l.world, LoopStatus{});
    REQUIRE(l.scene.name() == "drop");
    const std::uint32_t starts = l.scene.start_count();
    l.reset(4, "wide");
    l.link.at_step_boundary(l.world, LoopStatus{});
    if (l.refusals_of(4) == std::vector<ControlRefusedReply::Why>{ControlRefusedReply::Why::too_soon}) {
      refused = true;
      CHECK(l.scene.start_count() == starts);
      CHECK(l.scene.name() == "drop");
    }
  }
  CHECK(refused);
}

TEST_CASE(
    "paused, a snapshot after steps carries the energy, contacts and overlap of its own step, however soon "
    "the steps follow the last figures",
    "[net][sandbox]") {
  Link l;
  l.viewers = 1;
  l.control.paused = true;
  const auto snapshot_after = [&l](int steps) {
    for (int i = 0; i < steps; ++i) l.world.step();              // as the loop runs a Step while paused
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // past the next snapshot's time (60 a second)
    const std::size_t before = l.published.size();
    l.link.at_step_boundary(l.world, LoopStatus{});
    REQUIRE(l.published.size() == before + 1);
    return l.published.back()->header;
  };
  snapshot_after(300);  // balls pouring in and falling: the energy changes every step
  for (int steps : {1, 5, 40}) {
    INFO(steps << " steps after the last snapshot, well within the figures' period");
    const protocol::SnapshotHeader h = snapshot_after(steps);
    const ContactFigures now = contact_figures(l.world);
    CHECK(h.physics_steps == l.world.steps());
    CHECK(h.kinetic_energy_per_ball == static_cast<float>(kinetic_energy(l.world) / l.world.ball_count()));
    CHECK(h.contacts == now.contacts);
    CHECK(h.max_overlap == now.max_overlap);
  }
}

TEST_CASE("a snapshot's capture is counted in CPU time too, for the status line's net cpu, never above its wall time",
          "[net]") {
  Link l;
  l.viewers = 1;
  for (int i = 0; i < 200; ++i) l.world.step();
  l.link.at_step_boundary(l.world, LoopStatus{});
  const SnapshotStats& stats = l.link.snapshot_stats();
  REQUIRE(stats.encoded == 1);
  CHECK(stats.encode_cpu_seconds > 0.0);
  CHECK(stats.encode_cpu_seconds <= stats.encode_seconds + 1e-4);  // the two clocks' resolution apart
}
