#include "viewer/render/gl_program.h"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace fishtank::viewer {
namespace {

GLuint compile(GLenum type, const char* source) {
  GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::string log(4096, '\0');
    glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
    std::fprintf(stderr, "fishtank-viewer: shader does not compile:\n%s\n", log.c_str());
    std::exit(1);
  }
  return shader;
}

}  // namespace

GLuint build_program(const char* vertex_source, const char* fragment_source) {
  GLuint vs = compile(GL_VERTEX_SHADER, vertex_source);
  GLuint fs = compile(GL_FRAGMENT_SHADER, fragment_source);
  GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    std::string log(4096, '\0');
    glGetProgramInfoLog(program, static_cast<GLsizei>(log.size()), nullptr, log.data());
    std::fprintf(stderr, "fishtank-viewer: shader program does not link:\n%s\n", log.c_str());
    std::exit(1);
  }
  return program;
}

}  // namespace fishtank::viewer
