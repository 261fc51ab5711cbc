#pragma once
// Carrying a scene to LAMMPS (SPEC 3.7): a data file and an input script that
// continue the current state with the same contact model, and a trajectory
// writer in LAMMPS dump format (the suite reads it with ASE and MDAnalysis).
//
// Mapping of the model onto LAMMPS's GRANULAR package:
//   ball kinds 1..3         atom types 1..3, atom_style sphere (density set so mass = 1, 2, 3)
//   pair force k x - c v_n  pair_style granular, "hooke k c ... damping velocity",
//                           with c = 2 zeta sqrt(k m_eff) written per type pair
//   walls                   fix wall/gran per axis and per type (wall damping
//                           depends on the ball's mass, one fix per type)
//   gravity, dt             fix gravity, timestep
// The player sphere is kinematic and has no LAMMPS counterpart; it is left out.

#include <cstdint>
#include <cstdio>
#include <string>

#include "server/physics/world.h"

namespace fishtank {

// Writes DIR/data.fishtank and DIR/in.fishtank (DIR is created if missing).
// The script runs run_steps steps. Returns "" or why it failed.
std::string export_lammps(const World& world, const std::string& dir, std::uint64_t run_steps);

// Damping coefficient c = 2 zeta sqrt(k m_eff) for two kinds, or a kind and a wall (kind_b < 0).
double lammps_damping(const World& world, int kind_a, int kind_b);

// Appends frames "ITEM: TIMESTEP ... ITEM: ATOMS id type x y z vx vy vz radius".
class LammpsDumpWriter {
 public:
  LammpsDumpWriter() = default;
  ~LammpsDumpWriter();
  LammpsDumpWriter(const LammpsDumpWriter&) = delete;
  LammpsDumpWriter& operator=(const LammpsDumpWriter&) = delete;

  std::string open(const std::string& path);  // "" or why it failed
  std::string write_frame(const World& world);
  // The frames so far are complete on disk, and no more are written; "" or why the last of them were not
  // (the C library writes its buffer out only now, so a full disk may show here first).
  std::string close();
  std::uint64_t frames() const { return frames_; }

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
  std::uint64_t frames_ = 0;
};

}  // namespace fishtank
