#pragma once
// Saves what has been drawn into the back buffer as a PNG (stb_image_write),
// for --screenshot and the viewer's pixel test.

#include <string>

namespace fishtank::viewer {

// False (with a message on stderr) when the file cannot be written.
bool save_screenshot(const std::string& path, int width, int height);

// A path in the working folder for a screenshot taken now, named by the local
// time (fishtank-YYYYMMDD-HHMMSS.png, then -2, -3 ... within one second), absolute.
std::string new_screenshot_path();

}  // namespace fishtank::viewer
