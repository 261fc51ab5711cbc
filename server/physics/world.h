#pragma once
// The simulated world: ball state, the spawn queue, player spheres, and the
// fixed-dt step. Only the thread that owns a World touches it. One concept per file:
//   world.cpp           state and admission: balls queued, placed, spawned; restart
//   world_players.cpp   the kinematic player spheres
//   world_step.cpp      the step and its list policy (below)
//   prefetch_plan.h     what the SIMD step asks memory for ahead
//   world_measures.h    what observers measure: energies, overlaps, contacts, the state hash
//
// One step (world_step.cpp, World::step()):
//
//   spawn round (every kSpawnInterval steps while balls are queued)
//   swap           the last pass's pos_next, vel_half_next become pos, vel_half
//                  (and vel_half becomes vel_half_before)
//   players move   (serial, few)
//   rebuild?       if a ball strayed > skin/2 and the lists miss one of its
//                  contacts (or checking costs more), or the lists outlast their
//                  cost: adapt the skin, sort by cell, reorder, new lists
//   step pass    ║ parallel over balls (kernels.h): a = F/m + g, v = v_half + a dt/2,
//                  then the next half kick and drift into pos_next, vel_half_next
//
// Between steps pos is the state at time() and the next step's positions are
// already computed, so one pass and one barrier make a step. vel is derived
// when asked for: the mean of the half-step velocities either side.
// Every rebuild reorders the balls; ids() gives their permanent numbers.

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common/float4.h"
#include "common/tank.h"
#include "server/physics/broadphase.h"
#include "server/physics/kernels.h"
#include "server/physics/params.h"
#include "server/physics/spawner.h"
#include "server/physics/worker_pool.h"

