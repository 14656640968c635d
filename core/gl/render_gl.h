// render_gl.h — the OpenGL ray caster (Bhagvat et al. 2009 sec. 2.5, 2.6, 4): the analytic frusta
// drawn on the GPU with the shading model of the CPU reference (render_cpu.h), so the two
// give the same picture within the tolerances of tests/gl/render_gl_test.cpp; and the frame
// API a window uses (GlRenderer::draw into a GlTarget, GlFrameStats).
//
// How a frame is made (shaders/*.glsl, mirroring the CPU code function by function; one
// GlRenderer method per pass, GlPass in gl_frame_stats.h):
//   upload (once)  one 64-byte GpuSegment record per frustum (skin.h) and 16 bytes of ids
//                  (plant, chain, segment) in shader storage buffers; nothing per vertex.
//                  Bark images, each distinct file once, with MIP chains; per plant its
//                  texture parameters (bark.glsl's PlantMaps).
//   shadow map     when the sun shines: the same ray-casting shaders, depth only, in an
//                  orthographic view along the sun direction fitted to the plants' bounds.
//   frusta         vertex pulling builds each frustum's 12-triangle bounding pyramid (sec.
//                  2.6); the fragment shader intersects the pixel's ray with the frustum
//                  (intersect_frustum_f's GLSL twin) — or, for a relief-mapped plant,
//                  marches its relief inside the pyramid of the shell (sec. 3,
//                  relief.glsl, also in the shadow map) — discards misses, writes the
//                  real hit depth and a G-buffer (normals, distance, ids, u/v_m, and the
//                  bark texture's albedo looked up over the ray differentials' footprint).
//   mesh           instead of the frusta when GeometryOptions::kind is mesh (gl_mesh.h,
//                  the paper's polygon baseline GS / GS+R): the CPU mesh path's triangles,
//                  uploaded once, rasterised into the same G-buffer and, depth only, into
//                  the shadow map; the shading is the same.
//   shade          one fullscreen pass: ground plane, sky, sun (Lambert + normalised
//                  Blinn-Phong) with the shadow map, sky ambient — render_cpu.cpp's lit() —
//                  added into the renderer's accumulation target.
//   fog            a scene with fog only (docs/spec/fog.md; docs/gl-fog.md): shade[FOG] has
//                  already multiplied the surfaces' sunlight by T_sun and what is seen by
//                  T(0, t_end); one fullscreen pass (fog.frag.glsl) adds the in-scatter —
//                  `brute`: N jittered samples of the unshadowed in-scatter's distribution
//                  along the ray to the G-buffer's depth, each looked up in the shadow map —
//                  and writes the fog AOV (fog.R fog.G fog.B fog.T). `fast` (and
//                  `auto`): first a cone pass draws the shadow cones (set_fog_cones) as
//                  frusta, their intervals into per-pixel lists; the resolve integrates
//                  in closed form outside them (V = 0 inside). `medium`: the same
//                  lists, closed form outside, the N samples of the shadow map spent
//                  inside the intervals. refined, reference: refused (gl_unsupported).
//   present        only when the caller gives a target (gl_target.h): the accumulated
//                  beauty ÷ spp into it, linear or sRGB-encoded.
// --spp N repeats shadow map (if the sun is a disc), frusta and shade N times with the
// CPU's stratified pixel offsets (one offset per pass for all pixels, the rasteriser
// sampling where the rays go) and, for a disc sun, a sun direction drawn on the disc per
// pass: both converge to the CPU's estimate. AOVs come from the pixel centres.
//
// Where it differs from the CPU, by design (and measured by the tests):
//   - float instead of double (the GpuSegment record, float ray casting): depth agrees to
//     ~1e-6 relative; normals to ~1e-6 rad.
//   - shadows from a shadow map: a texel is ~1/2 pixel, receivers are offset along their
//     normal by 2 texels (no acne), so shadow edges can move by that much.
//   - at --spp 1 a disc sun is treated as its centre (hard shadows); the CPU then takes
//     one random point of the disc per pixel (noisy penumbrae). Both converge with --spp.
//   - relief (relief.glsl, the twin of relief.cpp) marches in float: hits agree with the
//     CPU's double march to about the bisection's last bracket; a sample that float
//     rounds to the other side of the height field can move a hit by one uniform step.
//     The relief's filtered normal reads GL's MIP chain (glGenerateMipmap's box filter,
//     trilinear) where the CPU reads OpenImageIO's (its automip, trilinear).
//   - bark albedo (bark.glsl): the same texture coordinates and ray-differential
//     footprint as texture.h, the encoded values filtered then sRGB-decoded, but GL's
//     isotropic trilinear filter where OpenImageIO filters anisotropically (up to 32
//     taps along the footprint's major axis): at grazing angles the GL albedo is blurrier.
//   - a relief plant's shadow lookups start a pixel footprint above the hit (as the
//     CPU's shadow rays do), or two shadow-map texels where that is more.
//   - at most 16 distinct bark images per scene (gl_unsupported says so).
//   - fog: the shadow map stands for the fog's shadow rays (a texel moves a shadow edge by
//     up to its size: docs/gl-fog.md measures the error), in float, and other random
//     numbers than the CPU's; at --spp 1 the disc sun's centre casts the fog's shadows.
//   - meshes are rasterised, not ray traced (gl_mesh.h): coverage rules instead of
//     Embree's watertight test at silhouettes, and attributes interpolated from vertices
//     snapped to the sub-pixel grid (normals ~1e-4, depth ~1e-7 relative); the bark
//     albedo's footprint from the screen derivatives of (u, v_m).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/gl/gl_context.h"
#include "core/gl/gl_frame_stats.h"
#include "core/gl/gl_target.h"
#include "core/light/sun_map.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"
#include "core/light/shadow_cones.h"

