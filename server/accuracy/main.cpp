// fishtank-accuracy: the measurements of SPEC 7.1 and 7.2 (docs/accuracy.md).
//
//   fishtank-accuracy [--out DIR] [--quick] [--scalar | --avx2] [--collisions-only]
//
// Writes to DIR (default .):
//   rows.csv              a ball hitting a row of 1, 2 or 4 (chain, cradle): error per steps per contact
//   collisions.csv        the worst collision of every kind per e and steps per contact (the tolerance rule)
//   restitutions.csv      every collision's measured e at the default steps per contact
//   accuracy.csv          scene, method, n, dt, error, CPU seconds per run
//   accuracy-orders.csv   observed order of each scene and method, vs dt and vs CPU time
//   stability.csv         the (k, dt) map with its measurements and class
//   stability-product.csv the server's automatic dt at the default k, classified
// and prints a summary. --quick runs a coarse sweep (seconds); --scalar and
// --avx2 use those kernels instead of the SSE ones fishtank-server ships.

#include <boost/program_options.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/flag_values.h"
#include "common/output_paths.h"
#include "server/accuracy/collisions.h"
#include "server/accuracy/reference.h"
#include "server/accuracy/rows.h"
#include "server/accuracy/stability.h"
#include "server/accuracy/sweep.h"
#include "server/physics/kernels.h"
#include "server/physics/params.h"

using namespace fishtank;
using namespace fishtank::accuracy;

