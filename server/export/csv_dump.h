#pragma once
// Final state as CSV (x,y,z,vx,vy,vz,diameter,mass), one row per ball in id
// order, for checking a run with other tools.

#include <string>

#include "server/physics/world.h"

namespace fishtank {

// Returns "" on success, otherwise why the file could not be written.
std::string write_csv_dump(const World& world, const std::string& path);

}  // namespace fishtank