namespace sylva {

// Why the GL backend cannot render `scene` with `options` as the CPU would (more bark
// images than it binds), or nullopt when it can.
std::optional<std::string> gl_unsupported(const Scene& scene, const RenderOptions& options);

// Whether the GL fog pass draws fog mode `mode` by walking sun maps (map, and auto, which is
// map on the GL backend: docs/gl-fog.md sec. 2b), so that its caller must bring them
// (options.fog.maps, GlRenderer::set_fog_maps).
bool gl_fog_walks_maps(FogMode mode);

// A scene's plants on the GPU: skinned and uploaded once, drawn any number of times.
//
// Contract:
//   - Threads: an OpenGL 4.5 core context (a GlContext, or a window's) is current on the
//     calling thread for the renderer's whole life, construction to destruction; one thread
//     at a time. Failures throw GlError.
//   - What is done when. The constructor loads the bark images, skins (or, for
//     GeometryKind::mesh, tessellates) every plant and uploads it, and builds the programs
//     the first frame needs. draw() reads only the camera, image size, sun, sky, ground and
//     fog of the scene it is given: a new camera or sun redraws the same buffers (0 plant bytes
//     uploaded), a new image size reallocates the render targets and nothing else, a
//     program variant is built the first time a frame needs it (EYE_INSIDE, a sun that
//     starts shining). Only update_plants sends plant data again.
//   - GL state: draw() sets what its passes need (clip control lower left / zero to one,
//     viewport, depth test, culling, blending, scissor off, sRGB writes off) and leaves the
//     framebuffer, program and vertex array bindings at 0, blending, depth test and culling
//     off; a window's UI sets its own state after it (Dear ImGui's GL3 backend does).
//   - Options (spp, AOVs, geometry, skin) are fixed at construction.
//
// From a window (the studio), on its GL thread:
//   GlRenderer renderer(scene, options);                  // once per scene (new plants: a new one)
//   GlTextureTarget image(w, h, GlTextureTarget::Format::rgba8);
//   per frame:  scene.width = w, scene.height = h; image.resize(w, h);
//               renderer.draw(scene, image.target());     // returns at once
//               ImGui::Image((ImTextureID)(intptr_t)image.texture(), {w, h}, {0, 1}, {1, 0});
//               if (auto timed = renderer.timed_frame()) stats = *timed;  // GPU ms, a frame late
// or renderer.draw(scene, GlTarget{0, w, h, GlTargetEncoding::srgb}) into the back buffer.
class GlProgramCache;  // gl_program.h

class GlRenderer {
 public:
  // Preconditions: every plant's skeleton is set. Throws GlError (gl_unsupported's cases
  // included), std::logic_error for a plant without a skeleton, GlCancelled when
  // options.progress is cancelled while the plants are skinned (checked before each plant
  // and every 1024 chains; the fraction skinned is reported as "skin").
  // `programs`: the context's program cache to share with renderers made before or after
  // this one on the same context (gl_program.h); null: the renderer builds its own.
  GlRenderer(const Scene& scene, const RenderOptions& options, std::shared_ptr<GlProgramCache> programs = nullptr);
  ~GlRenderer();
  GlRenderer(const GlRenderer&) = delete;
  GlRenderer& operator=(const GlRenderer&) = delete;

