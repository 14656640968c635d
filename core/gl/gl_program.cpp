// gl_program.cpp — see gl_program.h.
#include "core/gl/gl_program.h"

#include <algorithm>

#include "core/gl/gl_api.h"

namespace sylva {

namespace {

std::string shader_log(GLuint shader) {
  GLint length = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
  glGetShaderInfoLog(shader, length, nullptr, log.data());
  log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
  return log;
}

std::string program_log(GLuint program) {
  GLint length = 0;
  glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
  glGetProgramInfoLog(program, length, nullptr, log.data());
  log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
  return log;
}

const char* stage_name(ShaderStage stage) { return stage == ShaderStage::vertex ? "vertex" : "fragment"; }

}  // namespace

GlProgram build_gl_program(const ShaderProgramSource& source) {
  GlProgram result;
  result.name = source.name;
  GLuint shaders[2] = {0, 0};
  std::string failure;
  const ShaderStageSource* stages[2] = {&source.vertex, &source.fragment};
  for (int i = 0; i < 2; ++i) {
    const ShaderStageSource& stage = *stages[i];
    const std::string text = assemble_shader(stage);
    shaders[i] = glCreateShader(stage.stage == ShaderStage::vertex ? GL_VERTEX_SHADER : GL_FRAGMENT_SHADER);
    const char* pointer = text.c_str();
    glShaderSource(shaders[i], 1, &pointer, nullptr);
    glCompileShader(shaders[i]);
    GLint ok = GL_FALSE;
    glGetShaderiv(shaders[i], GL_COMPILE_STATUS, &ok);
    const std::string log = format_shader_log(stage, shader_log(shaders[i]));
    if (log.find_first_not_of(" \n") != std::string::npos)
      result.info_log += std::string(stage_name(stage.stage)) + " shader:\n" + log;
    if (!ok) failure += std::string(stage_name(stage.stage)) + " shader does not compile:\n" + log;
  }
  GLuint program = 0;
  if (failure.empty()) {
    program = glCreateProgram();
    glAttachShader(program, shaders[0]);
    glAttachShader(program, shaders[1]);
    glLinkProgram(program);
    GLint ok = GL_FALSE;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    const std::string log = program_log(program);
    if (log.find_first_not_of(" \n") != std::string::npos) result.info_log += "link:\n" + log;
    if (!ok) {
      failure = "program does not link:\n" + log;
      glDeleteProgram(program);
      program = 0;
    } else {
      glDetachShader(program, shaders[0]);
      glDetachShader(program, shaders[1]);
    }
  }
  for (GLuint shader : shaders)
    if (shader) glDeleteShader(shader);
  if (!failure.empty()) throw GlError("shader program " + source.name + ": " + failure);
  result.id = program;
  return result;
}

}  // namespace sylva
