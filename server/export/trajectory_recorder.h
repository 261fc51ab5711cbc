#pragma once
// When the trajectory (--record) gets a frame: at every step that is a multiple
// of N (as LAMMPS's dump every N), from a simulated second on, never an empty
// one (ASE's dump reader cannot parse a frame without atoms), and the final
// state last, so the file ends where --dump does. The paced loop ends a batch
// at each such step (LoopOptions::boundary_every).
//
// A constant-count recording is for readers that take the first frame's count
// for the whole file (MDAnalysis): it starts once no ball is queued to pour in
// and ends, with a message, at the first change of the count; the simulation
// goes on unrecorded.

#include <cstdint>
#include <optional>
#include <string>

#include "server/export/lammps_export.h"
#include "server/physics/world.h"

namespace fishtank {

struct RecordOptions {
  std::string path;             // empty: nothing is recorded
  std::uint32_t every = 100;    // a frame at every multiple of this step
  double from = 0.0;            // simulated seconds before the first frame
  bool constant_count = false;  // one ball count per file
};

class TrajectoryRecorder {
 public:
  explicit TrajectoryRecorder(RecordOptions options) : options_(std::move(options)) {}

  std::string open();  // "" or why the file cannot be written
  // Between steps: a frame where one is due. Returns "" or a line for the log
  // (a write error, or why the recording ended).
  std::string at_step_boundary(const World& world);
  // The final state as the last frame, unless it was just written. Returns as above.
  std::string finish(const World& world);

  bool failed() const { return failed_; }  // a write failed, or the run ended before a frame was due
  std::uint64_t frames() const { return writer_.frames(); }

 private:
  std::string write(const World& world);
  // Closes the file: note, or the write error its close found (the recording then failed).
  std::string close_with(const std::string& note);

  RecordOptions options_;
  LammpsDumpWriter writer_;
  std::optional<std::uint64_t> last_step_;  // of the last frame written
  std::uint32_t count_ = 0;                 // balls in the first frame
  bool ended_ = false;
  bool failed_ = false;
};

}  // namespace fishtank
