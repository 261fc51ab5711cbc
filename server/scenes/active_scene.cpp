#include "server/scenes/active_scene.h"

#include <algorithm>

namespace fishtank {

std::uint32_t ActiveScene::asked_balls() const { return choice_.balls.value_or(default_balls(choice_.name)); }

SceneSpec ActiveScene::spec() const {
  SceneSpec spec;
  spec.name = choice_.name;
  spec.seed = choice_.seed;
  // --max-balls bounds every scene, not only what AddBalls pours in; the wide scene's tank is sized for it.
  spec.balls = choice_.max_balls > 0 ? std::min(asked_balls(), choice_.max_balls) : asked_balls();
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
  std::string refusal = populate(world, s);
  if (const std::uint32_t asked = asked_balls(); s.balls < asked) {
    const std::string cap =
        "--max-balls lets in " + std::to_string(s.balls) + " of the " + std::to_string(asked) + " balls asked for";
    refusal = refusal.empty() ? "the " + s.name + " scene: " + cap : refusal + " (" + cap + ")";
  }
  world.respawn_players();
  ++starts_;
  return refusal;
}

}  // namespace fishtank
