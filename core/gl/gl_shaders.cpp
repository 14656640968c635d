// gl_shaders.cpp — see gl_shaders.h.
#include "core/gl/gl_shaders.h"

#include <algorithm>
#include <charconv>
#include <stdexcept>

#include "core/scene/fog_integrator.h"
#include "core/light/shading.h"

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
    if (i == 0) {
      // bindings.glsl heads file 0's slot under its own number, then file 0 starts at its
      // line 1 again.
      text += "#line 1 " + std::to_string(stage.files.size()) + "\n";
      text += embedded_shader(kBindingsFile);
      if (text.back() != '\n') text += '\n';
      text += "#line 1 0\n";
    }
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
      else if (index == stage.files.size()) line = line.substr(0, p) + kBindingsFile + line.substr(digits);
    }
    out += line + "\n";
    line_start = line_end + 1;
  }
  return out;
}

namespace {

// The frusta program's shared files, in the order of the C++ they mirror: the intersector
// (ray_frustum.h), skinning and the GPU record (skin.h), the views (shared with the
// meshes), the instances' transforms (shared with the meshes), then the pass's interface.
const std::vector<std::string> kFrustaCommon = {"ray_frustum.glsl", "skin.glsl", "views.glsl", "instances.glsl",
                                                 "frusta_common.glsl"};

std::vector<std::string> with(std::vector<std::string> files, const std::string& last) {
  files.push_back(last);
  return files;
}

}  // namespace

ShaderProgramSource frusta_program(FrustaPass pass, const FrustaFeatures& features) {
  ShaderProgramSource p;
  std::vector<std::string> defines;
  switch (pass) {
    case FrustaPass::gbuffer:
      defines = {"GBUFFER_PASS"};
      break;
    case FrustaPass::gbuffer_eye_inside:
      defines = {"GBUFFER_PASS", "EYE_INSIDE"};
      break;
    case FrustaPass::shadow:
      defines = {"SHADOW_PASS"};
      break;
  }
  const bool shadow = pass == FrustaPass::shadow;
  const bool bark = features.bark && !shadow;
  // The G-buffer pass's relief filters the normal's heights through the height texture;
  // the shadow pass reads the finest level alone (height_texels).
  const int units = (bark || (features.relief && !shadow)) ? std::max(1, features.texture_units) : 0;
  if (features.want_uv && !shadow) defines.push_back("WANT_UV");
  if (features.relief) defines.push_back("RELIEF");
  if (features.relief && features.crotch_fade) defines.push_back("CROTCH_FADE");
  if (bark) defines.push_back("BARK");
  if (units > 0) defines.push_back("BARK_TEXTURE_UNITS " + std::to_string(units));
  if (!features.conservative_depth) defines.push_back("NO_CONSERVATIVE_DEPTH");
  if (features.instanced) defines.push_back("INSTANCED");
  p.name = "frusta[";
  for (size_t i = 0; i < defines.size(); ++i) {
    std::string name = defines[i];
    if (name.rfind("BARK_TEXTURE_UNITS ", 0) == 0) name = "TEXTURE_UNITS=" + std::to_string(units);
    p.name += (i ? " " : "") + name;
  }
  p.name += "]";
  std::vector<std::string> files = kFrustaCommon;
  if (features.relief || bark) files.insert(files.end(), {"srgb.glsl", "bark.glsl"});
  if (features.relief && features.crotch_fade) files.push_back("crotch.glsl");
  if (features.relief) files.push_back("relief.glsl");
  p.vertex = {ShaderStage::vertex, with(files, "frusta.vert.glsl"), defines};
  p.fragment = {ShaderStage::fragment, with(files, "frusta.frag.glsl"), defines};
  return p;
}

ShaderProgramSource frusta_program(FrustaPass pass, bool want_uv) {
  FrustaFeatures features;
  features.want_uv = want_uv;
  return frusta_program(pass, features);
}

