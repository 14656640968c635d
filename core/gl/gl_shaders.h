// gl_shaders.h — the GLSL sources of the GL backend (shaders/*.glsl, embedded into the
// library at build time by shaders/embed_shaders.cmake) and how one shader stage of one
// variant is assembled from them.
//
// A stage is `#version 450 core`, then one `#define` per variant switch, then the files of
// the stage in order, each preceded by `#line 1 N` with N its index in the file list: a
// driver or glslangValidator message "N:LINE" names file N, line LINE (format_shader_log
// puts the file names back). shaders/bindings.glsl (binding points, texture units, the
// std140 blocks and shared constants: core/gl/bindings.h) opens every stage, at the head
// of file 0's slot under number F (the number of files), so that every file may use it. The same text goes to the driver and to glslangValidator
// (tests/gl/gl_shaders_test.cpp), so what CI validates is what runs.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace sylva {

struct EmbeddedShader {
  const char* name;    // file name in shaders/, e.g. "ray_frustum.glsl"
  const char* source;  // its text
};
extern const EmbeddedShader kEmbeddedShaders[];
extern const size_t kEmbeddedShaderCount;

// The file every stage begins with (bindings.h is its C++ side).
inline constexpr const char* kBindingsFile = "bindings.glsl";

// The text of shaders/NAME; throws std::logic_error if there is no such file.
std::string_view embedded_shader(std::string_view name);

enum class ShaderStage { vertex, fragment };

// One stage of one program variant.
struct ShaderStageSource {
  ShaderStage stage = ShaderStage::vertex;
  std::vector<std::string> files;    // shaders/ files, concatenated in this order
  std::vector<std::string> defines;  // "NAME" or "NAME VALUE", one #define each
};

// The complete source handed to glShaderSource / glslangValidator.
std::string assemble_shader(const ShaderStageSource& stage);

// `log` (a driver or glslangValidator info log for `stage`) with "N:" source-string
// numbers replaced by the file names they stand for (N = files.size(): bindings.glsl).
std::string format_shader_log(const ShaderStageSource& stage, const std::string& log);

// A program variant: a name for --verbose and messages, and its two stages.
struct ShaderProgramSource {
  std::string name;  // e.g. "frusta[GBUFFER_PASS]"
  ShaderStageSource vertex;
  ShaderStageSource fragment;
};

// The variant switches of the frusta program (frusta.vert.glsl + frusta.frag.glsl).
enum class FrustaPass {
  gbuffer,             // camera view, front faces, conservative depth (depth_less)
  gbuffer_eye_inside,  // camera view, back faces, for pyramids that contain the eye
  shadow,              // orthographic sun view, depth only (depth_greater)
};
// What a scene asks of the frusta program beyond its pass: each switch is a #define, so a
// scene without height maps compiles no relief code and one without albedo textures no
// texture lookups.
struct FrustaFeatures {
  bool want_uv = false;            // WANT_UV: u and v_m into the G-buffer (the UV AOV)
  bool relief = false;             // RELIEF: relief marching for plants with a relief
                                   // (relief.glsl), in the pyramid of the shell
  bool crotch_fade = false;        // CROTCH_FADE (with relief): a blended crotch's relief
                                   // fades into its fillet (crotch.glsl, gl_crotch_fade.h)
  bool bark = false;               // BARK: albedo textures looked up into g_albedo (bark.glsl)
  int texture_units = 0;           // BARK_TEXTURE_UNITS: distinct bark images bound (albedo
                                   // and height maps); at least 1 with relief or bark
  bool conservative_depth = true;  // false: NO_CONSERVATIVE_DEPTH, no depth layout (early-Z
                                   // measurements)
  bool instanced = false;          // INSTANCED: plants drawn through their transforms
                                   // (frusta_common.glsl GpuInstance), every pass
};
// The variant of `pass` with `features`; the shadow pass takes only relief and
// conservative_depth (it writes depth alone). Its name lists the defines, e.g.
// "frusta[GBUFFER_PASS WANT_UV RELIEF BARK TEXTURE_UNITS=2]".
ShaderProgramSource frusta_program(FrustaPass pass, const FrustaFeatures& features);
// frusta_program(pass, {.want_uv = want_uv}).
ShaderProgramSource frusta_program(FrustaPass pass, bool want_uv);

