#pragma once
// The ball mesh (SPEC 5.2): a UV sphere of 12 x 12 surface patches, built once
// and drawn for every ball by instancing.
//
// On the unit sphere a vertex's position is its own normal, so one attribute
// serves both. Neighbouring patches share their corner vertices, so each vertex
// has one normal and the shading is smooth across patch edges, not flat.
// The patches touching a pole have two corners at the pole and are one triangle.

#include <cstdint>
#include <vector>

#include "common/vec3.h"

namespace fishtank::viewer {

struct SphereMesh {
  std::vector<Vec3> vertices;          // unit length; also the normals
  std::vector<std::uint16_t> indices;  // counter-clockwise triangles seen from outside
};

// segments_u patches around (longitude) by segments_v from pole to pole (latitude).
SphereMesh make_uv_sphere(int segments_u = 12, int segments_v = 12);

}  // namespace fishtank::viewer
