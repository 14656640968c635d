// gl_program.h — compiling and linking one shader program variant (gl_shaders.h) on the
// current OpenGL context, with the driver's info logs kept: a failure throws GlError
// naming the variant and each message's file and line; a success still returns the logs
// (the shader tests require them free of warnings).
#pragma once

#include <cstdint>
#include <string>

#include "core/gl/gl_context.h"
#include "core/gl/gl_shaders.h"

namespace sylva {

struct GlProgram {
  uint32_t id = 0;       // the GL program object (the caller deletes it)
  std::string name;      // the variant's name
  std::string info_log;  // compile logs of both stages and the link log, file names restored
};

// Compiles both stages and links them. Throws GlError with the logs on failure.
GlProgram build_gl_program(const ShaderProgramSource& source);

}  // namespace sylva
