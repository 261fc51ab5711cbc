#include "server/export/csv_dump.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "server/export/finish_file.h"
#include "server/physics/world_measures.h"

namespace fishtank {

std::string write_csv_dump(const World& world, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return "cannot write " + path + ": " + std::strerror(errno);
  std::fprintf(f, "x,y,z,vx,vy,vz,diameter,mass\n");
  for (std::uint32_t i : indices_by_id(world)) {
    const Float4& p = world.positions()[i];
    const Float4& v = world.velocities()[i];
    std::fprintf(f, "%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g\n", p.x, p.y, p.z, v.x, v.y, v.z, 2.0f * p.w, v.w);
  }
  return finish_file(f, path);
}

}  // namespace fishtank
