#include "viewer/render/tank_outline.h"

#include <array>

#include "viewer/render/gl_program.h"

namespace fishtank::viewer {
namespace {

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_pos;
uniform mat4 u_view_proj;
void main() { gl_Position = u_view_proj * vec4(a_pos, 1.0); }
)";

// Blended over the scene so the lines stay faint against balls and background.
constexpr const char* kFragmentShader = R"(#version 330 core
out vec4 frag_colour;
void main() { frag_colour = vec4(0.75, 0.82, 0.95, 0.35); }
)";

constexpr int kEdgeVertices = 24;

}  // namespace

TankOutline::TankOutline() {
  program_ = build_program(kVertexShader, kFragmentShader);
  u_view_proj_ = glGetUniformLocation(program_, "u_view_proj");
  glGenVertexArrays(1, &vao_);
  glBindVertexArray(vao_);
  glGenBuffers(1, &vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3), nullptr);
  glBindVertexArray(0);
  set_bounds(TankBounds{});
}

TankOutline::~TankOutline() {
  glDeleteBuffers(1, &vbo_);
  glDeleteVertexArrays(1, &vao_);
  glDeleteProgram(program_);
}

void TankOutline::set_bounds(const TankBounds& b) {
  // Corner c has x from bit 0, y from bit 1, z from bit 2; an edge joins two
  // corners that differ in exactly one bit.
  auto corner = [&](int c) {
    return Vec3{(c & 1) ? b.max.x : b.min.x, (c & 2) ? b.max.y : b.min.y, (c & 4) ? b.max.z : b.min.z};
  };
  std::array<Vec3, kEdgeVertices> lines;
  int n = 0;
  for (int c = 0; c < 8; ++c)
    for (int bit = 1; bit < 8; bit <<= 1)
      if (!(c & bit)) {
        lines[n++] = corner(c);
        lines[n++] = corner(c | bit);
      }
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, sizeof(lines), lines.data(), GL_STATIC_DRAW);
}

void TankOutline::draw(const Mat4& view_proj) {
  glUseProgram(program_);
  glUniformMatrix4fv(u_view_proj_, 1, GL_FALSE, view_proj.data());
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glBindVertexArray(vao_);
  glDrawArrays(GL_LINES, 0, kEdgeVertices);
  glBindVertexArray(0);
  glDisable(GL_BLEND);
}

}  // namespace fishtank::viewer