ShaderProgramSource mesh_program(MeshPass pass, int bark_texture_units, bool leaf_images, bool instanced) {
  const bool shadow = pass == MeshPass::shadow;
  std::vector<std::string> defines = {shadow ? "SHADOW_PASS" : "GBUFFER_PASS"};
  ShaderProgramSource p;
  p.name = shadow ? "mesh[SHADOW_PASS" : "mesh[GBUFFER_PASS";
  if (leaf_images) {
    defines.push_back("LEAF_IMAGES");
    p.name += " LEAF_IMAGES";
  }
  if (instanced) {
    defines.push_back("INSTANCED");
    p.name += " INSTANCED";
  }
  std::vector<std::string> fragment_files = {"mesh.frag.glsl"};
  if (!shadow && bark_texture_units > 0) {
    defines.push_back("BARK_TEXTURE_UNITS " + std::to_string(bark_texture_units));
    p.name += " TEXTURE_UNITS=" + std::to_string(bark_texture_units);
    fragment_files.insert(fragment_files.begin(), "bark.glsl");
  }
  if (!shadow && (bark_texture_units > 0 || leaf_images)) fragment_files.insert(fragment_files.begin(), "srgb.glsl");
  // The shadow pass's one-sided leaves need the sun's direction (views.glsl u_light_dir).
  if (shadow && leaf_images) fragment_files.insert(fragment_files.begin(), "views.glsl");
  p.name += "]";
  p.vertex = {ShaderStage::vertex, {"views.glsl", "instances.glsl", "mesh.vert.glsl"}, defines};
  p.fragment = {ShaderStage::fragment, fragment_files, defines};
  return p;
}

std::string glsl_float(double value) {
  // The shortest decimal that reads back as `value` (a double): the text core/light/shading.h
  // writes, so the GLSL compiler rounds the same literal as before to float.
  char buffer[64];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
  if (error != std::errc()) throw std::logic_error("glsl_float: cannot format a constant");
  std::string text(buffer, end);
  if (text.find_first_of(".eE") == std::string::npos) text += ".0";  // 40 → 40.0, a float
  return text;
}

std::vector<std::string> shading_defines() {
  return {"SHADING_SPECULAR " + glsl_float(shading::kSpecular), "SHADING_SHININESS " + glsl_float(shading::kShininess)};
}

ShaderProgramSource present_program(bool srgb) {
  ShaderProgramSource p;
  p.name = srgb ? "present[SRGB]" : "present[]";
  p.vertex = {ShaderStage::vertex, {"fullscreen.vert.glsl"}, {}};
  p.fragment = {ShaderStage::fragment, {"present.frag.glsl"}, srgb ? std::vector<std::string>{"SRGB"}
                                                                  : std::vector<std::string>{}};
  return p;
}

ShaderProgramSource shade_program(bool sun, bool fog) {
  ShaderProgramSource p;
  std::vector<std::string> defines = shading_defines();
  if (sun) defines.push_back("SUN");
  if (fog) defines.push_back("FOG");
  p.name = std::string("shade[") + (sun ? "SUN" : "") + (sun && fog ? " " : "") + (fog ? "FOG" : "") + "]";
  p.vertex = {ShaderStage::vertex, {"fullscreen.vert.glsl"}, {}};
  std::vector<std::string> files = {"srgb.glsl", "bark.glsl", "shading.glsl"};
  if (fog) files.push_back("fog.glsl");
  p.fragment = {ShaderStage::fragment, with(files, "shade.frag.glsl"), defines};
  return p;
}

const char* gl_fog_mode_name(GlFogMode mode) {
  switch (mode) {
    case GlFogMode::brute: return "brute";
    case GlFogMode::medium: return "medium";
    case GlFogMode::fast: return "fast";
    case GlFogMode::map: return "map";
  }
  return "?";
}

ShaderProgramSource fog_program(bool sun, GlFogMode mode) {
  ShaderProgramSource p;
  const char* mode_define = mode == GlFogMode::brute    ? "FOG_BRUTE"
                            : mode == GlFogMode::medium ? "FOG_MEDIUM"
                            : mode == GlFogMode::fast   ? "FOG_FAST"
                                                        : "FOG_MAP";
  std::vector<std::string> defines = {mode_define, "FOG_NEGLIGIBLE_DEPTH " + glsl_float(kFogNegligibleDepth)};
  if (sun) defines.push_back("SUN");
  p.name = std::string("fog[") + mode_define + (sun ? " SUN]" : "]");
  p.vertex = {ShaderStage::vertex, {"fullscreen.vert.glsl"}, {}};
  std::vector<std::string> files = {"fog.glsl"};
  if (mode == GlFogMode::medium || mode == GlFogMode::fast) files.push_back("fog_lists.glsl");
  if (mode == GlFogMode::map) files.push_back("fog_map.glsl");
  p.fragment = {ShaderStage::fragment, with(files, "fog.frag.glsl"), defines};
  return p;
}

