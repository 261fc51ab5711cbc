#include "viewer/render/sphere_mesh.h"

#include <cmath>

namespace fishtank::viewer {

SphereMesh make_uv_sphere(int segments_u, int segments_v) {
  constexpr float kPi = 3.14159265358979f;
  SphereMesh mesh;
  // (segments_v + 1) rings of (segments_u + 1) vertices: the seam column is
  // repeated so that rings index uniformly; it has the same normal both times.
  for (int j = 0; j <= segments_v; ++j) {
    float theta = kPi * static_cast<float>(j) / static_cast<float>(segments_v);  // from +y
    for (int i = 0; i <= segments_u; ++i) {
      float phi = 2.0f * kPi * static_cast<float>(i) / static_cast<float>(segments_u);
      mesh.vertices.push_back(
          {std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)});
    }
  }
  const int ring = segments_u + 1;
  for (int j = 0; j < segments_v; ++j) {
    for (int i = 0; i < segments_u; ++i) {
      auto a = static_cast<std::uint16_t>(j * ring + i);  // upper left of the patch
      auto b = static_cast<std::uint16_t>(a + ring);      // lower left
      auto c = static_cast<std::uint16_t>(b + 1);         // lower right
      auto d = static_cast<std::uint16_t>(a + 1);         // upper right
      if (j != 0) mesh.indices.insert(mesh.indices.end(), {a, b, d});
      if (j != segments_v - 1) mesh.indices.insert(mesh.indices.end(), {d, b, c});
    }
  }
  return mesh;
}

}  // namespace fishtank::viewer
