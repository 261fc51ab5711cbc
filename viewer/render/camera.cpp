#include "viewer/render/camera.h"

#include <algorithm>
#include <cmath>

namespace fishtank::viewer {
namespace {

constexpr float kFov = 0.7854f;  // 45 degrees, across the window's narrower side
constexpr float kOrbitRadiansPerPixel = 0.005f;
constexpr float kMaxPitch = 1.5f;  // just short of straight down, where look_at degenerates

}  // namespace

void OrbitCamera::frame(const TankBounds& tank) {
  Vec3 size = tank.size();
  // Aim a little below the centre: the pile sits on the floor, and from above
  // the floor would otherwise crowd the bottom of the picture.
  target_ = tank.min + Vec3{size.x * 0.5f, size.y * 0.45f, size.z * 0.5f};
  // The bounding sphere of the box fits the field of view, whichever the aspect.
  float radius = 0.5f * length(size);
  distance_ = radius / std::sin(kFov * 0.5f);
  min_distance_ = 0.05f * radius;
  max_distance_ = 6.0f * radius;
  yaw_ = 0.0f;
  pitch_ = 0.35f;
}

void OrbitCamera::orbit(float dx_pixels, float dy_pixels) {
  yaw_ -= dx_pixels * kOrbitRadiansPerPixel;
  pitch_ = std::clamp(pitch_ + dy_pixels * kOrbitRadiansPerPixel, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::zoom(float wheel_steps) {
  distance_ = std::clamp(distance_ * std::pow(0.9f, wheel_steps), min_distance_, max_distance_);
}

Vec3 OrbitCamera::eye() const {
  float c = std::cos(pitch_);
  return target_ + Vec3{-std::sin(yaw_) * c, std::sin(pitch_), std::cos(yaw_) * c} * distance_;
}

Mat4 OrbitCamera::view_projection(float window_aspect) const {
  const float aspect =
      window_aspect > 0.0f && std::isfinite(window_aspect) ? window_aspect : 1.0f;  // minimised
  // A tall window (a phone held upright) widens the vertical field, so that
  // the horizontal one stays kFov and the tank still fits across.
  float fov_y = aspect >= 1.0f ? kFov : 2.0f * std::atan(std::tan(kFov * 0.5f) / aspect);
  return perspective(fov_y, aspect, 0.1f, distance_ + max_distance_) *
         look_at(eye(), target_, {0.0f, 1.0f, 0.0f});
}

Vec3 OrbitCamera::forward_on_ground() const { return {std::sin(yaw_), 0.0f, -std::cos(yaw_)}; }

Vec3 OrbitCamera::right_on_ground() const { return cross(forward_on_ground(), {0.0f, 1.0f, 0.0f}); }

}  // namespace fishtank::viewer
