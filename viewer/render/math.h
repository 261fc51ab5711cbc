#pragma once
// The little linear algebra the viewer needs: a column-major 4x4 matrix (the
// layout glUniformMatrix4fv takes without transposing), a perspective and a
// look-at transform. Vectors are common/vec3.h's, shared with the server.

#include <algorithm>
#include <array>
#include <cmath>

#include "common/vec3.h"

namespace fishtank::viewer {

inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Vec3 normalize(Vec3 a) {
  float len = length(a);
  return len > 0.0f ? a * (1.0f / len) : Vec3{};
}
inline Vec3 lerp(Vec3 a, Vec3 b, float t) { return a + (b - a) * t; }

struct Mat4 {
  std::array<float, 16> m{};  // m[col * 4 + row]

  float& at(int row, int col) { return m[col * 4 + row]; }
  float at(int row, int col) const { return m[col * 4 + row]; }
  const float* data() const { return m.data(); }

  static Mat4 identity() {
    Mat4 r;
    for (int i = 0; i < 4; ++i) r.at(i, i) = 1.0f;
    return r;
  }
};

inline Mat4 operator*(const Mat4& a, const Mat4& b) {
  Mat4 r;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) {
      float s = 0.0f;
      for (int k = 0; k < 4; ++k) s += a.at(row, k) * b.at(k, col);
      r.at(row, col) = s;
    }
  return r;
}

// OpenGL clip space: z in [-w, w], right-handed eye space looking down -z.
inline Mat4 perspective(float fovy_radians, float aspect, float near, float far) {
  float f = 1.0f / std::tan(fovy_radians * 0.5f);
  Mat4 r;
  r.at(0, 0) = f / aspect;
  r.at(1, 1) = f;
  r.at(2, 2) = (far + near) / (near - far);
  r.at(2, 3) = 2.0f * far * near / (near - far);
  r.at(3, 2) = -1.0f;
  return r;
}

inline Mat4 look_at(Vec3 eye, Vec3 target, Vec3 up) {
  Vec3 f = normalize(target - eye);
  Vec3 s = normalize(cross(f, up));
  Vec3 u = cross(s, f);
  Mat4 r = Mat4::identity();
  r.at(0, 0) = s.x, r.at(0, 1) = s.y, r.at(0, 2) = s.z, r.at(0, 3) = -dot(s, eye);
  r.at(1, 0) = u.x, r.at(1, 1) = u.y, r.at(1, 2) = u.z, r.at(1, 3) = -dot(u, eye);
  r.at(2, 0) = -f.x, r.at(2, 1) = -f.y, r.at(2, 2) = -f.z, r.at(2, 3) = dot(f, eye);
  return r;
}

// The radius in pixels of a sphere of `radius` at `centre`, on a viewport
// `height_px` tall: row 1 of a perspective times a look-at is the focal
// length times the camera's up axis, row 3 the depth.
inline float radius_on_screen(const Mat4& view_proj, Vec3 centre, float radius, float height_px) {
  float depth = view_proj.at(3, 0) * centre.x + view_proj.at(3, 1) * centre.y +
                view_proj.at(3, 2) * centre.z + view_proj.at(3, 3);
  float focal = length(Vec3{view_proj.at(1, 0), view_proj.at(1, 1), view_proj.at(1, 2)});
  return depth > 0.0f ? radius * focal * 0.5f * height_px / depth : 0.0f;
}

// How much the own sphere's ring grows its radius: `grow`, or more where the
// sphere is small on screen, so that the ring reaches `min_px`.
inline float outline_grow(float radius_px, float min_px, float grow) {
  return radius_px > 0.0f ? std::max(grow, min_px / radius_px) : grow;
}

}  // namespace fishtank::viewer
