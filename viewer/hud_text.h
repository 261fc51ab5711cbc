#pragma once
// What the HUD says, decided apart from ImGui so that it can be tested: whether
// the server's figures are live or left over from a lost connection, how many
// threads step, and how fast simulated time runs.

#include <cstdint>
#include <optional>
#include <string>

namespace fishtank::viewer {

struct Freshness {
  bool live = true;  // false: the server's figures are old and drawn greyed
  std::string note;  // why they are not live, e.g. "disconnected, last update 7 s ago"; empty when live
};

// connected: a Welcome arrived on the current connection. last_update: when
// the newest snapshot arrived (steady seconds, like now); negative if none did.
Freshness figures_freshness(bool connected, double now, double last_update);

// "stepping on 1 of 2 threads"; "2 threads at most" when the server did not say.
std::string threads_text(std::uint32_t stepping, int available);

// How fast simulated time runs: "paused"; "real time"; "×0.50 as set" when
// people slowed it; "slow motion ×0.42" (with "(×0.50 set)" when slowed too)
// when the physics cannot keep the pace asked for; "-" when the server did
// not say. time_scale_set 0 (not reported) counts as 1.
std::string time_scale_text(float time_scale, float time_scale_set = 1.0f, bool paused = false);

// The largest overlap (Snapshot.max_overlap, a fraction of the smaller radius):
// "4.2 % of the smaller radius", and whether to warn about it: deep while the
// balls rest (Snapshot.kinetic_energy_per_ball, common/overlap.h), not an impact's.
struct OverlapText {
  std::string text;
  bool warn = false;
};
OverlapText overlap_text(float fraction, float energy_per_ball);

// How the server chose its time step: "1.08 ms, 13 steps per contact: each
// collision's e within 0.005"; "0.70 ms (given), 20.0 steps per contact" when
// dt or the steps per contact were given; "1.08 ms" from a server that does
// not say; "-" without a dt.
std::string step_text(float dt, float steps_per_contact, float tolerance);

// Who may use the sandbox's controls, for the HUD: this viewer's part, then the policy.
std::string control_text(bool may_control, const std::string& policy);

// The Player line while in line for a sphere (InLine): "observing, next in line for a sphere", or how many
// are ahead.
std::string in_line_text(std::uint32_t ahead);

}  // namespace fishtank::viewer
