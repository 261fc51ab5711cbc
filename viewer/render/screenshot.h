#pragma once
// Saves what has been drawn into the back buffer as a PNG (stb_image_write),
// for --screenshot and the viewer's pixel test.

#include <string>

namespace fishtank::viewer {

// False (with a message on stderr) when the file cannot be written.
bool save_screenshot(const std::string& path, int width, int height);

}  // namespace fishtank::viewer
