// The orbit camera's first view holds the whole tank, whatever the window's
// shape: a phone held upright as well as a wide monitor.

#include "viewer/render/camera.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <utility>

namespace fishtank::viewer {
namespace {

// The largest |x| and |y| of the tank's eight corners in normalised device
// coordinates: the tank is all on screen when both are below 1.
std::pair<float, float> corners_reach(const TankBounds& tank, float aspect) {
  OrbitCamera camera;
  camera.frame(tank);
  Mat4 vp = camera.view_projection(aspect);
  float reach_x = 0.0f, reach_y = 0.0f;
  for (int i = 0; i < 8; ++i) {
    Vec3 c{i & 1 ? tank.max.x : tank.min.x, i & 2 ? tank.max.y : tank.min.y, i & 4 ? tank.max.z : tank.min.z};
    float clip[4];
    for (int row = 0; row < 4; ++row)
      clip[row] = vp.at(row, 0) * c.x + vp.at(row, 1) * c.y + vp.at(row, 2) * c.z + vp.at(row, 3);
    REQUIRE(clip[3] > 0.0f);  // in front of the camera
    reach_x = std::max(reach_x, std::abs(clip[0] / clip[3]));
    reach_y = std::max(reach_y, std::abs(clip[1] / clip[3]));
  }
  return {reach_x, reach_y};
}

TEST_CASE("the first view holds the whole tank on a tall, square or wide window, the 40-unit one not small",
          "[camera]") {
  const TankBounds tank;  // the 40-unit tank
  const TankBounds wide{{-143.0f, 0.0f, -143.0f},
                        {143.0f, 40.0f, 143.0f}};  // about the wide scene's at 100 000 balls
  for (const TankBounds* t : {&tank, &wide})
    for (float aspect : {0.46f, 0.75f, 1.0f, 1.25f, 1.78f, 2.4f}) {
      CAPTURE(t->size().x, aspect);
      auto [x, y] = corners_reach(*t, aspect);
      CHECK(x < 1.0f);
      CHECK(y < 1.0f);
      // The 40-unit tank is not lost in the middle either: it reaches at least halfway to an edge.
      if (t == &tank) CHECK(std::max(x, y) > 0.5f);
    }
}

}  // namespace
}  // namespace fishtank::viewer
