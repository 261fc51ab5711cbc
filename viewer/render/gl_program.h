#pragma once
// Compiles and links a GLSL program, exiting with the driver's log on failure:
// a shader that does not build is a programming error, not a runtime condition.

#include <GL/glew.h>

namespace fishtank::viewer {

GLuint build_program(const char* vertex_source, const char* fragment_source);

}  // namespace fishtank::viewer
