#pragma once
// The browser viewer's files, served read-only from one folder (the web root).
// A request target maps to a regular file inside the root or to nothing (404):
// `..` segments, their percent-encoded forms, bad encodings and symlinks that
// lead out of the root all map to nothing. No I/O beyond stat and realpath.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace fishtank::net {

class StaticFiles {
 public:
  // root need not exist: then every file is "not found" and the 404 page says how to build the page.
  explicit StaticFiles(const std::string& root);

  // The file a GET of `target` ("/", "/app.js?v=2") serves; empty: 404.
  std::optional<std::filesystem::path> resolve(std::string_view target) const;
  // The 404 page: the page is not built (and how to build it), or that file is not part of it.
  std::string not_found_page() const;
  // True when the root holds index.html.
  bool page_built() const { return page_built_; }
  const std::string& root() const { return root_text_; }

 private:
  std::string root_text_;
  std::optional<std::filesystem::path> root_;  // canonical; empty when it does not exist
  bool page_built_ = false;
};

// The Content-Type of a file, from its extension.
std::string_view content_type(const std::filesystem::path& file);
// A request target's path with %XX decoded, without query and fragment; empty on a bad encoding or a NUL.
std::optional<std::string> decode_target_path(std::string_view target);

}  // namespace fishtank::net
