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
#include <map>
#include <string>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/gl/gl_context.h"
#include "core/gl/gl_objects.h"
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

// The program variants of one GL context, each built on first use and kept. Renderers
// made one after another on the same context (the studio's, one per regrown plant) share
// one cache, so a new renderer finds its variants linked — and, on llvmpipe, already
// compiled to machine code: Mesa JITs a program's shaders at its first draw, which cost the
// pine's first picture ~0.2 s on every regrow (docs/benchmarks.md, the studio). Keyed by
// the variant's name and its assembled sources, so two variants never share a program.
// Sharing is safe because the renderers set every uniform of a program before each frame
// they draw with it. Preconditions: used on the context that built it, by one thread at a
// time, and destroyed while that context is current.
class GlProgramCache {
 public:
  // The program of `source`: the kept one, or built now (its compile and link time added
  // to *compile_s and its name appended to *compiled, comma-separated). Throws GlError as
  // build_gl_program does (nothing is kept then).
  uint32_t get(const ShaderProgramSource& source, double* compile_s = nullptr, std::string* compiled = nullptr);
  size_t size() const { return programs_.size(); }

 private:
  std::map<std::string, GlProgramObject> programs_;
};

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
