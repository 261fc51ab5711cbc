#include "common/output_paths.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace fishtank {

namespace fs = std::filesystem;

namespace {

// "" where this process may write to path (access(2) with W_OK), otherwise the reason.
std::string write_access(const fs::path& path) { return ::access(path.c_str(), W_OK) == 0 ? "" : std::strerror(errno); }

}  // namespace

std::string check_writable_file(const std::string& path) {
  const fs::path file(path);
  const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
  std::error_code ec;
  if (fs::is_directory(file, ec)) return path + " is a folder; name a file in it";
  if (!fs::is_directory(folder, ec)) return "the folder " + folder.string() + " does not exist; create it first";
  const std::string denied = write_access(fs::exists(file, ec) ? file : folder);
  return denied.empty() ? "" : "cannot write " + path + ": " + denied;
}

std::string prepare_writable_folder(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return "cannot create " + dir + ": " + ec.message();
  if (!fs::is_directory(dir, ec)) return dir + " is a file, not a folder";
  const std::string denied = write_access(dir);
  return denied.empty() ? "" : "cannot write in " + dir + ": " + denied;
}

}  // namespace fishtank