ShaderProgramSource fog_cones_program() {
  ShaderProgramSource p;
  p.name = "fog_cones[CAMERA_VIEW]";
  const std::vector<std::string> defines = {"CAMERA_VIEW"};
  const std::vector<std::string> files = {"ray_frustum.glsl", "skin.glsl", "views.glsl", "fog.glsl", "fog_lists.glsl",
                                          "shadow_cones.glsl"};
  p.vertex = {ShaderStage::vertex, with(files, "fog_cones.vert.glsl"), defines};
  p.fragment = {ShaderStage::fragment, with(files, "fog_cones.frag.glsl"), defines};
  return p;
}

std::vector<ShaderProgramSource> all_shader_programs() {
  std::vector<ShaderProgramSource> all;
  for (FrustaPass pass : {FrustaPass::gbuffer, FrustaPass::gbuffer_eye_inside, FrustaPass::shadow})
    for (bool uv : {false, true})
      for (bool relief : {false, true})
        for (bool bark : {false, true}) {
          if (pass == FrustaPass::shadow && (uv || bark)) continue;
          FrustaFeatures features;
          features.want_uv = uv;
          features.relief = relief;
          features.bark = bark;
          features.texture_units = relief && bark ? 2 : 1;  // one image each (albedo, height)
          all.push_back(frusta_program(pass, features));
        }
  // Instanced (plants sharing a skeleton), with the bark and uv where they apply.
  for (FrustaPass pass : {FrustaPass::gbuffer, FrustaPass::gbuffer_eye_inside, FrustaPass::shadow}) {
    FrustaFeatures features;
    features.instanced = true;
    all.push_back(frusta_program(pass, features));
    if (pass == FrustaPass::shadow) continue;
    features.want_uv = features.bark = true;
    features.texture_units = 1;
    all.push_back(frusta_program(pass, features));
  }
  // Relief fading into blended crotches (CROTCH_FADE), each pass.
  for (FrustaPass pass : {FrustaPass::gbuffer, FrustaPass::gbuffer_eye_inside, FrustaPass::shadow}) {
    FrustaFeatures features;
    features.relief = features.crotch_fade = true;
    features.texture_units = 1;
    all.push_back(frusta_program(pass, features));
  }
  // Without the conservative depth layouts (early-Z measurements).
  for (FrustaPass pass : {FrustaPass::gbuffer, FrustaPass::shadow}) {
    FrustaFeatures features;
    features.conservative_depth = false;
    all.push_back(frusta_program(pass, features));
    features.relief = true;
    all.push_back(frusta_program(pass, features));
  }
  for (MeshPass pass : {MeshPass::gbuffer, MeshPass::shadow}) all.push_back(mesh_program(pass));
  all.push_back(mesh_program(MeshPass::gbuffer, 1));  // with the bark albedo
  for (MeshPass pass : {MeshPass::gbuffer, MeshPass::shadow}) all.push_back(mesh_program(pass, 0, true));
  for (MeshPass pass : {MeshPass::gbuffer, MeshPass::shadow}) {
    all.push_back(mesh_program(pass, 0, false, true));  // the instanced polygon baseline
    all.push_back(mesh_program(pass, 0, true, true));   // instanced leaves with images
  }
  for (bool sun : {false, true})
    for (bool fog : {false, true}) all.push_back(shade_program(sun, fog));
  for (bool sun : {false, true})
    for (GlFogMode mode : {GlFogMode::brute, GlFogMode::medium, GlFogMode::fast, GlFogMode::map})
      all.push_back(fog_program(sun, mode));
  all.push_back(fog_cones_program());
  for (bool srgb : {false, true}) all.push_back(present_program(srgb));
  return all;
}

}  // namespace sylva