  // ---- Frames ---------------------------------------------------------------------------
  // Draws one frame of `scene` (its camera, image size, sun, sky, ground and fog; its plants are
  // not read: they are the ones uploaded) into the renderer's own targets, and, given a
  // target, presents it there (gl_target.h; the target's size must be the scene's, else
  // std::invalid_argument). Returns once the work is submitted: no glFinish, no readback,
  // no wait on a query. The stats returned (valid until the next draw) have everything but
  // the GPU times; those follow through timed_frame or wait_for_frame. RenderOptions::cancel
  // is checked between samples (stats.cancelled).
  const GlFrameStats& draw(const Scene& scene);
  const GlFrameStats& draw(const Scene& scene, const GlTarget& target);

  // The last drawn frame: beauty (the shade passes' sum ÷ spp, RGBA with alpha 1) and the
  // AOVs of RenderOptions::aovs (at the pixel centres), top row first, as render_cpu gives
  // them. Waits for the GPU to finish the frame. Throws std::logic_error before any draw.
  RenderImage read_back();

  // The newest frame whose GPU times have arrived since the last call, without waiting
  // (usually the frame before the last, or an older one); nullopt when none has.
  std::optional<GlFrameStats> timed_frame();
  // The last drawn frame's stats with its GPU times, waiting for the GPU to answer (what
  // the CLI and `bench gpu` do after each frame). Throws std::logic_error before any draw.
  const GlFrameStats& wait_for_frame();

  // One frame as the CLI and render_gl() need it: draw(scene), wait_for_frame, read_back;
  // drawn a second time when its fog cone intervals overflowed their lists (then sized by
  // what the first asked for), so that a one-shot render marches no pixel whole.
  // Passes: describe_frame's, then "readback" (the transfer alone) and "frame (wall)".
  RenderResult render(const Scene& scene);

  // ---- Plants and variants ----------------------------------------------------------------
  // Animation (Bhagvat et al. 2009 sec. 4, the dancing cacti): re-skins the plants of `scene` — the
  // same plants as the constructor's, their skeletons moved — and re-uploads only the
  // segment records (the ids too where the number of frusta changed; the polygon baseline
  // its whole mesh). Returns the bytes uploaded (the next frame's plant_bytes_uploaded).
  // Throws std::invalid_argument for a different number of plants, GlCancelled (nothing
  // uploaded, the last plants still drawn) when options.progress is cancelled.
  uint64_t update_plants(const Scene& scene);

