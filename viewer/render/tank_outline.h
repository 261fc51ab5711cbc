#pragma once
// The tank's twelve edges as faint lines. The tank itself is invisible
// (SPEC 1.1); the outline is an aid to see where the walls are (key T).

#include <GL/glew.h>

#include "common/tank.h"
#include "viewer/render/math.h"

namespace fishtank::viewer {

class TankOutline {
 public:
  TankOutline();  // needs a current OpenGL 3.3 context
  ~TankOutline();
  TankOutline(const TankOutline&) = delete;
  TankOutline& operator=(const TankOutline&) = delete;

  void set_bounds(const TankBounds& bounds);
  void draw(const Mat4& view_proj);

 private:
  GLuint program_ = 0;
  GLuint vao_ = 0;
  GLuint vbo_ = 0;
  GLint u_view_proj_ = -1;
};

}  // namespace fishtank::viewer