namespace {

constexpr int kFitMinSteps = 10, kFitMaxSteps = 80;

struct Options {
  std::string out = ".";
  bool quick = false;
  bool collisions_only = false;
  const Kernels* kernels = &kSseKernels;
};

namespace po = boost::program_options;

// The options, or why not: exit code 0 (--help, printed) or 2 (a bad flag, named on stderr).
std::optional<Options> parse(int argc, char** argv, int& exit_code) {
  Options o;
  bool scalar = false, avx2 = false;
  po::options_description flags(
      "usage: fishtank-accuracy [--out DIR] [--quick] [--scalar | --avx2] [--collisions-only]\n"
      "The measurements behind docs/accuracy.md: single collisions against the contact model's exact e,\n"
      "rows of balls, error against dt for each scheme, and the stability map, as CSV files in DIR.\n\nOptions");
  flags.add_options()                                                                                              //
      ("help,h", "print this help and exit")                                                                       //
      ("out", po::value(&o.out), "where the CSV files go, made if missing (default .)")                            //
      ("quick", po::bool_switch(&o.quick), "a coarse sweep, a few seconds")                                        //
      ("scalar", po::bool_switch(&scalar), "the plain C++ kernels instead of the SSE ones fishtank-server ships")  //
      ("avx2", po::bool_switch(&avx2), "the AVX2 kernels instead")                                                 //
      ("collisions-only", po::bool_switch(&o.collisions_only),
       "only collisions.csv and restitutions.csv (the tolerance rule)");
  exit_code = 2;
  auto refuse = [](const std::string& why) {
    std::fprintf(stderr, "fishtank-accuracy: %s\nTry --help for the list of options.\n", why.c_str());
    return std::nullopt;
  };
  po::variables_map vm;
  try {
    po::store(parse_flags(argc, argv, flags), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    return refuse(flag_error_text(e, flags));
  }
  if (vm.count("help")) {
    std::cout << flags << "\n";
    exit_code = 0;
    return std::nullopt;
  }
  if (scalar && avx2) return refuse("--scalar and --avx2 each choose the kernels; give one of them");
  if (avx2 && !cpu_has_avx2()) return refuse("this processor has no AVX2; leave out --avx2");
  o.kernels = scalar ? &kScalarKernels : avx2 ? &kAvx2Kernels : &kSseKernels;
  // Checked before minutes of sweeps, so that they cannot end in "cannot write".
  if (const std::string why = prepare_writable_folder(o.out); !why.empty())
    return refuse("--out " + o.out + ": " + why);
  return o;
}

std::ofstream open_csv(const Options& o, const char* name, const char* header) {
  std::ofstream f(o.out + "/" + name);
  if (!f) throw std::runtime_error(std::string("cannot write ") + o.out + "/" + name);
  f.precision(6);
  f << header << '\n';
  return f;
}

// The half-decade grid of the map: 10^(lo/2) ... 10^(hi/2).
std::vector<double> half_decades(int lo, int hi, int stride) {
  std::vector<double> v;
  for (int i = lo; i <= hi; i += stride) v.push_back(std::pow(10.0, i / 2.0));
  return v;
}

void report_drop(const SceneConfig& config) {
  const double t_c = contact_duration(static_cast<float>(config.k));
  const LinearContact contact{1.0, config.k, pair_damping(config.k, config.restitution, 1.0)};
  const auto exact = exact_apexes(contact, 9.81, kDropHeight, kDropBounces);
  const auto ideal = instantaneous_apexes(config.restitution, kDropHeight, kDropBounces);
  const auto world = measured_apexes(methods().front(), config, t_c / 20);
  std::printf("\ndrop from %.1f: apex heights (exact model | e^2n h0 | World at t_c/20)\n", kDropHeight);
  for (int n = 0; n < kDropBounces; ++n)
    std::printf("  bounce %d: %.6f | %.6f (%+.2f%%) | %.6f (%+.3f%%)\n", n + 1, exact[n], ideal[n],
                100 * (ideal[n] / exact[n] - 1), world[n], 100 * (world[n] / exact[n] - 1));
}

// The product's worst collision at each number of steps per contact (the sweep of
// collisions.h for every e): the data of the tolerance rule (params.h).
void run_collisions(const Options& o) {
  const std::vector<int> n_values =
      o.quick ? std::vector<int>{10, 20} : std::vector<int>{10, 11, 12, 13, 14, 16, 20, 28, 40};
  std::ofstream csv = open_csv(o, "collisions.csv",
                               "variant,steps_per_contact,restitution,collisions,within_0.005,worst,worst_times_n2");
  // Every collision at the default steps per contact, for the distribution beside LAMMPS's
  // (scripts/figures-error-cost).
  std::ofstream each_csv =
      open_csv(o, "restitutions.csv", "variant,steps_per_contact,restitution,body,kind_a,kind_b,speed,phase,measured");
  const int default_n = steps_per_contact(PhysicsParams{});
  std::printf("%-8s %4s %6s %10s %10s %12s\n", "variant", "n", "e", "within", "worst", "worst*n^2");
  for (int n : n_values)
    for (float e : kSweepRestitutions) {
      PhysicsParams params;
      params.gravity = 0.0f;
      params.tank.min = {-50.0f, 0.0f, -50.0f};
      params.tank.max = {50.0f, 100.0f, 50.0f};
      params.restitution = e;
      params.steps_per_contact = n;
      const std::vector<CollisionCase> cases = every_collision(kSweepSpeeds, o.quick ? 5 : kSweepPhases);
      std::vector<float> measured;
      const CollisionErrors r = sweep_collisions(*o.kernels, params, cases, n == default_n ? &measured : nullptr);
      for (std::size_t i = 0; i < measured.size(); ++i)
        each_csv << o.kernels->variant << ',' << n << ',' << e << ',' << body_name(cases[i].other) << ','
                 << kBallKinds[cases[i].kind_a].diameter << ','
                 << (cases[i].other == Body::kBall ? kBallKinds[cases[i].kind_b].diameter : 0.0f) << ','
                 << cases[i].speed << ',' << cases[i].phase << ',' << measured[i] << '\n';
      const double scaled = double(r.worst) * n * n;
      csv << o.kernels->variant << ',' << n << ',' << e << ',' << r.collisions << ',' << r.within_5e3 << ',' << r.worst
          << ',' << scaled << '\n';
      std::printf("%-8s %4d %6.2f %4d/%-5d %10.5f %12.3f  %s\n", o.kernels->variant, n, double(e), r.within_5e3,
                  r.collisions, double(r.worst), scaled, r.worst_case.c_str());
    }
}

// A ball hitting a row (a three-ball chain, a five-ball cradle), against the RK4 reference.
void run_rows(const Options& o) {
  std::ofstream csv = open_csv(o, "rows.csv", "balls,steps_per_contact,error");
  std::printf("\nmulti-contact rows: largest final velocity error / approach speed\n");
  for (int balls : {2, 3, 5})
    for (int n : {10, 13, 20, 28, 40, 56, 80}) {
      const double error =
          row_error(Row{balls, PhysicsParams{}.stiffness, PhysicsParams{}.restitution, 1.0}, *o.kernels, n);
      csv << balls << ',' << n << ',' << error << '\n';
      std::printf("  %d balls, n = %2d: %.3e\n", balls, n, error);
    }
}

void run_accuracy(const Options& o, const SceneConfig& config) {
  const std::vector<int> n_values =
      o.quick ? std::vector<int>{10, 20, 40, 80} : std::vector<int>{5, 10, 20, 40, 80, 160, 320, 640};
  const auto points = run_sweep(config, n_values, o.quick ? 0.0 : 0.02);
  std::ofstream csv = open_csv(o, "accuracy.csv", "scene,method,steps_per_contact,dt,error,cpu_seconds");
  for (const SweepPoint& p : points)
    csv << p.scene << ',' << p.method << ',' << p.steps_per_contact << ',' << p.dt << ',' << p.error << ','
        << p.cpu_seconds << '\n';

  // Fitted over n = 10 ... 80: below 10 the errors are not yet asymptotic, above
  // 80 World's float32 state sets a floor near 1e-5 on the smooth scenes.
  const auto orders = fit_orders(points, kFitMinSteps, kFitMaxSteps);
  std::ofstream ocsv = open_csv(o, "accuracy-orders.csv", "scene,method,order_dt,order_cpu,error_at_n20");
  std::printf("%-16s %-17s %8s %8s %14s\n", "scene", "method", "p(dt)", "q(cpu)", "error@t_c/20");
  for (const Order& ord : orders) {
    double at_n20 = NAN;
    for (const SweepPoint& p : points)
      if (p.scene == ord.scene && p.method == ord.method && p.steps_per_contact == 20) at_n20 = p.error;
    ocsv << ord.scene << ',' << ord.method << ',' << ord.vs_dt << ',' << ord.vs_cpu << ',' << at_n20 << '\n';
    std::printf("%-16s %-17s %8.2f %8.2f %14.3e\n", ord.scene.c_str(), ord.method.c_str(), ord.vs_dt, ord.vs_cpu,
                at_n20);
  }
  report_drop(config);
}

void run_stability(const Options& o) {
  const auto ks = o.quick ? half_decades(4, 14, 2) : half_decades(4, 14, 1);       // 1e2 ... 1e7 N/m
  const auto dts = o.quick ? half_decades(-10, -2, 2) : half_decades(-12, -2, 1);  // 1e-6 ... 1e-1 s
  std::ofstream csv = open_csv(o, "stability.csv", "k,dt,dt_over_tc,restitution,overlap,energy_ratio,class,class_name");
  auto write = [](std::ofstream& f, const StabilityCell& c) {
    f << c.k << ',' << c.dt << ',' << c.dt / contact_duration(static_cast<float>(c.k)) << ',' << c.restitution << ','
      << c.overlap << ',' << c.energy_ratio << ',' << int(c.stability) << ',' << stability_name(c.stability) << '\n';
  };
  // The boundaries are known to within the grid's step only: a coarse grid moves them by its step.
  std::printf("\nstability: largest dt / t_c of each class, per k, among dt = %.0e ... %.0e s %s apart\n", dts.front(),
              dts.back(), o.quick ? "a decade" : "half a decade");
  for (double k : ks) {
    const double t_c = contact_duration(static_cast<float>(k));
    double last_accurate = 0, last_stable = 0;
    for (double dt : dts) {
      const StabilityCell c = classify(k, dt, *o.kernels);
      write(csv, c);
      if (c.stability == Stability::kAccurate) last_accurate = dt;
      if (c.stability != Stability::kUnstable) last_stable = dt;
    }
    csv << '\n';  // gnuplot's pm3d reads one scan per k
    char accurate[64] = "accurate at no dt tried";
    if (last_accurate > 0)
      std::snprintf(accurate, sizeof accurate, "accurate up to dt/t_c = %.3g", last_accurate / t_c);
    std::printf("  k = %8.3g: %s, stable up to %.3g (theory: 2/pi = 0.637)\n", k, accurate, last_stable / t_c);
  }

  const PhysicsParams product;
  const StabilityCell c = classify(product.stiffness, derived_dt(product), *o.kernels);
  std::ofstream pcsv =
      open_csv(o, "stability-product.csv", "k,dt,dt_over_tc,restitution,overlap,energy_ratio,class,class_name");
  write(pcsv, c);
  std::printf("  product: k = %g, dt = %.4g s -> %s (e = %.4f, overlap %.3f, energy ratio %.3f)\n", c.k, c.dt,
              stability_name(c.stability), c.restitution, c.overlap, c.energy_ratio);
}

}  // namespace

int main(int argc, char** argv) {
  int exit_code = 0;
  const std::optional<Options> parsed = parse(argc, argv, exit_code);
  if (!parsed) return exit_code;
  const Options& o = *parsed;
  try {
    run_collisions(o);
    if (o.collisions_only) return 0;
    run_rows(o);
    SceneConfig config;
    config.kernels = o.kernels;
    run_accuracy(o, config);
    run_stability(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fishtank-accuracy: %s\n", e.what());
    return 1;
  }
  return 0;
}
