#pragma once
// Draws spheres: every ball and player in one instanced draw of the shared
// 12 x 12 patch mesh, lit by one directional light (Lambert + ambient).

#include <GL/glew.h>

#include <vector>

#include "viewer/render/instance.h"
#include "viewer/render/math.h"

namespace fishtank::viewer {

class SphereRenderer {
 public:
  SphereRenderer();  // needs a current OpenGL 3.3 context
  ~SphereRenderer();
  SphereRenderer(const SphereRenderer&) = delete;
  SphereRenderer& operator=(const SphereRenderer&) = delete;

  void draw(const Mat4& view_proj, const std::vector<SphereInstance>& spheres);
  // A ring around one sphere: the sphere grown by `grow`, unlit, back faces
  // only (the "inverted hull"), so the real sphere drawn in front hides all
  // but a rim. Marks the viewer's own player among other white ones.
  void draw_outline(const Mat4& view_proj, const SphereInstance& sphere, float grow);
  // Where what was drawn before hides the sphere, a disc of the sphere grown by
  // `grow` (its ring's size) at the sphere's own depth, its flat colour blended
  // over that at `alpha` (the depth test passes only behind): the viewer's own
  // sphere found inside the pile it starts in. Where it is in view, nothing changes.
  void draw_hidden(const Mat4& view_proj, const SphereInstance& sphere, float grow, float alpha);

 private:
  // The program and its uniforms bound, and these spheres uploaded as the instances to draw.
  void prepare(const Mat4& view_proj, float grow, float depth_grow, bool unlit, const SphereInstance* spheres,
               std::size_t count);
  void upload(const SphereInstance* spheres, std::size_t count);

  GLuint program_ = 0;
  GLuint vao_ = 0;
  GLuint mesh_vbo_ = 0;
  GLuint index_buffer_ = 0;
  GLuint instance_vbo_ = 0;
  GLsizei index_count_ = 0;
  GLint u_view_proj_ = -1;
  GLint u_grow_ = -1;
  GLint u_depth_grow_ = -1;
  GLint u_unlit_ = -1;
};

}  // namespace fishtank::viewer
