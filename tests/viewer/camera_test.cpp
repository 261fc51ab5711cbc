// The orbit camera's first view holds the whole tank, whatever the window's
// shape: a phone held upright as well as a wide monitor.

#include "viewer/render/camera.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <utility>

namespace fishtank::viewer {
namespace {

// Where `p` lands on a viewport `height_px` tall, in pixels from its centre.
std::pair<float, float> on_screen(const Mat4& vp, Vec3 p, float height_px, float aspect) {
  float clip[4];
  for (int row = 0; row < 4; ++row)
    clip[row] = vp.at(row, 0) * p.x + vp.at(row, 1) * p.y + vp.at(row, 2) * p.z + vp.at(row, 3);
  return {0.5f * height_px * aspect * clip[0] / clip[3], 0.5f * height_px * clip[1] / clip[3]};
}

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

TEST_CASE(
    "a sphere's radius on screen is the pixels from its centre to its outline's top, near or far, tall or "
    "wide",
    "[camera]") {
  for (float aspect : {0.46f, 1.25f})
    for (float zoom : {0.0f, 10.0f, -8.0f}) {  // as framed, nearer, farther
      OrbitCamera camera;
      camera.frame(TankBounds{});
      camera.zoom(zoom);
      Mat4 vp = camera.view_projection(aspect);
      // A sphere on the line of sight through the target, so that its outline's top is the point straight
      // above its centre as the camera sees it, along the camera's up axis.
      Vec3 eye = camera.eye();
      Vec3 sight = normalize(Vec3{0.0f, 18.0f, 0.0f} - eye);
      Vec3 up = normalize(cross(cross(sight, {0.0f, 1.0f, 0.0f}), sight));
      float distance = 0.6f * length(Vec3{0.0f, 18.0f, 0.0f} - eye);
      Vec3 centre = eye + sight * distance;
      float radius = 0.5f;
      // The outline's top is where the tangent from the eye touches the sphere.
      float top_angle = std::asin(radius / distance);
      Vec3 top = eye + (sight * std::cos(top_angle) + up * std::sin(top_angle)) * distance;
      float height_px = 1000.0f;
      auto [cx, cy] = on_screen(vp, centre, height_px, aspect);
      auto [tx, ty] = on_screen(vp, top, height_px, aspect);
      CAPTURE(aspect, zoom);
      CHECK(radius_on_screen(vp, centre, radius, height_px) ==
            Approx(std::hypot(tx - cx, ty - cy)).epsilon(0.01));
    }
}

TEST_CASE(
    "the own sphere's ring reaches 8 px however small the sphere is on screen, and is 1.35 times a large one",
    "[camera]") {
  CHECK(outline_grow(2.5f, 8.0f, 1.35f) * 2.5f == Approx(8.0f));  // a phone's first view: 16 px across
  CHECK(outline_grow(20.0f, 8.0f, 1.35f) == 1.35f);
  CHECK(outline_grow(0.0f, 8.0f, 1.35f) == 1.35f);  // behind the camera: nothing to grow
}

}  // namespace
}  // namespace fishtank::viewer
