// gl_program.cpp — see gl_program.h.
#include "core/gl/gl_program.h"

#include <algorithm>
#include <chrono>

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

namespace {
GLint location(uint32_t program, const char* name) { return glGetUniformLocation(program, name); }
}  // namespace

void set_uniform(uint32_t p, const char* name, double value) {
  glProgramUniform1f(p, location(p, name), static_cast<float>(value));
}
void set_uniform(uint32_t p, const char* name, double x, double y) {
  glProgramUniform2f(p, location(p, name), static_cast<float>(x), static_cast<float>(y));
}
void set_uniform(uint32_t p, const char* name, double x, double y, double z, double w) {
  glProgramUniform4f(p, location(p, name), static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
                     static_cast<float>(w));
}
void set_uniform(uint32_t p, const char* name, const glm::vec3& v) {
  glProgramUniform3f(p, location(p, name), v.x, v.y, v.z);
}
void set_uniform(uint32_t p, const char* name, const glm::dvec3& v) { set_uniform(p, name, glm::vec3(v)); }
void set_uniform_int(uint32_t p, const char* name, int value) { glProgramUniform1i(p, location(p, name), value); }
void set_uniform_uint(uint32_t p, const char* name, uint32_t value) { glProgramUniform1ui(p, location(p, name), value); }
void set_uniform_vec3_array(uint32_t p, const char* name, int count, const float* xyz) {
  glProgramUniform3fv(p, location(p, name), count, xyz);
}
void set_uniform_float_array(uint32_t p, const char* name, int count, const float* x) {
  glProgramUniform1fv(p, location(p, name), count, x);
}

uint32_t GlProgramCache::get(const ShaderProgramSource& source, double* compile_s, std::string* compiled) {
  std::string key = source.name;
  key += '\0';
  key += assemble_shader(source.vertex);
  key += '\0';
  key += assemble_shader(source.fragment);
  auto found = programs_.find(key);
  if (found != programs_.end()) return found->second.id();
  const auto start = std::chrono::steady_clock::now();
  GlProgramObject built(build_gl_program(source).id);
  if (compile_s) *compile_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (compiled) *compiled += (compiled->empty() ? "" : ", ") + source.name;
  return programs_.emplace(std::move(key), std::move(built)).first->second.id();
}

}  // namespace sylva
