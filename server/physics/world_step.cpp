// The world's step: its phases in order (world.h draws them), and the list
// policy that decides when the neighbour lists are rebuilt.

#include <algorithm>
#include <cmath>

#include "server/physics/prefetch_plan.h"
#include "server/physics/world.h"

namespace fishtank {

namespace {

// vel_ carries each ball's mass, as observers expect; the kernels' half-step rows carry 1 / mass.
Float4 half_step_row(const Float4& vel) { return {vel.x, vel.y, vel.z, 1.0f / vel.w}; }

}  // namespace

float World::kick_drift(std::uint32_t i, const Float4& a) {
  const Float4 v = half_step_row(vel_[i]);
  const float d2 = fishtank::kick_drift(model_, v, pos_[i], a, pos_at_build_[i], vel_half_next_[i], pos_next_[i]);
  // Half a step before v, by the same a: what the step after next reads as the velocity a step earlier.
  vel_half_[i] = {v.x - a.x * model_.half_dt, v.y - a.y * model_.half_dt, v.z - a.z * model_.half_dt, v.w};
  fastest_next_ = std::max(fastest_next_, std::sqrt(squared_length3(vel_half_next_[i])));
  return d2;
}

void World::bound_lead(float fastest) {
  // A pair closes at most at the sum of its speeds; the rounding of v_n is covered by the margin.
  constexpr float kMargin = 1.001f;
  const float other = player_pos_.empty() ? fastest : std::max(fastest, params_.player_max_speed);
  model_.lead_bound = (fastest + other) * model_.half_dt * kMargin;
}

void World::start_from_current_state() {
  // The half-step velocities come from a(t), with v(t) standing in for v(t - dt/2) in the damping.
  derive_velocities();
  if (needs_rebuild_) rebuild();
  PhaseTimer timer(phase_seconds_.step_pass);
  std::transform(vel_.begin(), vel_.end(), vel_half_.begin(), half_step_row);
  std::copy(vel_half_.begin(), vel_half_.end(), vel_half_before_.begin());  // no last acceleration known
  float fastest = 0.0f;
  for (std::uint32_t i = 0; i < n_; ++i) fastest = std::max(fastest, std::sqrt(squared_length3(vel_[i])));
  bound_lead(fastest);
  const StepContext ctx = context();
  pool_.run(n_,
            [&](std::uint32_t begin, std::uint32_t end, int) { kernels_.accelerations(ctx, acc_.data(), begin, end); });
  next_max_d2_ = fastest_next_ = 0.0f;
  for (std::uint32_t i = 0; i < n_; ++i) next_max_d2_ = std::max(next_max_d2_, kick_drift(i, acc_[i]));
  strayed_listed_ = false;  // this pass lists no strayed balls: past skin / 2 the lists are rebuilt
  needs_initial_forces_ = false;
}

void World::step() {
  if (spawner_.pending() > 0 && steps_ % kSpawnInterval == 0) spawn();
  if (needs_initial_forces_) start_from_current_state();

  // The previous pass's outputs become this step's state; the half-step velocities rotate.
  pos_.swap(pos_next_);
  vel_half_before_.swap(vel_half_);
  vel_half_.swap(vel_half_next_);
  move_players();
  if (needs_rebuild_) {
    rebuild();
  } else if (!lists_hold() || skin_outlasts()) {
    adapt_skin();
    rebuild();
  }

  PhaseTimer timer(phase_seconds_.step_pass);
  bound_lead(fastest_next_);
  std::fill(chunk_moved_.begin(), chunk_moved_.end(), ChunkMoved{});
  StepContext ctx = context();
  // Every ball lists_hold() will count as strayed, and a hair more.
  ctx.arrays.stray_d2 = half_skin_d2() * kStrayMargin;
  ctx.arrays.stray_balls = stray_balls_.data();
  ctx.plan = prefetch_plan(list_, n_, beyond_cache());
  pool_.run(n_, [&](std::uint32_t begin, std::uint32_t end, int chunk) {
    chunk_moved_[chunk] = {begin, kernels_.step(ctx, begin, end)};
  });
  next_max_d2_ = 0.0f;
  float max_v2 = 0.0f;
  for (const ChunkMoved& chunk : chunk_moved_) {
    next_max_d2_ = std::max(next_max_d2_, chunk.moved.max_d2);
    max_v2 = std::max(max_v2, chunk.moved.max_v2);
  }
  fastest_next_ = std::sqrt(max_v2);
  strayed_listed_ = true;
  vel_stale_ = true;
  time_ += model_.dt;
  ++steps_;
}

bool World::lists_hold() {
  // Two balls that each moved at most skin / 2 cannot have closed the skin unseen. Past that the
  // lists are kept while every strayed ball touches only listed balls and checking costs less than rebuilding.
  if (next_max_d2_ <= half_skin_d2()) return true;
  if (!strayed_listed_ || !std::isfinite(next_max_d2_)) return false;
  const float moved = std::sqrt(next_max_d2_);
  if (!list_.can_check(moved)) return false;
  // Each chunk listed its strayed balls from its begin: gather them to the front.
  std::uint32_t strayed = 0;
  for (const ChunkMoved& chunk : chunk_moved_) {
    std::copy_n(stray_balls_.begin() + chunk.begin, chunk.moved.strayed, stray_balls_.begin() + strayed);
    strayed += chunk.moved.strayed;
  }
  // Kept while this step's checks cost less than the mean per step since the build, the rebuild
  // counted in: in checks, not seconds, so that the choice is the same for any thread count.
  const double cycle_cost = kRebuildCostInChecksPerBall * n_ + double(strayed_checked_ - strayed_checked_at_build_);
  const double steps_since_build = double(steps_ - built_at_step_);
  if (double(strayed) * steps_since_build >= cycle_cost || strayed > n_ / kStrayedBallsPerCheck + 16) return false;
  strayed_checked_ += strayed;
  PhaseTimer timer(phase_seconds_.neighbours), check_timer(phase_seconds_.stray_checks);
  std::fill(chunk_missing_.begin(), chunk_missing_.end(), 0);
  pool_.run_costly(strayed, kStrayChecksPerThread, [&](std::uint32_t begin, std::uint32_t end, int chunk) {
    for (std::uint32_t k = begin; k < end && !chunk_missing_[chunk]; ++k)
      chunk_missing_[chunk] = list_.misses_contact(stray_balls_[k], pos_.data(), pos_at_build_.data(), moved);
  });
  if (std::find(chunk_missing_.begin(), chunk_missing_.end(), 1) != chunk_missing_.end()) return false;
  ++lists_kept_by_checks_;
  return true;
}

bool World::skin_outlasts() const {
  // Lists that last skin x steps = kSkinCostRatio are the cheapest (adapt_skin): ones that last four
  // times that (a pile come to rest) cost more per step than a build with a narrower skin.
  constexpr float kOutlasting = 4.0f;
  return params_.skin == 0.0f && skin() > PhysicsParams::kMinSkin &&
         skin() * float(steps_ - built_at_step_) > kOutlasting * PhysicsParams::kSkinCostRatio;
}

void World::adapt_skin() {
  if (params_.skin > 0.0f) return;
  // The furthest any ball moved since the build, per step. A wider skin makes every step's lists
  // longer and builds rarer (kSkinCostRatio). Counted in steps and distances, not seconds, so every
  // thread count chooses the same skin.
  const float drift = std::sqrt(next_max_d2_) / float(std::max<std::uint64_t>(steps_ - built_at_step_, 1));
  const float skin = std::isfinite(drift) ? std::clamp(std::sqrt(2.0f * PhysicsParams::kSkinCostRatio * drift),
                                                       PhysicsParams::kMinSkin, PhysicsParams::kMaxSkin)
                                          : PhysicsParams::kMaxSkin;
  if (skin != list_.skin()) list_.configure(params_.tank, skin);
}

void World::rebuild() {
  PhaseTimer timer(phase_seconds_.neighbours);
  sort_and_reorder();
  build_lists();
  needs_rebuild_ = false;
  ++rebuilds_;
  built_at_step_ = steps_;
  strayed_checked_at_build_ = strayed_checked_;
}

void World::sort_and_reorder() {
  PhaseTimer timer(phase_seconds_.sort);
  list_.sort(pos_.data(), n_, order_);
  // Gathered in parallel into the next-step buffers and acc_, free here (the next pass rewrites them),
  // which then swap places with the originals.
  kind_scratch_.resize(kind_.size());
  id_scratch_.resize(id_.size());
  pool_.run(n_, [this](std::uint32_t begin, std::uint32_t end, int) {
    for (std::uint32_t k = begin; k < end; ++k) {
      const std::uint32_t from = order_[k];
      pos_next_[k] = pos_at_build_[k] = pos_[from];
      vel_half_next_[k] = vel_half_[from];
      acc_[k] = vel_[from];
      kind_scratch_[k] = kind_[from];
      id_scratch_[k] = id_[from];
    }
  });
  pos_.swap(pos_next_);
  vel_half_.swap(vel_half_next_);
  vel_.swap(acc_);
  kind_.swap(kind_scratch_);
  id_.swap(id_scratch_);
  // The old order's vel_half is free now: it takes vel_half_before's new order.
  pool_.run(n_, [this](std::uint32_t begin, std::uint32_t end, int) {
    for (std::uint32_t k = begin; k < end; ++k) vel_half_next_[k] = vel_half_before_[order_[k]];
  });
  vel_half_before_.swap(vel_half_next_);
  set_ghost();  // the swapped-in buffers' tails
}

void World::build_lists() {
  PhaseTimer timer(phase_seconds_.list_build);
  if (list_.stride() == 0) list_.reserve(n_, 32, kernels_.list_lanes);
  for (;;) {
    list_.reserve(n_, list_.stride(), kernels_.list_lanes);
    std::fill(chunk_longest_.begin(), chunk_longest_.end(), 0u);
    ListBuild build = list_.build_view(pos_.data(), n_);
    if (!beyond_cache()) build.remote_rows = nullptr;  // the step asks for nothing ahead
    pool_.run(n_, [&](std::uint32_t begin, std::uint32_t end, int chunk) {
      chunk_longest_[chunk] = kernels_.build_lists(build, begin, end);
    });
    std::uint32_t longest = *std::max_element(chunk_longest_.begin(), chunk_longest_.end());
    if (longest <= list_.stride()) break;
    list_.reserve(n_, longest + 8, kernels_.list_lanes);
  }
}

StepContext World::context() {
  StepContext ctx;
  ctx.model = model_;
  StepArrays& s = ctx.arrays;
  s.pos = pos_.data();
  s.vel_half = vel_half_.data();
  s.vel_half_before = vel_half_before_.data();
  s.pos_next = pos_next_.data();
  s.vel_half_next = vel_half_next_.data();
  s.lists = list_.step_lists(pos_at_build_.data());
  s.player_pos = player_pos_.data();
  s.player_vel = player_vel_.data();
  s.players = static_cast<int>(player_pos_.size());
  s.tank = params_.tank;
  return ctx;
}

}  // namespace fishtank
