// The ball mesh is the one SPEC 5.2 asks for: 12 x 12 patches, smooth normals.

#include "viewer/render/sphere_mesh.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "viewer/render/math.h"

using namespace fishtank;
using namespace fishtank::viewer;

TEST_CASE("the ball mesh has 12 x 12 patches: 10 rings of quads and 2 pole fans") {
  SphereMesh m = make_uv_sphere(12, 12);
  CHECK(m.vertices.size() == 13u * 13u);
  // 12 patches around times 10 inner rows of two triangles, plus 12 triangles at each pole.
  CHECK(m.indices.size() == 3u * (12u * 10u * 2u + 2u * 12u));
}

TEST_CASE("every vertex lies on the unit sphere, so its position is its smooth normal") {
  SphereMesh m = make_uv_sphere(12, 12);
  for (const Vec3& v : m.vertices) REQUIRE(length(v) == Approx(1.0f).margin(1e-6));
}

TEST_CASE("triangles are non-degenerate and wound counter-clockwise seen from outside") {
  SphereMesh m = make_uv_sphere(12, 12);
  for (std::size_t t = 0; t < m.indices.size(); t += 3) {
    Vec3 a = m.vertices[m.indices[t]], b = m.vertices[m.indices[t + 1]], c = m.vertices[m.indices[t + 2]];
    Vec3 n = cross(b - a, c - a);
    REQUIRE(length(n) > 1e-4f);
    REQUIRE(dot(n, a + b + c) > 0.0f);  // the face normal points away from the centre
  }
}

TEST_CASE("neighbouring patches share vertices, so the shading has no seams between patches") {
  SphereMesh m = make_uv_sphere(12, 12);
  // Each inner vertex is used by the triangles of the four patches around it.
  std::vector<int> uses(m.vertices.size(), 0);
  for (auto i : m.indices) ++uses[i];
  const int ring = 13;  // 12 segments and the seam's copy of the first vertex
  for (int row = 1; row < 12; ++row)
    for (int column = 1; column < 12; ++column) {
      INFO("ring " << row << ", vertex " << column);
      // 6 triangles of the 4 patches around it; next to a pole, whose patches are one triangle each, 5.
      CHECK(uses[row * ring + column] == (row == 1 || row == 11 ? 5 : 6));
    }
}
