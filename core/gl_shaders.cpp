// gl_shaders.cpp — see gl_shaders.h.
#include "core/gl_shaders.h"

#include <stdexcept>

namespace sylva {

std::string_view embedded_shader(std::string_view name) {
  for (size_t i = 0; i < kEmbeddedShaderCount; ++i)
    if (name == kEmbeddedShaders[i].name) return kEmbeddedShaders[i].source;
  throw std::logic_error("embedded_shader: no shaders/" + std::string(name) + " in this build");
}

std::string assemble_shader(const ShaderStageSource& stage) {
  std::string text = "#version 450 core\n";
  for (const std::string& define : stage.defines) text += "#define " + define + "\n";
  for (size_t i = 0; i < stage.files.size(); ++i) {
    text += "#line 1 " + std::to_string(i) + "\n";
    text += embedded_shader(stage.files[i]);
    if (text.back() != '\n') text += '\n';
  }
  return text;
}

std::string format_shader_log(const ShaderStageSource& stage, const std::string& log) {
  // Mesa writes "N:L(C): error: ...", glslang "ERROR: N:L: ...": a number right before
  // ':' at the start of a line or after "ERROR: " / "WARNING: " is a source string.
  std::string out;
  size_t line_start = 0;
  while (line_start < log.size()) {
    size_t line_end = log.find('\n', line_start);
    if (line_end == std::string::npos) line_end = log.size();
    std::string line = log.substr(line_start, line_end - line_start);
    size_t p = 0;
    for (const char* prefix : {"ERROR: ", "WARNING: "})
      if (line.rfind(prefix, 0) == 0) p = std::string(prefix).size();
    size_t digits = p;
    while (digits < line.size() && line[digits] >= '0' && line[digits] <= '9') ++digits;
    if (digits > p && digits < line.size() && line[digits] == ':') {
      const size_t index = std::stoul(line.substr(p, digits - p));
      if (index < stage.files.size()) line = line.substr(0, p) + stage.files[index] + line.substr(digits);
    }
    out += line + "\n";
    line_start = line_end + 1;
  }
  return out;
}

namespace {

// The frusta program's shared files, in the order of the C++ they mirror: the intersector
// (ray_frustum.h), skinning and the GPU record (skin.h), then the pass's interface.
const std::vector<std::string> kFrustaCommon = {"ray_frustum.glsl", "skin.glsl", "frusta_common.glsl"};

std::vector<std::string> with(std::vector<std::string> files, const std::string& last) {
  files.push_back(last);
  return files;
}

}  // namespace

ShaderProgramSource frusta_program(FrustaPass pass, bool want_uv) {
  ShaderProgramSource p;
  std::vector<std::string> defines;
  switch (pass) {
    case FrustaPass::gbuffer:
      p.name = "frusta[GBUFFER_PASS";
      defines = {"GBUFFER_PASS"};
      break;
    case FrustaPass::gbuffer_eye_inside:
      p.name = "frusta[GBUFFER_PASS EYE_INSIDE";
      defines = {"GBUFFER_PASS", "EYE_INSIDE"};
      break;
    case FrustaPass::shadow:
      p.name = "frusta[SHADOW_PASS";
      defines = {"SHADOW_PASS"};
      break;
  }
  if (want_uv && pass != FrustaPass::shadow) {
    p.name += " WANT_UV";
    defines.push_back("WANT_UV");
  }
  p.name += "]";
  p.vertex = {ShaderStage::vertex, with(kFrustaCommon, "frusta.vert.glsl"), defines};
  p.fragment = {ShaderStage::fragment, with(kFrustaCommon, "frusta.frag.glsl"), defines};
  return p;
}

ShaderProgramSource shade_program(bool sun) {
  ShaderProgramSource p;
  std::vector<std::string> defines;
  if (sun) defines.push_back("SUN");
  p.name = sun ? "shade[SUN]" : "shade[]";
  p.vertex = {ShaderStage::vertex, {"fullscreen.vert.glsl"}, {}};
  p.fragment = {ShaderStage::fragment, {"shade.frag.glsl"}, defines};
  return p;
}

std::vector<ShaderProgramSource> all_shader_programs() {
  std::vector<ShaderProgramSource> all;
  for (FrustaPass pass : {FrustaPass::gbuffer, FrustaPass::gbuffer_eye_inside, FrustaPass::shadow})
    for (bool uv : {false, true}) {
      if (pass == FrustaPass::shadow && uv) continue;
      all.push_back(frusta_program(pass, uv));
    }
  for (bool sun : {false, true}) all.push_back(shade_program(sun));
  return all;
}

}  // namespace sylva
