#pragma once
// What the HUD says, decided apart from ImGui so that it can be tested: whether
// the server's figures are live or left over from a lost connection, how many
// threads step, and how fast simulated time runs.

#include <cstdint>
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

// "real time", "slow motion ×0.42", or "-" when the server did not say.
std::string time_scale_text(float time_scale);

}  // namespace fishtank::viewer
