#pragma once
// The end of every file the server writes (--dump, --export-lammps, --record).

#include <cstdio>
#include <string>

namespace fishtank {

// Flushes and closes f: "" when everything written reached `path`, else why not. A full disk
// may fail an earlier fprintf, whose error only the stream's error flag keeps.
inline std::string finish_file(std::FILE* f, const std::string& path) {
  bool ok = std::fflush(f) == 0 && !std::ferror(f);
  ok = std::fclose(f) == 0 && ok;
  return ok ? "" : "error while writing " + path;
}

}  // namespace fishtank