// The variant switches of the mesh program (mesh.vert.glsl + mesh.frag.glsl: the polygon
// baseline rasterised into the frusta's G-buffer, core/gl_mesh.h).
enum class MeshPass {
  gbuffer,  // camera view, reversed Z, both faces
  shadow,   // orthographic sun view, depth only
};
// `bark_texture_units` > 0 (gbuffer only): the scene's distinct bark images; the fragment
// stage then writes the bark albedo through bark.glsl (BARK_TEXTURE_UNITS). `leaf_images`
// (the leaves, both passes): the table's leaf images, cut-outs and one-sidedness
// (leaf_images.h) from LEAF_IMAGES_UNIT's 2D array (LEAF_IMAGES). `instanced`: plants that
// share a skeleton drawn through instances.glsl's transforms, one draw per skeleton (INSTANCED).
ShaderProgramSource mesh_program(MeshPass pass, int bark_texture_units = 0, bool leaf_images = false,
                                 bool instanced = false);

// `value` as a GLSL float literal that reads back as it: the shortest decimal of the
// double, with ".0" added where it has no point or exponent (40 → "40.0", 0.04 → "0.04").
std::string glsl_float(double value);

// The #defines shading.glsl needs: core/light/shading.h's constants, SHADING_SPECULAR (k_s) and
// SHADING_SHININESS (s), as glsl_float literals — how the GLSL twins get them from C++.
std::vector<std::string> shading_defines();

// The deferred shading program (fullscreen.vert.glsl + bark.glsl's per-plant maps +
// shading.glsl's model + shade.frag.glsl), with shading_defines(); `sun` false leaves out
// the sun and its shadow map (black or absent sun: sky only); `fog` (a scene with fog)
// adds fog.glsl and FOG: sunlight × T_sun, what is seen × T(0, t_end) (docs/spec/fog.md).
ShaderProgramSource shade_program(bool sun, bool fog = false);

// The fog pass's modes on the GPU (docs/spec/fog.md, docs/gl-fog.md).
enum class GlFogMode {
  brute,   // FOG_BRUTE: the shadow map marched along the whole ray
  medium,  // FOG_MEDIUM: closed form outside the cone intervals, the map marched inside
  fast,    // FOG_FAST: closed form outside the cone intervals, V = 0 inside
  map,     // FOG_MAP: the sun maps walked texel by texel (fog_map.glsl), closed form over the lit parts
};
const char* gl_fog_mode_name(GlFogMode mode);  // "brute", "medium", "fast", "map" (docs/spec/fog.md's)

// The fog pass (fullscreen.vert.glsl + fog.glsl [+ fog_lists.glsl] + fog.frag.glsl): the
// light the fog scatters toward the eye, added into the accumulated beauty, and the fog
// AOV; the cone modes read the per-pixel interval lists the cone pass wrote. `sun` false:
// the sky's share and T alone. FOG_NEGLIGIBLE_DEPTH is fog_integrator.h's
// kFogNegligibleDepth.
ShaderProgramSource fog_program(bool sun, GlFogMode mode = GlFogMode::brute);

// The cone pass (ray_frustum.glsl + skin.glsl + views.glsl[CAMERA_VIEW] + fog.glsl +
// fog_lists.glsl + shadow_cones.glsl + fog_cones.vert/frag.glsl): each shadow cone's
// bounding pyramid rasterised in the camera's view, its interval along each pixel's ray
// appended to that pixel's list.
ShaderProgramSource fog_cones_program();

// The present program (fullscreen.vert.glsl + present.frag.glsl): the accumulated beauty
// divided by the sample count into the caller's target (render_gl.h), as linear values or,
// `srgb`, encoded for display (IEC 61966-2-1, core/util/color.h's linear_to_srgb).
ShaderProgramSource present_program(bool srgb);

// Every variant the renderer can build (what the shader tests compile).
std::vector<ShaderProgramSource> all_shader_programs();

}  // namespace sylva
