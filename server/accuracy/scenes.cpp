#include "server/accuracy/scenes.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>

#include "common/tank.h"
#include "server/physics/world.h"

namespace fishtank::accuracy {
namespace {

constexpr double kGravity = 9.81;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What a scene watches, whoever integrates it: the overlap x of the contact
// and its rate u, in the coordinates of contact_1d.h.
class Probe {
 public:
  virtual ~Probe() = default;
  virtual void step() = 0;
  virtual double overlap() const = 0;
  virtual double rate() const = 0;
};

class ModelProbe final : public Probe {
 public:
  explicit ModelProbe(const Contact1D& model) : model_(model) {}
  void step() override { model_.step(); }
  double overlap() const override { return model_.state().x; }
  double rate() const override { return model_.state().u; }

 private:
  Contact1D model_;
};

struct Placement {
  int kind;
  Vec3 pos, vel;
};

// The same problem laid out in a World; overlap and rate read it back.
struct WorldScene {
  PhysicsParams params;
  std::vector<Placement> balls;
  std::function<double(const World&)> overlap, rate;
};

class WorldProbe final : public Probe {
 public:
  WorldProbe(const WorldScene& scene, const Kernels& kernels) : scene_(scene), world_(scene.params, kernels, 1, 1) {
    for (const Placement& b : scene.balls) world_.place_ball(b.kind, b.pos, b.vel);
  }
  void step() override { world_.step(); }
  double overlap() const override { return scene_.overlap(world_); }
  double rate() const override { return scene_.rate(world_); }

 private:
  WorldScene scene_;
  World world_;
};

// The 1-D problem: contact, push (acceleration into the contact) and start.
struct Problem {
  LinearContact contact;
  double push, x0, u0;
};

std::unique_ptr<Probe> make_probe(const Method& method, const SceneConfig& config, double dt, const Problem& problem,
                                  WorldScene scene) {
  if (!method.world)
    return std::make_unique<ModelProbe>(
        Contact1D(problem.contact, problem.push, method.scheme, dt, problem.x0, problem.u0));
  scene.params.stiffness = static_cast<float>(config.k);
  scene.params.dt = static_cast<float>(dt);
  return std::make_unique<WorldProbe>(scene, *config.kernels);
}

// A ball of kind 0 over a floor at y = -0.5, so its centre stays near 0 where
// float spacing is far below the errors measured; overlap = -y.
WorldScene ball_on_floor(double restitution, double y0) {
  WorldScene scene;
  scene.params.restitution = static_cast<float>(restitution);
  scene.params.gravity = static_cast<float>(kGravity);
  scene.params.tank.min = {-5.0f, -0.5f, -5.0f};
  scene.params.tank.max = {5.0f, 9.5f, 5.0f};
  scene.balls = {{0, {0.0f, static_cast<float>(y0), 0.0f}, {0.0f, 0.0f, 0.0f}}};
  scene.overlap = [](const World& w) { return -double(w.ball(0).pos.y); };
  scene.rate = [](const World& w) { return -double(w.ball(0).vel.y); };
  return scene;
}

LinearContact contact_for(const SceneConfig& config, double mass, double restitution) {
  return {mass, config.k, pair_damping(config.k, restitution, mass)};
}

int steps_for(double seconds, double dt) { return static_cast<int>(std::ceil(seconds / dt)); }

// Apex height of each flight, from the last rising state in flight: h + v^2/2g
// is exact for Verlet's free flight and carries each Euler scheme's flight error.
class ApexTracker {
 public:
  void observe(double x, double u) {
    if (x <= 0.0 && u < 0.0) {
      candidate_ = -x + u * u / (2.0 * kGravity);
      rising_ = true;
    } else if (rising_ && u >= 0.0) {
      apexes_.push_back(candidate_);
      rising_ = false;
    }
  }
  const std::vector<double>& apexes() const { return apexes_; }

