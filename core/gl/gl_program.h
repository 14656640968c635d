// gl_program.h — compiling and linking one shader program variant (gl_shaders.h) on the
// current OpenGL context, with the driver's info logs kept: a failure throws GlError
// naming the variant and each message's file and line; a success still returns the logs
// (the shader tests require them free of warnings).
//
// Uniforms of the default block are set by name on a program (glProgramUniform*, no
// glUseProgram): a name the variant does not declare, or one the compiler removed as
// unused, has location -1 and is silently skipped, so one call fits every variant. Values
// given as double are converted to float once, here. The std140 blocks every variant shares
// (the camera, the sun's view) are buffers instead (bindings.h).
#pragma once

#include <cstdint>
#include <string>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/gl/gl_context.h"
#include "core/gl/gl_shaders.h"

namespace sylva {

struct GlProgram {
  uint32_t id = 0;       // the GL program object (the caller deletes it, or gives it to a
                         // GlProgramObject, gl_objects.h)
  std::string name;      // the variant's name
  std::string info_log;  // compile logs of both stages and the link log, file names restored
};

// Compiles both stages and links them. Throws GlError with the logs on failure.
GlProgram build_gl_program(const ShaderProgramSource& source);

void set_uniform(uint32_t program, const char* name, double value);                  // float
void set_uniform(uint32_t program, const char* name, double x, double y);            // vec2
void set_uniform(uint32_t program, const char* name, double x, double y, double z, double w);  // vec4
void set_uniform(uint32_t program, const char* name, const glm::vec3& value);        // vec3
void set_uniform(uint32_t program, const char* name, const glm::dvec3& value);       // vec3
void set_uniform_int(uint32_t program, const char* name, int value);                 // int, bool, sampler
void set_uniform_uint(uint32_t program, const char* name, uint32_t value);           // uint
// vec3 name[count] from `count` consecutive x, y, z floats.
void set_uniform_vec3_array(uint32_t program, const char* name, int count, const float* xyz);
// float name[count] from `count` floats.
void set_uniform_float_array(uint32_t program, const char* name, int count, const float* x);

}  // namespace sylva