  // Whether the frusta programs declare conservative depth (layout(depth_less) /
  // depth_greater, frusta.frag.glsl; default true): false builds the NO_CONSERVATIVE_DEPTH
  // variants from the next frame on, the same pictures, for timing what early depth
  // testing is worth.
  void set_conservative_depth(bool on);

  // The shadow map's side in texels from the next frame on (clamped to [16, the driver's
  // largest texture]); 0 (the default): chosen from the frame's size, at least 1024, as the
  // CLI renders. A smaller map is a cheaper, blockier-shadowed picture: the studio's
  // preview of new plants (app/studio/gl_viewport.cpp) before the full one; the fog tests
  // measure what the map's resolution costs the fog (docs/gl-fog.md).
  void set_shadow_map_texels(uint32_t texels);

  // The shadow cones of this scene's plants and sun (the CPU's: core/cpu/photons.h build_sun_cones),
  // uploaded once for every frame in a cone mode (medium, fast, auto) until the next call
  // (a new sun). Returns the bytes uploaded. Without them the cone modes are refused
  // (GlError).
  uint64_t set_fog_cones(const ConeSet& cones);
  // The sun maps fog mode map walks (core/light/sun_map.h, built by the CPU), uploaded once
  // per (plants, sun); returns the bytes uploaded. Throws GlError for none or too many.
  uint64_t set_fog_maps(std::span<const SunDepthMap> maps);

  uint64_t frusta() const;          // frusta uploaded
  uint64_t uploaded_bytes() const;  // bytes in the segment and id buffers (or the mesh's)
  // What was done once: "textures", "skin", "upload", "programs" (compile and link); the
  // mesh's own for GeometryKind::mesh.
  const std::vector<RenderPass>& setup_passes() const;

 private:
  struct State;  // what was uploaded, the programs, targets and timers (render_gl.cpp)
  struct Frame;  // one frame's views, programs and stats while it is recorded

  // The passes of draw(), in order; each is timed as its GlPass.
  void begin_frame(const Scene& scene, Frame& f);                // targets, views, programs, uniforms
  void shadow_pass(Frame& f, const glm::dvec3& sun_direction);   // GlPass::shadow
  void geometry_pass(Frame& f, double jitter_x, double jitter_y);  // GlPass::geometry
  void shade_pass(Frame& f, const glm::dvec3& sun_direction);    // GlPass::shade
  void fog_cones_pass(Frame& f);                                 // GlPass::fog_cones
  void fog_pass(Frame& f, uint32_t sample, bool aov_only);       // GlPass::fog
  void present_pass(Frame& f, const GlTarget& target);           // GlPass::present
  void end_frame(Frame& f);                                      // submit, stats
  const GlFrameStats& draw_frame(const Scene& scene, const GlTarget* target);
  void take_timed_frames(bool wait);

  std::unique_ptr<State> state_;
};

// The shadow cones of a scene's plants and sun for its fog in cone mode `mode` (medium or
// fast), made for the GL renderer by its caller — the CPU's sun photons and clustering
// (app/front/render.h sun_cone_source) — with what that did appended to `passes`; null
// when cancelled.
using GlConeSource = std::function<std::shared_ptr<const ConeSet>(FogMode mode, std::vector<RenderPass>& passes)>;

// Renders `scene` on the current context: GlRenderer(scene, options), then for a fog in a
// cone mode (medium, fast, auto) the cones of `cones` uploaded (set_fog_cones), then
// render(scene); passes: the setup passes, the cone source's and "cone upload", the
// frame's. The frame's stats (GPU times in) go to *stats when given. Throws GlError
// (gl_unsupported's reason included; a cone mode without a cone source). Cancelled by
// options.progress (or a cone source that returns null): a result with `cancelled` set
// (and no image), as render_cpu's.
RenderResult render_gl(const Scene& scene, const RenderOptions& options, GlFrameStats* stats = nullptr,
                       const GlConeSource& cones = {});

}  // namespace sylva
