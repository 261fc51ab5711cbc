#include "server/physics/world.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "common/fp_env.h"
#include "server/physics/player_spawn.h"

namespace fishtank {

namespace {

constexpr float kPackingLimit = 0.6f;
constexpr Float4 kGhostVel{0.0f, 0.0f, 0.0f, 1.0f};  // mass 1: the same as vel_ and as a half-step row

// vel_ carries each ball's mass, as observers expect; the kernels' half-step rows carry 1 / mass.
Float4 half_step_row(const Float4& vel) { return {vel.x, vel.y, vel.z, 1.0f / vel.w}; }

float squared_speed(const Float4& v) { return v.x * v.x + v.y * v.y + v.z * v.z; }

class PhaseTimer {
 public:
  explicit PhaseTimer(double& total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  ~PhaseTimer() { total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

 private:
  double& total_;
  std::chrono::steady_clock::time_point start_;
};

std::uint32_t capacity_of(const TankBounds& tank) {
  return static_cast<std::uint32_t>(kPackingLimit * tank.volume() / mean_ball_volume());
}

double ball_energy(const Float4& pos, const Float4& vel, float gravity) {
  const double speed2 = double(vel.x) * vel.x + double(vel.y) * vel.y + double(vel.z) * vel.z;
  return 0.5 * vel.w * speed2 + double(vel.w) * gravity * pos.y;
}

}  // namespace

World::World(const PhysicsParams& params, const Kernels& kernels, int threads, std::uint64_t seed)
    : params_(params),
      model_(make_contact_model(params)),
      kernels_(kernels),
      pool_(kernels.threaded ? threads : 1, kStepBatch),
      spawner_(params.tank, seed) {
  enable_flush_denormals_to_zero();
  list_.configure(params.tank, params.skin);
  capacity_ = capacity_of(params.tank);
  max_balls_ = capacity_;
  chunk_moved_.resize(pool_.max_chunks());
  chunk_missing_.resize(pool_.max_chunks());
  chunk_longest_.resize(pool_.max_chunks());
  resize(0);
}

void World::resize(std::uint32_t n) {
  n_ = n;
  for (auto* v : {&pos_, &vel_, &vel_half_, &pos_next_, &vel_half_next_, &acc_, &pos_at_build_})
    v->resize(n + kGhostSlots);
  kind_.resize(n);
  id_.resize(n);
  stray_balls_.resize(n);
  set_ghost();
}

void World::set_ghost() {
  for (std::uint32_t g = n_; g < n_ + kGhostSlots; ++g) {
    pos_[g] = pos_next_[g] = pos_at_build_[g] = kGhostPos;
    vel_[g] = vel_half_[g] = vel_half_next_[g] = kGhostVel;
    acc_[g] = Float4{};
  }
}

AddResult World::add_balls(std::int64_t count) {
  AddResult result;
  const std::int64_t room = std::max<std::int64_t>(0, std::int64_t(max_balls_) - n_ - spawner_.pending());
  if (count <= 0) {
    result.refusal = "asked to add " + std::to_string(count) + " balls; the count must be positive";
    return result;
  }
  result.accepted = static_cast<std::uint32_t>(std::min(count, room));
  spawner_.enqueue(result.accepted);
  if (result.accepted < count)
    result.refusal = "added " + std::to_string(result.accepted) + " of " + std::to_string(count) +
                     " balls: the tank holds at most " + std::to_string(max_balls_) + " (" + std::to_string(n_) +
                     " in it, " + std::to_string(spawner_.pending() - result.accepted) + " already queued)";
  return result;
}

void World::place_ball(int kind, Vec3 p, Vec3 v) {
  derive_velocities();  // the others' velocities become the start of the next pass
  const BallKind& k = kBallKinds.at(kind);
  std::uint32_t i = n_;
  resize(n_ + 1);
  pos_[i] = {p.x, p.y, p.z, 0.5f * k.diameter};
  vel_[i] = {v.x, v.y, v.z, k.mass};
  kind_[i] = static_cast<std::uint8_t>(kind);
  id_[i] = next_id_++;
  energy_added_ += ball_energy(pos_[i], vel_[i], model_.gravity);
  needs_rebuild_ = true;
  needs_initial_forces_ = true;
}

void World::restart(const TankBounds& tank, std::uint64_t seed) {
  params_.tank = tank;
  model_.tank = tank;
  list_.configure(tank, params_.skin);
  spawner_ = Spawner(tank, seed);
  capacity_ = capacity_of(tank);
  max_balls_ = capacity_;
  resize(0);
  next_id_ = 0;
  energy_added_ = 0.0;
  vel_stale_ = false;
  strayed_listed_ = false;
  needs_initial_forces_ = false;
  needs_rebuild_ = true;
}

void World::respawn_players() {
  derive_velocities();
  for (std::size_t p = 0; p < player_pos_.size(); ++p) {
    // Avoids the players placed before it in this loop, not the old places of the others.
    const Vec3 at = choose_player_spawn(params_.tank, player_pos_.data(), p, pos_.data(), n_);
    player_pos_[p] = {at.x, at.y, at.z, 0.5f * kPlayerDiameter};
    player_vel_[p] = {};
  }
  if (n_ > 0) needs_initial_forces_ = true;  // a ball a player now touches feels it from the next step's first kick
}

std::uint32_t World::add_player() {
  std::uint32_t id = next_player_id_++;
  const Vec3 at = choose_player_spawn(params_.tank, player_pos_.data(), player_pos_.size(), pos_.data(), n_);
  player_ids_.push_back(id);
  player_pos_.push_back({at.x, at.y, at.z, 0.5f * kPlayerDiameter});
  player_vel_.push_back({});
  return id;
}

bool World::remove_player(std::uint32_t id) {
  auto it = std::find(player_ids_.begin(), player_ids_.end(), id);
  if (it == player_ids_.end()) return false;
  auto k = it - player_ids_.begin();
  player_ids_.erase(it);
  player_pos_.erase(player_pos_.begin() + k);
  player_vel_.erase(player_vel_.begin() + k);
  return true;
}

bool World::set_player_velocity(std::uint32_t id, Vec3 v) {
  auto it = std::find(player_ids_.begin(), player_ids_.end(), id);
  if (it == player_ids_.end() || !is_finite(v)) return false;
  // In double: a finite float velocity's squared length can overflow a float.
  const double speed = std::sqrt(double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z);
  if (speed > params_.player_max_speed) v = v * static_cast<float>(params_.player_max_speed / speed);
  player_vel_[it - player_ids_.begin()] = {v.x, v.y, v.z, 0.0f};
  return true;
}

Vec3 World::player_position(std::uint32_t id) const {
  auto it = std::find(player_ids_.begin(), player_ids_.end(), id);
  if (it == player_ids_.end()) return {};
  const Float4& p = player_pos_[it - player_ids_.begin()];
  return {p.x, p.y, p.z};
}

void World::move_players() {
  // Kinematic: the sphere goes where it is told, stopping at the walls.
  const TankBounds& t = params_.tank;
  for (std::size_t p = 0; p < player_pos_.size(); ++p) {
    Float4& pos = player_pos_[p];
    Float4& vel = player_vel_[p];
    float* x[3] = {&pos.x, &pos.y, &pos.z};
    float* v[3] = {&vel.x, &vel.y, &vel.z};
    const float lo[3] = {t.min.x, t.min.y, t.min.z}, hi[3] = {t.max.x, t.max.y, t.max.z};
    for (int a = 0; a < 3; ++a) {
      *x[a] += *v[a] * model_.dt;
      if (*x[a] < lo[a] + pos.w || *x[a] > hi[a] - pos.w) {
        *x[a] = std::clamp(*x[a], lo[a] + pos.w, hi[a] - pos.w);
        *v[a] = 0.0f;
      }
    }
  }
}

void World::spawn() {
  PhaseTimer timer(phase_seconds_.spawn);
  derive_velocities();  // while vel_half_ and vel_half_next_ are still the last pass's
  placed_.clear();
  spawner_.place(pos_.data(), n_, player_pos_.data(), static_cast<int>(player_pos_.size()), placed_);
  if (placed_.empty()) return;
  std::uint32_t first = n_;
  resize(n_ + static_cast<std::uint32_t>(placed_.size()));
  for (std::size_t b = 0; b < placed_.size(); ++b) {
    std::uint32_t i = first + static_cast<std::uint32_t>(b);
    pos_[i] = placed_[b].pos;
    vel_[i] = placed_[b].vel;
    kind_[i] = static_cast<std::uint8_t>(placed_[b].kind);
    id_[i] = next_id_++;
    energy_added_ += ball_energy(pos_[i], vel_[i], model_.gravity);
    // A spawned ball touches nothing, so gravity is its whole acceleration (and the lists are rebuilt).
    kick_drift(i, Float4{0.0f, -model_.gravity, 0.0f, 0.0f});
  }
  needs_rebuild_ = true;
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

StepArrays World::arrays() {
  StepArrays s;
  s.pos = pos_.data();
  s.vel_half = vel_half_.data();
  s.pos_next = pos_next_.data();
  s.vel_half_next = vel_half_next_.data();
  s.lists = list_.step_lists(pos_at_build_.data());
  s.player_pos = player_pos_.data();
  s.player_vel = player_vel_.data();
  s.players = static_cast<int>(player_pos_.size());
  return s;
}

PrefetchPlan World::prefetch_plan() const {
  PrefetchPlan plan;
  plan.beyond_cache = beyond_cache();
  plan.remote_rows = list_.remote_rows();
  plan.batches = (n_ + kStepBatch - 1) / kStepBatch;
  return plan;
}

// Neighbouring chunks' threads read each other's edge rows, and each such line
// comes by a transfer between cores. So a chunk asks for them ahead, while
// batches that do not need them run: the rows below its first ball at once
// (running first the batches after those that read them), the rows around
// its last ball over the few batches before. Larger ranges are left to the hardware.
void World::add_edge_fetches(PrefetchPlan& plan, std::uint32_t begin, std::uint32_t end) const {
  constexpr std::uint32_t kBelowWindow = 2, kAboveWindow = 4;  // batches
  constexpr std::uint32_t kMostRowsPerBall = 4;
  const BatchReach* reach = list_.batch_reach();
  const std::uint32_t first = begin / kStepBatch, last = (end + kStepBatch - 1) / kStepBatch;
  const std::uint32_t batches = (n_ + kStepBatch - 1) / kStepBatch;
  RowFetch* fetch = plan.edge_fetch;
  const auto add = [&](RowFetch f) {
    if (f.rows_begin < f.rows_end &&
        f.rows_end - f.rows_begin <= (f.end_batch - f.first_batch) * kStepBatch * kMostRowsPerBall)
      *fetch++ = f;
  };
  if (begin > 0) {
    std::uint32_t lowest = begin, lead = first;  // lead: the first batch that reads no row below
    for (std::uint32_t b = first; b < last; ++b) lowest = std::min(lowest, reach[b].lowest);
    while (lead < last && reach[lead].lowest < begin) ++lead;
    if (lead == last) lead = first;  // every batch reads below: no batch to run meanwhile
    const std::uint32_t lead_end = std::min(last, lead + kBelowWindow);
    if (lead > first) plan.lead_begin = lead * kStepBatch, plan.lead_end = std::min(end, lead_end * kStepBatch);
    add({lowest, begin, lead, lead_end});
  }
  if (end < n_) {
    std::uint32_t lowest = end, highest = end - 1;  // [lowest, highest]: rows both threads read
    for (std::uint32_t b = last; b < batches; ++b) lowest = std::min(lowest, reach[b].lowest);
    for (std::uint32_t b = first; b < last; ++b) highest = std::max(highest, reach[b].highest);
    std::uint32_t reader = first;  // this chunk's first batch that reads them
    while (reader + 1 < last && reach[reader].highest < lowest) ++reader;
    add({lowest, highest + 1, std::max(first, reader - std::min(reader, kAboveWindow)), std::max(reader, first + 1)});
  }
}

float World::kick_drift(std::uint32_t i, const Float4& a) {
  const float d2 = fishtank::kick_drift(model_, half_step_row(vel_[i]), pos_[i], a, pos_at_build_[i], vel_half_next_[i],
                                        pos_next_[i]);
  fastest_next_ = std::max(fastest_next_, std::sqrt(squared_speed(vel_half_next_[i])));
  return d2;
}

void World::bound_lead(float fastest) {
  // A pair closes at most at the sum of its speeds; the rounding of v_n is covered by the margin.
  constexpr float kMargin = 1.001f;
  const float other = player_pos_.empty() ? fastest : std::max(fastest, params_.player_max_speed);
  model_.lead_bound = (fastest + other) * model_.half_dt * kMargin;
}

// v(t) is the mean of vel_half = v(t - dt/2) and vel_half_next = v(t + dt/2): derived for observers,
// who look a few dozen times a second, instead of stored by every step.
void World::derive_velocities() const {
  if (!vel_stale_) return;
  for (std::uint32_t i = 0; i < n_; ++i) {
    const Float4 before = vel_half_[i], after = vel_half_next_[i];
    const float mass = kBallKinds[kind_[i]].mass;  // the rows carry 1 / mass
    vel_[i] = {0.5f * (before.x + after.x), 0.5f * (before.y + after.y), 0.5f * (before.z + after.z), mass};
  }
  vel_stale_ = false;
}

const Float4* World::velocities() const {
  derive_velocities();
  return vel_.data();
}

void World::start_from_current_state() {
  // The half-step velocities come from a(t), with v(t) standing in for v(t - dt/2) in the damping.
  derive_velocities();
  if (needs_rebuild_) rebuild();
  PhaseTimer timer(phase_seconds_.step_pass);
  std::transform(vel_.begin(), vel_.end(), vel_half_.begin(), half_step_row);
  float fastest = 0.0f;
  for (std::uint32_t i = 0; i < n_; ++i) fastest = std::max(fastest, std::sqrt(squared_speed(vel_[i])));
  bound_lead(fastest);
  StepArrays s = arrays();
  pool_.run(n_, [&](std::uint32_t begin, std::uint32_t end, int) {
    kernels_.accelerations(s, model_, acc_.data(), begin, end);
  });
  next_max_d2_ = fastest_next_ = 0.0f;
  for (std::uint32_t i = 0; i < n_; ++i) next_max_d2_ = std::max(next_max_d2_, kick_drift(i, acc_[i]));
  strayed_listed_ = false;  // this pass lists no strayed balls: past skin / 2 the lists are rebuilt
  needs_initial_forces_ = false;
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

void World::set_thread_tuning(bool on) {
  if (!on) {
    tuner_.reset();
    return;
  }
  tuner_.emplace(pool_.threads());
  tuner_epoch_ = std::chrono::steady_clock::now();
  set_thread_limit(tuner_->threads());
}

int World::stepping_threads() const { return tuner_ ? tuner_->chosen() : pool_.active_limit(); }

void World::step() {
  one_thread_steps_ += pool_.active_limit() == 1;
  if (!tuner_) {
    advance();
    return;
  }
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  advance();
  const Clock::time_point end = Clock::now();
  const auto seconds = [](Clock::duration d) { return std::chrono::duration<double>(d).count(); };
  const double now = seconds(end - tuner_epoch_);
  machine_load_.update(now);  // after the step's clock: a reading is not a step's cost
  using Load = ThreadTuner::Load;
  const Load load = !machine_load_.room_for(pool_.threads()) ? Load::kOneThread
                    : machine_load_.shared_per_thread()      ? Load::kEveryThread
                                                             : Load::kMeasure;
  set_thread_limit(tuner_->record(seconds(end - start), 1, now, load));
}

void World::advance() {
  if (spawner_.pending() > 0 && steps_ % kSpawnInterval == 0) spawn();
  if (needs_initial_forces_) start_from_current_state();

  // The previous pass's outputs become this step's state.
  pos_.swap(pos_next_);
  vel_half_.swap(vel_half_next_);
  move_players();
  if (needs_rebuild_ || !lists_hold()) rebuild();

  PhaseTimer timer(phase_seconds_.step_pass);
  bound_lead(fastest_next_);
  std::fill(chunk_moved_.begin(), chunk_moved_.end(), ChunkMoved{});
  StepArrays s = arrays();
  s.stray_d2 = half_skin_d2() * kStrayMargin;  // every ball lists_hold() will count as strayed, and a hair more
  s.stray_balls = stray_balls_.data();
  const PrefetchPlan plan = prefetch_plan();
  pool_.run(n_, [&](std::uint32_t begin, std::uint32_t end, int chunk) {
    PrefetchPlan chunk_plan = plan;
    add_edge_fetches(chunk_plan, begin, end);
    chunk_moved_[chunk] = {begin, kernels_.step(s, chunk_plan, model_, begin, end)};
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

double World::mean_neighbours() const {
  if (n_ == 0 || list_.stride() == 0) return 0.0;
  double sum = 0.0;
  for (std::uint32_t i = 0; i < n_; ++i) sum += list_.counts()[i];
  return sum / n_;
}

BallView World::ball(std::uint32_t id) const {
  derive_velocities();
  for (std::uint32_t i = 0; i < n_; ++i)
    if (id_[i] == id) return {pos_[i], vel_[i], kind_[i]};
  return {Float4{}, Float4{}, -1};
}

double World::kinetic_energy() const {
  derive_velocities();
  double e = 0.0;
  for (std::uint32_t i = 0; i < n_; ++i) e += ball_energy(pos_[i], vel_[i], 0.0f);
  return e;
}

float World::max_speed() const {
  derive_velocities();
  float fastest2 = 0.0f;
  for (std::uint32_t i = 0; i < n_; ++i) fastest2 = std::max(fastest2, squared_speed(vel_[i]));
  return std::sqrt(fastest2);
}

double World::potential_energy() const {
  derive_velocities();  // vel_'s w is the mass, also of balls placed since the last step
  double e = 0.0;
  for (std::uint32_t i = 0; i < n_; ++i) e += double(vel_[i].w) * model_.gravity * pos_[i].y;
  return e;
}

double World::elastic_energy() const {
  if (needs_rebuild_) return 0.0;  // no lists yet: nothing has been stepped
  const TankBounds& t = params_.tank;
  double sum_x2 = 0.0;
  list_.for_each_list([&](std::uint32_t i, ListView list) {
    const Float4& p = pos_[i];
    for (std::uint32_t n = 0; n < list.count; ++n) {
      const Float4& q = pos_[list[n]];
      double dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z;
      double overlap = p.w + q.w - std::sqrt(dx * dx + dy * dy + dz * dz);
      if (overlap > 0.0) sum_x2 += 0.5 * overlap * overlap;  // each pair is listed from both sides
    }
  });
  for (std::uint32_t i = 0; i < n_; ++i) {
    const Float4& p = pos_[i];
    for (double overlap : {t.min.x + p.w - p.x, p.x + p.w - t.max.x, t.min.y + p.w - p.y, p.y + p.w - t.max.y,
                           t.min.z + p.w - p.z, p.z + p.w - t.max.z})
      if (overlap > 0.0) sum_x2 += overlap * overlap;
  }
  return 0.5 * model_.k * sum_x2;
}

std::string World::set_max_balls(std::uint32_t max_balls) {
  if (max_balls <= capacity_) {
    max_balls_ = max_balls;
    return "";
  }
  char text[160];
  std::snprintf(text, sizeof text,
                "the tank holds at most %u balls of the default mix (packing fraction %.2g); asked for %u", capacity_,
                double(kPackingLimit), max_balls);
  return text;
}

std::string World::overlap_warning() const {
  const float overlap = max_overlap_fraction();
  if (!overlap_too_deep(overlap) || kinetic_energy() > kRestingEnergyPerBall * n_) return "";
  char text[160];
  std::snprintf(text, sizeof text,
                "largest resting overlap %.0f %% of the smaller radius (over %.0f %%): k = %g N/m is too soft",
                100.0 * overlap, 100.0 * kOverlapWarning, double(model_.k));
  return text;
}

std::uint32_t World::contact_count() const {
  if (needs_rebuild_) return 0;  // no lists yet: nothing has been stepped
  const TankBounds& t = params_.tank;
  std::uint32_t sides = 0;  // each pair is listed from both sides
  list_.for_each_list([&](std::uint32_t i, ListView list) {
    const Float4& p = pos_[i];
    for (std::uint32_t n = 0; n < list.count; ++n) {
      const Float4& q = pos_[list[n]];
      float dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z, reach = p.w + q.w;
      sides += dx * dx + dy * dy + dz * dz < reach * reach;
    }
  });
  std::uint32_t walls = 0;
  for (std::uint32_t i = 0; i < n_; ++i) {
    const Float4& p = pos_[i];
    walls += (p.x - p.w < t.min.x) + (p.x + p.w > t.max.x) + (p.y - p.w < t.min.y) + (p.y + p.w > t.max.y) +
             (p.z - p.w < t.min.z) + (p.z + p.w > t.max.z);
  }
  return sides / 2 + walls;
}

float World::max_overlap_fraction() const {
  float worst = 0.0f;
  const TankBounds& t = params_.tank;
  // The neighbour list holds every touching pair (stale only between a spawn and the next step).
  if (!needs_rebuild_) {
    list_.for_each_list([&](std::uint32_t i, ListView list) {
      const Float4& p = pos_[i];
      for (std::uint32_t n = 0; n < list.count; ++n) {
        const Float4& q = pos_[list[n]];
        float dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z;
        float overlap = p.w + q.w - std::sqrt(dx * dx + dy * dy + dz * dz);
        worst = std::max(worst, overlap / std::min(p.w, q.w));
      }
    });
  }
  for (std::uint32_t i = 0; i < n_; ++i) {
    const Float4& p = pos_[i];
    float walls = std::max({t.min.x + p.w - p.x, p.x + p.w - t.max.x, t.min.y + p.w - p.y, p.y + p.w - t.max.y,
                            t.min.z + p.w - p.z, p.z + p.w - t.max.z});
    worst = std::max(worst, walls / p.w);
  }
  return worst;
}

float World::pile_top() const {
  float top = params_.tank.min.y;
  for (std::uint32_t i = 0; i < n_; ++i) top = std::max(top, pos_[i].y + pos_[i].w);
  return top;
}

std::uint32_t World::escaped_or_invalid() const {
  derive_velocities();
  const TankBounds& t = params_.tank;
  std::uint32_t bad = 0;
  for (std::uint32_t i = 0; i < n_; ++i) {
    const Float4& p = pos_[i];
    const Float4& v = vel_[i];
    bool inside = p.x >= t.min.x && p.x <= t.max.x && p.y >= t.min.y && p.y <= t.max.y && p.z >= t.min.z &&
                  p.z <= t.max.z;  // false for NaN
    bool finite = std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    if (!inside || !finite) ++bad;
  }
  return bad;
}

std::uint64_t World::state_hash() const {
  derive_velocities();
  std::vector<std::uint32_t> by_id(n_);
  for (std::uint32_t i = 0; i < n_; ++i) by_id[id_[i]] = i;
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* data, std::size_t bytes) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) h = (h ^ b[k]) * 1099511628211ull;
  };
  for (std::uint32_t i : by_id) {
    mix(&pos_[i], sizeof(Float4));
    mix(&vel_[i], sizeof(Float4));
  }
  return h;
}

}  // namespace fishtank