 private:
  double candidate_ = 0.0;
  bool rising_ = false;
  std::vector<double> apexes_;
};

// One height fixes where in a step each bounce starts, so its error scatters from one dt to the next; the
// worst over kDropPhases heights, each starting the first contact an equal part of a step later, converges.
double drop_error(const Method& method, const SceneConfig& config, double dt) {
  const double fall = std::sqrt(2.0 * kDropHeight / kGravity);
  double worst = 0.0;
  for (int phase = 0; phase < kDropPhases; ++phase) {
    const double t = fall + dt * phase / kDropPhases, height = 0.5 * kGravity * t * t;
    const std::vector<double> measured = measured_apexes(method, config, dt, height);
    if (measured.size() < std::size_t(kDropBounces)) return kNaN;
    const std::vector<double> exact =
        exact_apexes(contact_for(config, kBallKinds[0].mass, config.restitution), kGravity, height, kDropBounces);
    for (int n = 0; n < kDropBounces; ++n) worst = std::max(worst, std::fabs(measured[n] - exact[n]) / height);
  }
  return worst;
}

double head_on_error_at(const Method& method, const SceneConfig& config, double dt, double restitution) {
  double worst = 0.0;
  for (int a = 0; a < kKindCount; ++a)
    for (int b = a; b < kKindCount; ++b) {
      SceneConfig pair = config;
      pair.restitution = restitution;
      worst = std::max(worst, head_on_pair_error(method, pair, dt, a, b));
    }
  return worst;
}

double head_on_error(const Method& method, const SceneConfig& config, double dt) {
  return head_on_error_at(method, config, dt, config.restitution);
}

double head_on_elastic_error(const Method& method, const SceneConfig& config, double dt) {
  return head_on_error_at(method, config, dt, 1.0);
}

double energy_error(const Method& method, const SceneConfig& config, double dt) {
  const double m = kBallKinds[0].mass, k = config.k;
  const double x_eq = m * kGravity / k;
  const double amplitude = 0.9 * x_eq;  // stays in contact: a smooth problem
  const Problem problem{contact_for(config, m, 1.0), kGravity, x_eq - amplitude, 0.0};
  auto probe = make_probe(method, config, dt, problem, ball_on_floor(1.0, amplitude - x_eq));
  auto energy = [&](double x, double u) {
    const double spring = x > 0.0 ? 0.5 * k * x * x : 0.0;
    return 0.5 * m * u * u - m * kGravity * x + spring;
  };
  const double e0 = energy(problem.x0, problem.u0);
  const double scale = 0.5 * k * amplitude * amplitude;
  const double periods = 5.0;
  double worst = 0.0;
  for (int s = steps_for(periods * 2.0 * M_PI * std::sqrt(m / k), dt); s > 0; --s) {
    probe->step();
    worst = std::max(worst, std::fabs(energy(probe->overlap(), probe->rate()) - e0) / scale);
    if (!std::isfinite(worst)) return kNaN;
  }
  return worst;
}

}  // namespace

const std::vector<Method>& methods() {
  static const std::vector<Method> all{{"world-verlet", true, Scheme::kVerlet},
                                       {"verlet-1d", false, Scheme::kVerlet},
                                       {"symplectic-euler", false, Scheme::kSymplecticEuler},
                                       {"explicit-euler", false, Scheme::kExplicitEuler}};
  return all;
}

const std::vector<Scene>& scenes() {
  static const std::vector<Scene> all{{"drop", drop_error},
                                      {"head-on", head_on_error},
                                      {"head-on-elastic", head_on_elastic_error},
                                      {"energy", energy_error}};
  return all;
}

std::vector<double> measured_apexes(const Method& method, const SceneConfig& config, double dt, double height) {
  const Problem problem{contact_for(config, kBallKinds[0].mass, config.restitution), kGravity, -height, 0.0};
  auto probe = make_probe(method, config, dt, problem, ball_on_floor(config.restitution, height));
  ApexTracker tracker;
  const double max_seconds = 10.0;  // three bounces take under 2 s
  for (int s = steps_for(max_seconds, dt); s > 0 && tracker.apexes().size() < std::size_t(kDropBounces); --s) {
    probe->step();
    if (!std::isfinite(probe->overlap())) break;
    tracker.observe(probe->overlap(), probe->rate());
  }
  return tracker.apexes();
}

double measured_restitution(const Method& method, const SceneConfig& config, double dt, int kind_a, int kind_b,
                            double phase) {
  const float ra = 0.5f * kBallKinds[kind_a].diameter, rb = 0.5f * kBallKinds[kind_b].diameter;
  const double ma = kBallKinds[kind_a].mass, mb = kBallKinds[kind_b].mass;
  const double gap = kHeadOnGap + phase * 2.0 * config.head_on_speed * dt;
  const Problem problem{contact_for(config, ma * mb / (ma + mb), config.restitution), 0.0, -gap,
                        2.0 * config.head_on_speed};

  WorldScene scene;
  scene.params.restitution = static_cast<float>(config.restitution);
  scene.params.gravity = 0.0f;
  // Small enough that building the World's grid costs little next to the steps.
  scene.params.tank.min = {-5.0f, -5.0f, -5.0f};
  scene.params.tank.max = {5.0f, 5.0f, 5.0f};
  const float half_gap = static_cast<float>(gap / 2), speed = static_cast<float>(config.head_on_speed);
  scene.balls = {{kind_a, {-ra - half_gap, 0.0f, 0.0f}, {speed, 0.0f, 0.0f}},
                 {kind_b, {rb + half_gap, 0.0f, 0.0f}, {-speed, 0.0f, 0.0f}}};
  scene.overlap = [ra, rb](const World& w) { return double(ra + rb) - (w.ball(1).pos.x - w.ball(0).pos.x); };
  scene.rate = [](const World& w) { return double(w.ball(0).vel.x) - w.ball(1).vel.x; };
  auto probe = make_probe(method, config, dt, problem, scene);

  bool touched = false;
  const double t_c = M_PI * std::sqrt(problem.contact.mass / config.k);
  // A few steps more than the contact needs, for dt of the order of t_c.
  for (int s = steps_for(gap / problem.u0 + 4.0 * t_c, dt) + 20; s > 0; --s) {
    probe->step();
    touched = touched || probe->overlap() > 0.0;
    if (touched && !(probe->overlap() > 0.0)) {
      // The World's full-step velocity at the parting step holds half of that step's impulse.
      for (int after = 0; after < 2; ++after) probe->step();
      return -probe->rate() / problem.u0;  // NaN stays NaN
    }
  }
  return kNaN;
}

double head_on_pair_error(const Method& method, const SceneConfig& config, double dt, int kind_a, int kind_b) {
  const double ma = kBallKinds[kind_a].mass, mb = kBallKinds[kind_b].mass, v = config.head_on_speed;
  const Rebound exact = exact_rebound(ma, v, mb, -v, config.restitution);
  double worst = 0.0;
  for (int p = 0; p < kHeadOnPhases; ++p) {
    const double w = -2.0 * v * measured_restitution(method, config, dt, kind_a, kind_b, double(p) / kHeadOnPhases);
    // Forces are equal and opposite, so the momentum fixes each velocity from the relative one.
    const double momentum = (ma - mb) * v;
    const double va = (momentum + mb * w) / (ma + mb), vb = (momentum - ma * w) / (ma + mb);
    worst = std::max(worst, std::max(std::fabs(va - exact.v1), std::fabs(vb - exact.v2)) / (2.0 * v));
  }
  return worst;
}

}  // namespace fishtank::accuracy
