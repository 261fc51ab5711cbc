// Checks the viewer's screenshot (screenshot_test.sh): the right size, not
// blank, and the scene's colours in plausible proportions: red, green and
// blue balls (diameters 1, 2, 3, equal numbers, so blue covers the most
// pixels and red the fewest) and the white player sphere. With --own-hidden,
// the viewer's own sphere lies under the pile: no white shows, and its amber
// shows through the balls instead (hidden_player_test.sh).
//
// Usage: viewer_screenshot_check [--own-hidden] FILE.png; exit status 0 when it passes.

#include <stb_image.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

struct Counts {
  long background = 0, red = 0, green = 0, blue = 0, white = 0, amber = 0, total = 0;
};

bool near(const unsigned char* p, const unsigned char* q) {
  return std::abs(p[0] - q[0]) <= 6 && std::abs(p[1] - q[1]) <= 6 && std::abs(p[2] - q[2]) <= 6;
}

// Shaded spheres span dark to bright versions of their colour; a pixel counts
// for a colour when that channel is bright enough and clearly dominates.
Counts classify(const unsigned char* rgb, int w, int h) {
  Counts c;
  const unsigned char* bg = rgb;  // the corner: clear colour (the HUD is off in the test)
  for (long i = 0; i < static_cast<long>(w) * h; ++i) {
    const unsigned char* p = rgb + 3 * i;
    const int r = p[0], g = p[1], b = p[2];
    ++c.total;
    if (near(p, bg))
      ++c.background;
    else if (std::min({r, g, b}) >= 170 && std::max({r, g, b}) - std::min({r, g, b}) <= 30)
      ++c.white;
    else if (r >= 150 && r > g && g >= 0.4 * r && b <= 0.65 * g)  // the own sphere's ring
      ++c.amber;
    else if (r >= 80 && r > 2 * g && r > 2 * b)
      ++c.red;
    else if (g >= 80 && g > 2 * r && g > 2 * b)
      ++c.green;
    else if (b >= 80 && b > 2 * r && b > 1.5 * g)
      ++c.blue;
  }
  return c;
}

bool expect(bool ok, const char* what) {
  std::printf("%s %s\n", ok ? "ok:    " : "FAILED:", what);
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  const bool own_hidden = argc == 3 && std::strcmp(argv[1], "--own-hidden") == 0;
  if (argc != 2 && !own_hidden) {
    std::fprintf(stderr, "usage: %s [--own-hidden] FILE.png\n", argv[0]);
    return 2;
  }
  const char* file = argv[argc - 1];
  int w = 0, h = 0, channels = 0;
  unsigned char* rgb = stbi_load(file, &w, &h, &channels, 3);
  if (!rgb) {
    std::fprintf(stderr, "cannot read %s: %s\n", file, stbi_failure_reason());
    return 1;
  }
  const Counts c = classify(rgb, w, h);
  stbi_image_free(rgb);
  const double n = static_cast<double>(c.total);
  std::printf("%dx%d: background %.2f %%, red %ld, green %ld, blue %ld, white %ld, amber %ld pixels\n", w, h,
              100.0 * c.background / n, c.red, c.green, c.blue, c.white, c.amber);

  bool ok = expect(w == 1280 && h == 1024, "the window is 1280x1024");
  ok &= expect(c.background < 0.995 * n, "not blank: more than 0.5 % of the pixels show something");
  ok &= expect(c.red >= 100, "red balls (diameter 1) are visible");
  ok &= expect(c.green >= 100, "green balls (diameter 2) are visible");
  ok &= expect(c.blue >= 100, "blue balls (diameter 3) are visible");
  if (own_hidden) {
    ok &= expect(c.white < 20, "no white sphere in view: the pile hides the player");
    ok &= expect(c.amber >= 20, "the hidden own sphere shows through the balls in amber");
  } else {
    ok &= expect(c.white >= 20, "the white player sphere is visible");
    ok &= expect(c.white < 0.01 * n, "white is only the small player sphere (under 1 % of the picture)");
  }
  ok &= expect(c.blue > c.red && c.green > c.red,
               "blue and green balls cover more pixels than the small red ones");
  return ok ? 0 : 1;
}
