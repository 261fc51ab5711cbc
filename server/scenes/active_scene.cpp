#include "server/scenes/active_scene.h"

namespace fishtank {

SceneSpec ActiveScene::spec() const {
  SceneSpec spec;
  spec.name = choice_.name;
  spec.seed = choice_.seed;
  spec.balls = choice_.balls.value_or(default_balls(choice_.name));
  return spec;
}

std::string ActiveScene::start(World& world, const std::optional<std::string>& scene,
                               std::optional<std::uint64_t> seed) {
  if (scene) choice_.name = *scene;
  if (seed) choice_.seed = *seed;
  const SceneSpec s = spec();
  world.restart(scene_tank(s), s.seed);
  // Refused by a scene whose tank holds fewer: its capacity is then the limit, and the note says so.
  limit_note_.clear();
  if (choice_.max_balls > 0)
    if (const std::string refusal = world.set_max_balls(choice_.max_balls); !refusal.empty())
      limit_note_ = "scene " + choice_.name + ": --max-balls: " + refusal + "; the tank's capacity is the limit";
  std::string refusal;
  SceneSpec placed = s;
  // --max-balls bounds every scene, not only what AddBalls pours in.
  if (choice_.max_balls > 0 && placed.balls > choice_.max_balls) {
    placed.balls = choice_.max_balls;
    refusal = "the " + s.name + " scene: --max-balls lets in " + std::to_string(placed.balls) + " of the " +
              std::to_string(s.balls) + " balls asked for";
  }
  if (std::string fewer = populate(world, placed); !fewer.empty()) refusal = fewer;
  world.respawn_players();
  ++starts_;
  return refusal;
}

}  // namespace fishtank
