// gl_frame_stats.h — what one GL frame did and cost (GlRenderer, render_gl.h): the passes
// it ran with their GPU times, what it drew, the bytes it sent and the targets it holds.
// `sylva render --verbose` lists it (describe_frame), `sylva bench gpu` tabulates it, the
// studio shows it; nobody parses text.
//
// GPU times come from GL_TIME_ELAPSED queries, which the GPU answers after the frame ran:
// GlRenderer hands a frame's stats out at once without them (gpu_times_ready false) and
// with them a frame or more later (GlRenderer::timed_frame), or when asked to wait
// (GlRenderer::wait_for_frame).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/scene/render_types.h"

namespace sylva {

// The passes of a frame, in the order they run (render_gl.cpp, one method each). A new
// pass (fog) is one enumerator here, its name in gl_pass_name, and its method.
enum class GlPass : uint8_t {
  shadow,    // the shadow map, in the sun's orthographic view (when the sun shines)
  geometry,  // the G-buffer: the ray-cast frusta, or the rasterised mesh
  shade,     // deferred shading into the accumulated beauty
  fog_cones, // the shadow cones' intervals into per-pixel lists (the fog's cone modes)
  fog,       // the fog's in-scatter into the beauty and the fog AOV (a scene with fog only)
  present,   // the beauty into the caller's target (only when one is given)
};
inline constexpr size_t kGlPassCount = 6;

// "shadow map", "frusta" or "mesh" (the geometry pass, by `geometry`), "shade",
// "fog cones", "fog", "present".
const char* gl_pass_name(GlPass pass, GeometryKind geometry = GeometryKind::frusta);

struct GlPassStats {
  uint32_t runs = 0;    // times the pass ran this frame (spp, the AOV pass at pixel centres, ...)
  double gpu_s = 0;     // GPU time over every run; meaningful when gpu_times_ready
  std::string program;  // the variant it drew with (gl_shaders.h names), e.g. "shade[SUN]"
};

struct GlFrameStats {
  uint64_t frame = 0;  // 1 for a renderer's first frame, then 2, 3, ...
  uint32_t width = 0, height = 0, spp = 1;
  bool cancelled = false;  // RenderOptions::cancel stopped it between samples: the picture is partial
  bool presented = false;  // drawn into a caller's target (the present pass ran)

  // What was drawn.
  GeometryKind geometry = GeometryKind::frusta;
  std::string geometry_label;  // the mesh's "GS 1" / "GS+R 2"; empty for frusta
  uint64_t frusta = 0;         // frusta uploaded (the mesh's: frusta tessellated)
  uint64_t triangles = 0;      // mesh triangles uploaded; 0 for frusta
  uint32_t eye_inside = 0;     // frusta drawn again from inside their pyramid (EYE_INSIDE)
  uint32_t shadow_texels = 0;  // the shadow map's side; 0: no sun, no shadow pass
  std::string fog_mode;        // the fog pass's mode ("brute", "medium", "fast"); empty: no fog
  uint32_t fog_steps = 0;      // its samples along each ray
  uint32_t fog_cones = 0;      // shadow cones drawn by the cone pass (0: none ran)
  uint32_t fog_list_capacity = 0;  // interval list nodes held
  uint64_t fog_map_bytes = 0;  // mode map: the sun maps' bytes on the GPU (0: none bound)
  // The cone pass's counts, read by wait_for_frame (fog_counted) once the GPU is done:
  bool fog_counted = false;
  uint64_t fog_fragments = 0;           // intervals appended over the frame
  uint64_t fog_overflow_fragments = 0;  // of them, those that found the node buffer full
  uint64_t fog_overflow_pixels = 0;     // pixels marched whole instead (their list incomplete)
  uint64_t fog_largest_pass = 0;        // the most nodes one cone pass asked for

  // Time.
  std::array<GlPassStats, kGlPassCount> passes{};  // indexed by GlPass
  bool gpu_times_ready = false;  // passes[].gpu_s have arrived from the GPU
  double cpu_s = 0;              // wall time of the draw call: recording and submitting, not the GPU's work
  double compile_s = 0;          // programs built during this frame (first use of a variant)
  std::string compiled;          // their names, ", "-separated

  // Memory and transfers.
  uint64_t geometry_bytes = 0;        // resident plant geometry: segment records + ids, or the mesh
  uint64_t plant_bytes_uploaded = 0;  // plant data sent since the previous frame: the constructor's
                                      // for frame 1, update_plants's after it, else 0
  uint64_t frame_bytes_uploaded = 0;  // per-frame buffer data: the EYE_INSIDE list (never the
                                      // plants; uniforms are not counted)
  uint64_t target_bytes = 0;          // render targets held: G-buffer, depth, accumulation, shadow map
  uint32_t targets_allocated = 0;     // render targets (re)allocated by this frame: frame 1's,
                                      // a new image size's, a new shadow-map size's

  const GlPassStats& pass(GlPass p) const { return passes[static_cast<size_t>(p)]; }
  GlPassStats& pass(GlPass p) { return passes[static_cast<size_t>(p)]; }
  double gpu_s() const;  // every pass's GPU time
};

// The frame as `sylva render --verbose` lists it, one RenderPass per line: "programs" (when
// some were built), "shadow map (GPU)", "frusta (GPU)" or "mesh (GPU)", "shade (GPU)",
// "fog (GPU)" (a scene with fog), "present (GPU)" (when it ran), with what each drew in the detail. GPU times are 0 until
// gpu_times_ready.
std::vector<RenderPass> describe_frame(const GlFrameStats& stats);

}  // namespace sylva
