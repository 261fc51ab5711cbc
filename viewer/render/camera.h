#pragma once
// An orbit camera around the tank: yaw and pitch on a sphere around a target,
// distance for zoom. Also gives the ground-plane axes that player movement is
// relative to, so "forward" is always away from the viewer.

#include "common/tank.h"
#include "viewer/render/math.h"

namespace fishtank::viewer {

class OrbitCamera {
 public:
  // Frames the whole tank from slightly above, at any aspect ratio.
  void frame(const TankBounds& tank);

  void orbit(float dx_pixels, float dy_pixels);
  void zoom(float wheel_steps);

  Vec3 eye() const;
  Mat4 view_projection(float aspect) const;
  Vec3 forward_on_ground() const;  // unit, y = 0
  Vec3 right_on_ground() const;    // unit, y = 0

 private:
  Vec3 target_{0.0f, 20.0f, 0.0f};
  float yaw_ = 0.0f;     // radians around +y; 0 looks along -z
  float pitch_ = 0.35f;  // radians above the horizon
  float distance_ = 90.0f;
  float min_distance_ = 2.0f;
  float max_distance_ = 400.0f;
};

}  // namespace fishtank::viewer
