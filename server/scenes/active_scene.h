#pragma once
// The scene the interactive server runs, and its (re)starts: at start-up,
// on Reset (the same scene again, perhaps with another seed) and on a switch
// to another preset. Each start empties the world into the scene's tank,
// fills it, and puts the players back near the centre; ball ids restart at 0,
// and start_count() tells clients so (Snapshot.scene_start).

#include <cstdint>
#include <optional>
#include <string>

#include "server/scenes/scene_presets.h"

namespace fishtank {

struct SceneChoice {
  std::string name = "tank";
  std::uint64_t seed = 1;
  std::optional<std::uint32_t> balls;  // every scene's count; empty: each scene's default_balls
  std::uint32_t max_balls = 0;         // most balls a scene or AddBalls may bring; 0: the tank's capacity
};

class ActiveScene {
 public:
  explicit ActiveScene(SceneChoice choice) : choice_(std::move(choice)) {}

  // The tank the first start() needs, to construct the world with.
  TankBounds first_tank() const { return scene_tank(spec()); }
  // (Re)starts in `world`; scene and seed replace the current ones when given.
  // Returns a refusal (the scene took fewer balls than asked) or "".
  std::string start(World& world, const std::optional<std::string>& scene = std::nullopt,
                    std::optional<std::uint64_t> seed = std::nullopt);

  // After a start: "" or why --max-balls could not hold in this scene's tank (its capacity is then the limit).
  const std::string& limit_note() const { return limit_note_; }
  const std::string& name() const { return choice_.name; }
  std::uint64_t seed() const { return choice_.seed; }
  std::uint32_t start_count() const { return starts_; }

 private:
  std::uint32_t asked_balls() const;  // --balls, or the scene's default

  SceneSpec spec() const;

  SceneChoice choice_;
  std::uint32_t starts_ = 0;
  std::string limit_note_;
};

}  // namespace fishtank
