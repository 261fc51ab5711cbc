#include "viewer/render/screenshot.h"

#include <GL/glew.h>
#include <stb_image_write.h>

#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <vector>

namespace fishtank::viewer {

bool save_screenshot(const std::string& path, int width, int height) {
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);  // rows of 3-byte pixels are not 4-byte multiples
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
  stbi_flip_vertically_on_write(1);  // GL's first row is the bottom one, PNG's the top
  if (!stbi_write_png(path.c_str(), width, height, 3, rgb.data(), width * 3)) {
    std::fprintf(stderr, "fishtank-viewer: cannot write %s\n", path.c_str());
    return false;
  }
  return true;
}

std::string new_screenshot_path() {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char stem[32];
  std::strftime(stem, sizeof stem, "fishtank-%Y%m%d-%H%M%S", &local);
  std::error_code ec;
  std::filesystem::path path = std::filesystem::absolute(std::string(stem) + ".png", ec);
  for (int n = 2; std::filesystem::exists(path, ec); ++n)
    path = std::filesystem::absolute(std::string(stem) + "-" + std::to_string(n) + ".png", ec);
  return path.string();
}

}  // namespace fishtank::viewer
