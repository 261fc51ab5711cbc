#include "server/net/static_files.h"

#include <algorithm>

namespace fishtank::net {

namespace fs = std::filesystem;

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// True when `inside` is `root` or below it (both canonical).
bool within(const fs::path& root, const fs::path& inside) {
  const auto [r, i] = std::mismatch(root.begin(), root.end(), inside.begin(), inside.end());
  return r == root.end();
}

}  // namespace

std::optional<std::string> decode_target_path(std::string_view target) {
  target = target.substr(0, target.find_first_of("?#"));
  std::string path;
  for (std::size_t i = 0; i < target.size(); ++i) {
    char c = target[i];
    if (c == '%') {
      const int hi = i + 2 < target.size() ? hex_value(target[i + 1]) : -1;
      const int lo = i + 2 < target.size() ? hex_value(target[i + 2]) : -1;
      if (hi < 0 || lo < 0) return std::nullopt;
      c = static_cast<char>(16 * hi + lo);
      i += 2;
    }
    if (c == '\0') return std::nullopt;
    path += c;
  }
  return path;
}

StaticFiles::StaticFiles(const std::string& root) : root_text_(root) {
  std::error_code ec;
  const fs::path canonical = fs::canonical(root, ec);
  if (ec || !fs::is_directory(canonical, ec)) return;
  root_ = canonical;
  page_built_ = fs::is_regular_file(canonical / "index.html", ec);
}

std::optional<fs::path> StaticFiles::resolve(std::string_view target) const {
  if (!root_ || target.empty() || target.front() != '/') return std::nullopt;
  const std::optional<std::string> decoded = decode_target_path(target);
  if (!decoded) return std::nullopt;
  fs::path relative;
  for (const fs::path& part : fs::path(*decoded).relative_path()) {
    const std::string name = part.string();
    // No climbing out, even where a symlink would bring the path back in.
    if (name == ".." || name.find('\\') != std::string::npos) return std::nullopt;
    if (!name.empty() && name != ".") relative /= part;
  }
  std::error_code ec;
  fs::path file = fs::canonical(*root_ / relative, ec);
  if (!ec && fs::is_directory(file, ec)) file = fs::canonical(file / "index.html", ec);
  if (ec || !within(*root_, file) || !fs::is_regular_file(file, ec)) return std::nullopt;
  return file;
}

std::string StaticFiles::not_found_page() const {
  const std::string head =
      "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>Fishtank: not found</title>"
      "</head>\n<body>\n";
  if (page_built_)
    return head +
           "<h1>404: not found</h1>\n<p>No such file in the viewer's page: the viewer is at <a "
           "href=\"/\">/</a>.</p>\n</body></html>\n";
  return head +
         "<h1>404: the browser viewer is not built</h1>\n"
         // The folder is named in the server's log, not to every browser that asks.
         "<p>The folder this fishtank-server serves the page from (its log names it) holds no "
         "<code>index.html</code>.</p>\n"
         "<p>Build the page with <code>cmake --build build</code> on a machine with Node and npm (the README "
         "says how), or start the server with <code>--web-root DIR</code> naming a built page. "
         "WebSocket clients can connect to <code>/ws</code> all the same.</p>\n</body></html>\n";
}

std::string_view content_type(const fs::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json" || ext == ".map") return "application/json";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".ico") return "image/x-icon";
  if (ext == ".wasm") return "application/wasm";
  if (ext == ".txt") return "text/plain; charset=utf-8";
  return "application/octet-stream";
}

}  // namespace fishtank::net
