#include "server/export/csv_dump.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

namespace fishtank {

std::string write_csv_dump(const World& world, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return "cannot write " + path + ": " + std::strerror(errno);
  std::vector<std::uint32_t> by_id(world.ball_count());
  for (std::uint32_t i = 0; i < world.ball_count(); ++i) by_id[world.ids()[i]] = i;
  std::fprintf(f, "x,y,z,vx,vy,vz,diameter,mass\n");
  for (std::uint32_t i : by_id) {
    const Float4& p = world.positions()[i];
    const Float4& v = world.velocities()[i];
    std::fprintf(f, "%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g\n", p.x, p.y, p.z, v.x, v.y, v.z, 2.0f * p.w, v.w);
  }
  bool ok = std::fflush(f) == 0;
  ok = std::fclose(f) == 0 && ok;
  return ok ? "" : "error while writing " + path;
}

}  // namespace fishtank