namespace fishtank {

struct PhaseSeconds {
  double spawn = 0.0;
  double neighbours = 0.0;  // sort, reorder and list build, and checks that keep the lists
  double step_pass = 0.0;   // forces and integration
  // Parts of neighbours: sort and reorder, list build, checks of strayed balls (World::lists_hold).
  double sort = 0.0;
  double list_build = 0.0;
  double stray_checks = 0.0;
};

// Adds the seconds of its scope to a phase's total.
class PhaseTimer {
 public:
  explicit PhaseTimer(double& total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  ~PhaseTimer() { total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

 private:
  double& total_;
  std::chrono::steady_clock::time_point start_;
};

struct AddResult {
  std::uint32_t accepted = 0;
  std::string refusal;  // empty when everything asked for was accepted
};

struct BallView {
  Float4 pos;  // x, y, z, radius
  Float4 vel;  // vx, vy, vz, mass
  int kind;
};

class World {
 public:
  // params must pass validate(). threads is ignored (1) for unthreaded kernels.
  World(const PhysicsParams& params, const Kernels& kernels, int threads, std::uint64_t seed);

  // Queues balls to pour in from the top, up to max_balls() including those queued.
  AddResult add_balls(std::int64_t count);
  // Puts one ball exactly there, without any overlap check (scenes and tests); it may touch others,
  // so the next step starts with a force pass.
  void place_ball(int kind, Vec3 pos, Vec3 vel);
  // Empty when accepted; a refusal saying what fits when max_balls exceeds capacity().
  std::string set_max_balls(std::uint32_t max_balls);
  // Empties the world into a (possibly different) tank, for a scene's start:
  // no balls, nothing queued, spawning reseeded, max_balls() the new capacity.
  // The clock and step count go on (viewers interpolate over them); players
  // stay, until respawn_players() puts them back near the centre.
  void restart(const TankBounds& tank, std::uint64_t seed);
  // Each player at a free point near the centre of the balls now present, at rest.
  void respawn_players();

  // Kinematic player spheres; ids are never reused. Each starts at a free point
  // near the centre, apart from the others (choose_player_spawn).
  std::uint32_t add_player();
  bool remove_player(std::uint32_t id);
  // Desired velocity, clamped to the maximum player speed. False if non-finite or unknown id.
  bool set_player_velocity(std::uint32_t id, Vec3 velocity);
  Vec3 player_position(std::uint32_t id) const;
  std::size_t player_count() const { return player_ids_.size(); }
  const std::vector<std::uint32_t>& player_ids() const { return player_ids_; }
  const Float4* player_positions() const { return player_pos_.data(); }

  void step();
  // Gets the worker threads ready for a step due within a millisecond (see WorkerPool::wake).
  void wake_workers() { pool_.wake(); }

  std::uint32_t ball_count() const { return n_; }
  std::uint32_t pending() const { return spawner_.pending(); }
  std::uint32_t max_balls() const { return max_balls_; }
  // Balls of the default mix that fill the tank to a packing fraction of 0.6.
  std::uint32_t capacity() const { return capacity_; }
  double time() const { return time_; }
  std::uint64_t steps() const { return steps_; }
  std::uint64_t rebuilds() const { return rebuilds_; }
  float skin() const { return list_.skin(); }  // the lists' skin now (PhysicsParams::skin)
  // Whether the SIMD step asks for rows ahead (PrefetchPlan): from PhysicsParams::prefetch_from balls.
  // The scalar twin (one lane) reads its rows in order and asks for none.
  bool beyond_cache() const { return kernels_.list_lanes > 1 && n_ >= params_.prefetch_from; }
  // Steps whose lists were kept after checking the balls that strayed more than skin / 2 (lists_hold()).
  std::uint64_t lists_kept_by_checks() const { return lists_kept_by_checks_; }
  // Balls checked in those steps and in the steps whose checks found a contact.
  std::uint64_t strayed_balls_checked() const { return strayed_checked_; }
  // The lists of the last build, for tests and tools.
  const NeighbourList& neighbour_list() const { return list_; }
  float dt() const { return model_.dt; }
  const PhysicsParams& params() const { return params_; }
  const ContactModel& model() const { return model_; }
  const Kernels& kernels() const { return kernels_; }
  int threads() const { return pool_.threads(); }
  // The CPUs this process could use when the world was made; its pool pins its threads to them.
  const std::vector<int>& cpus() const { return pool_.cpus(); }
  // Steps use at most this many of the threads (results do not depend on it; the paced loop's TunedStepper
  // chooses it).
  void set_thread_limit(int limit) { pool_.set_active_limit(limit); }
  int thread_limit() const { return pool_.active_limit(); }
  // The threads a step's passes over the balls split over now: the limit, or one for too few balls.
  int stepping_threads() const { return pool_.threads_for(ball_count()); }
  // Each thread's fraction of the items of every pass since reset_thread_shares().
  std::vector<double> thread_shares() const { return pool_.shares(); }
  void reset_thread_shares() { pool_.reset_shares(); }
  // For tests: runs on a worker thread as it picks up each pass (WorkerPool::set_worker_hook).
  void set_worker_hook(std::function<void(int thread)> hook) { pool_.set_worker_hook(std::move(hook)); }
  const PhaseSeconds& phase_seconds() const { return phase_seconds_; }
  // Whether the lists hold the balls now present: false before the first step and from a spawn or a
  // placement to the next step.
  bool lists_current() const { return !needs_rebuild_; }

  // Current (sorted) order; index with i < ball_count().
  const Float4* positions() const { return pos_.data(); }
  const Float4* velocities() const;
  const std::uint8_t* kinds() const { return kind_.data(); }
  const std::uint32_t* ids() const { return id_.data(); }
  // The ball with permanent number id (linear search: for tests and tools).
  BallView ball(std::uint32_t id) const;

  // Kinetic plus gravitational energy of every ball at the moment it appeared:
  // with no player moving, the world's total energy can never exceed it.
  double energy_added() const { return energy_added_; }

  static constexpr int kSpawnInterval = 20;

 private:
  void spawn();
  // Sorts the balls by cell, reorders every per-ball array, builds the lists.
  void rebuild();
  void sort_and_reorder();
  void build_lists();
  // Whether the lists still hold every contact of the next step's positions.
  bool lists_hold();
  float half_skin_d2() const { return 0.25f * skin() * skin(); }  // (skin / 2)^2
  // With PhysicsParams::skin 0, the skin for the next build, from how far balls moved per step since the last.
  void adapt_skin();
  // Whether the lists have lasted so long that a narrower skin would pay for a build.
  bool skin_outlasts() const;
  // Placed balls may start in contact: the next step's half-step state is computed anew from real forces.
  void start_from_current_state();
  // Ball i's half kick and drift into the next-step buffers (fishtank::kick_drift).
  float kick_drift(std::uint32_t i, const Float4& a);
  // model_.lead_bound for a step whose balls move at most `fastest`.
  void bound_lead(float fastest);
  void move_players();
  void resize(std::uint32_t n);
  void set_ghost();
  // The arrays and the contact model of the next pass; no prefetch plan.
  StepContext context();
  void derive_velocities() const;

  PhysicsParams params_;
  ContactModel model_;
  const Kernels& kernels_;
  WorkerPool pool_;
  Spawner spawner_;
  NeighbourList list_;

  std::uint32_t n_ = 0;
  // n_ balls, then kGhostSlots ghosts far away (index n_ pads neighbour lists).
  // The half-step rows' w is 1 / mass (StepArrays::vel_half), vel_'s the mass.
  AlignedVector<Float4> pos_, vel_half_, vel_half_before_;
  AlignedVector<Float4> pos_next_, vel_half_next_;  // written by the step pass
  // The full-step velocity at time(), stale after a pass until derive_velocities().
  mutable AlignedVector<Float4> vel_;
  mutable bool vel_stale_ = false;
  AlignedVector<Float4> acc_;  // scratch: start_from_current_state(), rebuild()
  AlignedVector<Float4> pos_at_build_;
  std::vector<std::uint8_t> kind_, kind_scratch_;
  std::vector<std::uint32_t> id_, id_scratch_;
  std::uint32_t next_id_ = 0;
  bool needs_rebuild_ = true;
  bool needs_initial_forces_ = false;
  float next_max_d2_ = 0.0f;   // largest squared distance of pos_next from pos_at_build
  float fastest_next_ = 0.0f;  // largest speed in vel_half_next: bounds the next step's lead

  std::vector<std::uint32_t> player_ids_;
  AlignedVector<Float4> player_pos_, player_vel_;
  std::uint32_t next_player_id_ = 0;

  std::uint32_t capacity_;
  std::uint32_t max_balls_;
  // Tunable: a strayed ball's check is taken to cost what a rebuild costs per two balls.
  static constexpr double kRebuildCostInChecksPerBall = 0.5;
  // Past n / kStrayedBallsPerCheck (+ 16) strayed balls the lists are rebuilt: by then checks go on
  // finding nothing only to end in a missed contact a few steps later.
  static constexpr std::uint32_t kStrayedBallsPerCheck = 256;
  // A check costs a few dozen balls' steps: a thread takes at least this many.
  static constexpr std::uint32_t kStrayChecksPerThread = 4;
  static constexpr float kStrayMargin = 1.0f - 1e-5f;  // a ball right at skin / 2 counts as strayed
  // What each chunk of the last step pass reported.
  struct ChunkMoved {
    std::uint32_t begin = 0;
    Moved moved;
  };
  std::vector<ChunkMoved> chunk_moved_;
  std::vector<char> chunk_missing_;           // per chunk: a strayed ball misses a contact
  std::vector<std::uint32_t> stray_balls_;    // per chunk, from its begin: its strayed balls
  bool strayed_listed_ = false;               // whether the last pass listed them
  std::vector<std::uint32_t> chunk_longest_;  // per chunk: the longest list it built
  std::vector<std::uint32_t> order_;
  std::vector<NewBall> placed_;
  double time_ = 0.0;
  double energy_added_ = 0.0;
  std::uint64_t steps_ = 0;
  std::uint64_t rebuilds_ = 0;
  std::uint64_t lists_kept_by_checks_ = 0;
  std::uint64_t strayed_checked_ = 0;
  std::uint64_t built_at_step_ = 0, strayed_checked_at_build_ = 0;  // at the last build
  PhaseSeconds phase_seconds_;
};

}  // namespace fishtank
