#pragma once
// Headless benchmark: build a scene, let it settle, time unpaced steps, and
// describe the run as one JSON object.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "server/bench/scenes.h"
#include "server/physics/world.h"

namespace fishtank {

struct BenchSpec {
  SceneSpec scene;
  std::uint64_t steps = 2000;
  std::uint32_t windows = 5;  // the timed steps are split into this many windows; rates are their median
};

// Runs the timed part on an already settled world and returns the report.
nlohmann::json time_steps(TunedStepper& stepper, const BenchSpec& spec, const SettleReport& settle);

}  // namespace fishtank
