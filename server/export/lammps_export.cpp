#include "server/export/lammps_export.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <vector>

#include "server/export/finish_file.h"
#include "server/physics/world_measures.h"

namespace fishtank {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Balls squeezed into a wall reach past its face; LAMMPS loses atoms that
// leave a fixed box, so the box extends one largest diameter past the tank.
constexpr float kBoxMargin = kMaxBallDiameter;

void write_box(std::FILE* f, const TankBounds& t, const char* format) {
  std::fprintf(f, format, t.min.x - kBoxMargin, t.max.x + kBoxMargin, t.min.y - kBoxMargin, t.max.y + kBoxMargin,
               t.min.z - kBoxMargin, t.max.z + kBoxMargin);
}

std::string write_data(const World& world, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return "cannot write " + path + ": " + std::strerror(errno);
  std::fprintf(f, "LAMMPS data file: Fishtank scene, %u balls at t = %.6f s\n\n", world.ball_count(), world.time());
  std::fprintf(f, "%u atoms\n%d atom types\n\n", world.ball_count(), kKindCount);
  write_box(f, world.params().tank, "%.6f %.6f xlo xhi\n%.6f %.6f ylo yhi\n%.6f %.6f zlo zhi\n");
  std::fprintf(f, "\nAtoms # sphere\n\n");
  const std::vector<std::uint32_t> by_id = indices_by_id(world);
  for (std::uint32_t id = 0; id < by_id.size(); ++id) {
    const std::uint32_t i = by_id[id];
    const Float4& p = world.positions()[i];
    const double d = 2.0 * p.w, mass = world.velocities()[i].w;
    const double density = mass / (kPi / 6.0 * d * d * d);
    std::fprintf(f, "%u %d %.9g %.9g %.9g %.9g %.9g\n", id + 1, world.kinds()[i] + 1, d, density, p.x, p.y, p.z);
  }
  std::fprintf(f, "\nVelocities\n\n");
  for (std::uint32_t id = 0; id < by_id.size(); ++id) {
    const Float4& v = world.velocities()[by_id[id]];
    std::fprintf(f, "%u %.9g %.9g %.9g 0 0 0\n", id + 1, v.x, v.y, v.z);
  }
  return finish_file(f, path);
}

std::string write_input(const World& world, const std::string& path, std::uint64_t run_steps) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return "cannot write " + path + ": " + std::strerror(errno);
  const PhysicsParams& p = world.params();
  const TankBounds& t = p.tank;
  std::fprintf(f,
               "# Fishtank scene for LAMMPS (GRANULAR package), exported by fishtank-server.\n"
               "# k = %g N/m, e = %g, dt = %.9g s, %u balls.\n"
               "# Run on one core:   lmp -in in.fishtank\n"
               "# Run on every core: mpirun --use-hwthread-cpus -np $(nproc) lmp -in in.fishtank\n"
               "#   (--use-hwthread-cpus: one rank per CPU; as root, Open MPI also asks for --allow-run-as-root)\n"
               "# Contact: F = k x - c v_n, c = 2 zeta sqrt(k m_eff), zeta = -ln e / sqrt(pi^2 + ln^2 e),\n"
               "# no friction, no clamp at zero force (as in fishtank-server).\n\n",
               p.stiffness, p.restitution, world.dt(), world.ball_count());
  std::fprintf(f,
               "units si\ndimension 3\natom_style sphere\nboundary f f f\ncomm_modify vel yes\n"
               "read_data data.fishtank\n\npair_style granular\n");
  for (int a = 0; a < kKindCount; ++a)
    for (int b = a; b < kKindCount; ++b)
      std::fprintf(f, "pair_coeff %d %d hooke %.9g %.9g tangential linear_nohistory 0.0 0.0 damping velocity\n", a + 1,
                   b + 1, p.stiffness, lammps_damping(world, a, b));
  std::fprintf(f, "\nneighbor %g bin\nneigh_modify delay 0 every 1 check yes\n\n", starting_skin(p));
  std::fprintf(f, "fix integrate all nve/sphere\nfix gravity all gravity %.9g vector 0.0 -1.0 0.0\n", p.gravity);
  const char* axes[3] = {"x", "y", "z"};
  const float lo[3] = {t.min.x, t.min.y, t.min.z}, hi[3] = {t.max.x, t.max.y, t.max.z};
  for (int k = 0; k < kKindCount; ++k) {
    std::fprintf(f, "\ngroup kind%d type %d\n", k + 1, k + 1);
    for (int a = 0; a < 3; ++a)
      std::fprintf(f,
                   "fix wall_%s_%d kind%d wall/gran granular hooke %.9g %.9g tangential linear_nohistory 0.0 0.0 "
                   "damping velocity %splane %.9g %.9g\n",
                   axes[a], k + 1, k + 1, p.stiffness, lammps_damping(world, k, -1), axes[a], lo[a], hi[a]);
  }
  std::fprintf(f,
               "\ntimestep %.9g\ncompute ke all ke\nthermo_style custom step time atoms c_ke\nthermo 1000\n"
               "run %llu\n",
               world.dt(), static_cast<unsigned long long>(run_steps));
  return finish_file(f, path);
}

}  // namespace

double lammps_damping(const World& world, int kind_a, int kind_b) {
  const double ma = kBallKinds[kind_a].mass;
  const double m_eff = kind_b < 0 ? ma : ma * kBallKinds[kind_b].mass / (ma + kBallKinds[kind_b].mass);
  return 2.0 * damping_ratio(world.params().restitution) * std::sqrt(double(world.params().stiffness) * m_eff);
}

std::string export_lammps(const World& world, const std::string& dir, std::uint64_t run_steps) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return "cannot create " + dir + ": " + ec.message();
  if (std::string err = write_data(world, dir + "/data.fishtank"); !err.empty()) return err;
  return write_input(world, dir + "/in.fishtank", run_steps);
}

LammpsDumpWriter::~LammpsDumpWriter() { close(); }  // an owner that cares asked close() first

std::string LammpsDumpWriter::close() {
  if (!file_) return "";
  std::FILE* f = file_;
  file_ = nullptr;
  return finish_file(f, path_);
}

std::string LammpsDumpWriter::open(const std::string& path) {
  file_ = std::fopen(path.c_str(), "w");
  path_ = path;
  return file_ ? "" : "cannot write " + path + ": " + std::strerror(errno);
}

std::string LammpsDumpWriter::write_frame(const World& world) {
  std::fprintf(file_, "ITEM: TIMESTEP\n%llu\nITEM: NUMBER OF ATOMS\n%u\nITEM: BOX BOUNDS ff ff ff\n",
               static_cast<unsigned long long>(world.steps()), world.ball_count());
  const TankBounds& t = world.params().tank;
  std::fprintf(file_, "%.6f %.6f\n%.6f %.6f\n%.6f %.6f\n", t.min.x, t.max.x, t.min.y, t.max.y, t.min.z, t.max.z);
  std::fprintf(file_, "ITEM: ATOMS id type x y z vx vy vz radius\n");
  for (std::uint32_t i : indices_by_id(world)) {
    const Float4& p = world.positions()[i];
    const Float4& v = world.velocities()[i];
    std::fprintf(file_, "%u %d %.7g %.7g %.7g %.7g %.7g %.7g %.7g\n", world.ids()[i] + 1, world.kinds()[i] + 1, p.x,
                 p.y, p.z, v.x, v.y, v.z, p.w);
  }
  ++frames_;
  return std::ferror(file_) ? "error while writing " + path_ : "";
}

}  // namespace fishtank
