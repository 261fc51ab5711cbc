#include "common/output_paths.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

namespace fishtank {

namespace fs = std::filesystem;

namespace {

// "" where this process may write to a file that exists, otherwise the reason. It is not opened: it may be a
// named pipe.
std::string write_access(const fs::path& path) { return ::access(path.c_str(), W_OK) == 0 ? "" : std::strerror(errno); }

// "" where a new file can be made at path, otherwise the reason. The file is made and removed again:
// access(2) on its folder passes for root, and in /proc, where no file can be made. Where something
// appeared there meanwhile (another run's file, a dangling link), the write itself will tell.
std::string trial_create(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) return errno == EEXIST ? "" : std::strerror(errno);
  ::close(fd);
  ::unlink(path.c_str());
  return "";
}

}  // namespace

std::string check_writable_file(const std::string& path) {
  const fs::path file(path);
  const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
  std::error_code ec;
  if (fs::is_directory(file, ec)) return path + " is a folder; name a file in it";
  if (!fs::is_directory(folder, ec)) return "the folder " + folder.string() + " does not exist; create it first";
  const std::string denied = fs::exists(file, ec) ? write_access(file) : trial_create(file);
  return denied.empty() ? "" : "cannot write " + path + ": " + denied;
}

std::string prepare_writable_folder(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return "cannot create " + dir + ": " + ec.message();
  if (!fs::is_directory(dir, ec)) return dir + " is a file, not a folder";
  // Named for this process: two runs checking one folder at once do not meet.
  const std::string denied = trial_create(fs::path(dir) / (".fishtank-write-trial-" + std::to_string(::getpid())));
  return denied.empty() ? "" : "cannot write in " + dir + ": " + denied;
}

}  // namespace fishtank
