#include "viewer/render/sphere_renderer.h"

#include <cstddef>

#include "viewer/render/gl_program.h"
#include "viewer/render/sphere_mesh.h"

namespace fishtank::viewer {
namespace {

// The mesh vertex is on the unit sphere, so it is scaled by the instance's
// radius for the position and used unchanged as the normal (uniform scale
// keeps normals valid without a normal matrix).
constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_unit;
layout(location = 1) in vec4 i_centre_radius;
layout(location = 2) in vec4 i_colour;
uniform mat4 u_view_proj;
uniform float u_grow;
uniform float u_depth_grow;
out vec3 v_normal;
out vec3 v_colour;
void main() {
  v_normal = a_unit;
  v_colour = i_colour.rgb;
  vec3 world = i_centre_radius.xyz + a_unit * (i_centre_radius.w * u_grow);
  gl_Position = u_view_proj * vec4(world, 1.0);
  // The hidden pass: the ring's size at the sphere's own depth, so that what hides the sphere turns amber.
  if (u_depth_grow != u_grow) {
    vec4 at = u_view_proj * vec4(i_centre_radius.xyz + a_unit * (i_centre_radius.w * u_depth_grow), 1.0);
    gl_Position.z = at.z / at.w * gl_Position.w;
  }
}
)";

// One fixed light from above and in front of the default camera, plus ambient
// so that the unlit side of a ball still shows its colour.
constexpr const char* kFragmentShader = R"(#version 330 core
in vec3 v_normal;
in vec3 v_colour;
uniform bool u_unlit;
out vec4 frag_colour;
const vec3 kLightDir = normalize(vec3(0.35, 0.85, 0.45));
const float kAmbient = 0.28;
void main() {
  float lambert = max(dot(normalize(v_normal), kLightDir), 0.0);
  float light = u_unlit ? 1.0 : kAmbient + (1.0 - kAmbient) * lambert;
  frag_colour = vec4(v_colour * light, 1.0);
}
)";

// The hidden pass takes its depth from a sphere a tenth larger than the own one:
// just in front of its surface, so that where the sphere is in view, the amber
// never ties with it in the depth test.
constexpr float kHiddenDepthGrow = 1.1f;

}  // namespace

SphereRenderer::SphereRenderer() {
  program_ = build_program(kVertexShader, kFragmentShader);
  u_view_proj_ = glGetUniformLocation(program_, "u_view_proj");
  u_grow_ = glGetUniformLocation(program_, "u_grow");
  u_depth_grow_ = glGetUniformLocation(program_, "u_depth_grow");
  u_unlit_ = glGetUniformLocation(program_, "u_unlit");

  SphereMesh mesh = make_uv_sphere(12, 12);
  index_count_ = static_cast<GLsizei>(mesh.indices.size());

  glGenVertexArrays(1, &vao_);
  glBindVertexArray(vao_);

  glGenBuffers(1, &mesh_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, mesh_vbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.vertices.size() * sizeof(Vec3)),
               mesh.vertices.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3), nullptr);

  glGenBuffers(1, &index_buffer_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, index_buffer_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.indices.size() * sizeof(std::uint16_t)),
               mesh.indices.data(), GL_STATIC_DRAW);

  glGenBuffers(1, &instance_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, instance_vbo_);
  const auto stride = static_cast<GLsizei>(sizeof(SphereInstance));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<void*>(offsetof(SphereInstance, x)));
  glVertexAttribDivisor(1, 1);
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 4, GL_UNSIGNED_BYTE, GL_TRUE, stride,
                        reinterpret_cast<void*>(offsetof(SphereInstance, rgba)));
  glVertexAttribDivisor(2, 1);

  glBindVertexArray(0);
}

SphereRenderer::~SphereRenderer() {
  glDeleteBuffers(1, &instance_vbo_);
  glDeleteBuffers(1, &index_buffer_);
  glDeleteBuffers(1, &mesh_vbo_);
  glDeleteVertexArrays(1, &vao_);
  glDeleteProgram(program_);
}

void SphereRenderer::upload(const SphereInstance* spheres, std::size_t count) {
  // Orphan and refill: the driver hands out fresh storage instead of waiting
  // for the previous frame's draw to finish reading the old one.
  glBindBuffer(GL_ARRAY_BUFFER, instance_vbo_);
  const auto bytes = static_cast<GLsizeiptr>(count * sizeof(SphereInstance));
  glBufferData(GL_ARRAY_BUFFER, bytes, nullptr, GL_STREAM_DRAW);
  glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, spheres);
}

void SphereRenderer::prepare(const Mat4& view_proj, float grow, float depth_grow, bool unlit,
                             const SphereInstance* spheres, std::size_t count) {
  glUseProgram(program_);
  glUniformMatrix4fv(u_view_proj_, 1, GL_FALSE, view_proj.data());
  glUniform1f(u_grow_, grow);
  glUniform1f(u_depth_grow_, depth_grow);
  glUniform1i(u_unlit_, unlit ? GL_TRUE : GL_FALSE);
  glBindVertexArray(vao_);
  upload(spheres, count);
}

void SphereRenderer::draw(const Mat4& view_proj, const std::vector<SphereInstance>& spheres) {
  if (spheres.empty()) return;
  prepare(view_proj, 1.0f, 1.0f, false, spheres.data(), spheres.size());
  glDrawElementsInstanced(GL_TRIANGLES, index_count_, GL_UNSIGNED_SHORT, nullptr,
                          static_cast<GLsizei>(spheres.size()));
  glBindVertexArray(0);
}

void SphereRenderer::draw_outline(const Mat4& view_proj, const SphereInstance& sphere, float grow) {
  prepare(view_proj, grow, grow, true, &sphere, 1);
  glCullFace(GL_FRONT);
  glDrawElementsInstanced(GL_TRIANGLES, index_count_, GL_UNSIGNED_SHORT, nullptr, 1);
  glCullFace(GL_BACK);
  glBindVertexArray(0);
}

void SphereRenderer::draw_hidden(const Mat4& view_proj, const SphereInstance& sphere, float grow,
                                 float alpha) {
  prepare(view_proj, grow, kHiddenDepthGrow, true, &sphere, 1);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendColor(0.0f, 0.0f, 0.0f, alpha);
  glBlendFunc(GL_CONSTANT_ALPHA, GL_ONE_MINUS_CONSTANT_ALPHA);
  glDrawElementsInstanced(GL_TRIANGLES, index_count_, GL_UNSIGNED_SHORT, nullptr, 1);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glBindVertexArray(0);
}

}  // namespace fishtank::viewer
