// render_types.h — what every renderer takes and gives (the CPU reference, core/cpu/
// render_cpu.h, and the GL backend, core/gl/render_gl.h): the options of a render, its
// images and the passes it ran. No renderer's code is needed to read or write them.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/geometry/relief.h"
#include "core/light/sun_map.h"
#include "core/scene/scene.h"
#include "core/geometry/skin.h"
#include "core/util/progress.h"

namespace sylva {

class FogConeSource;  // core/scene/fog_integrator.h

// Which AOVs to compute (bit flags).
enum AovFlags : uint32_t {
  kAovDepth = 1u << 0,   // channel Z
  kAovNormal = 1u << 1,  // N.X N.Y N.Z
  kAovUv = 1u << 2,      // U V
  kAovId = 1u << 3,      // id.plant id.chain id.segment
  kAovFog = 1u << 4,     // fog.R fog.G fog.B fog.T (docs/spec/fog.md, "Outputs")
};

// The id AOV of a leaf (both renderers): id.plant its plant, id.chain kAovLeafChain (no
// chain is negative; −1 is a miss), id.segment the leaf's index in its plant's
// Skeleton::leaves (the order the grammar closes them).
inline constexpr float kAovLeafChain = -2.0f;

// Which geometry stands for the plants (Bhagvat et al. 2009 sec. 4: the analytic frusta are the reference,
// the tessellated meshes the polygon baseline).
enum class GeometryKind : uint8_t {
  frusta,  // analytic conical frusta (frustum_tracer.h), relief-mapped where asked
  mesh,    // the frusta tessellated at GS level mesh_level (tessellate.h), in Embree
};

struct GeometryOptions {
  GeometryKind kind = GeometryKind::frusta;
  int mesh_level = 2;   // m: 16·4^m triangles per segment
  bool cull = true;     // CPU: leave out plants that can affect no pixel (outside the view
                        // frustum and casting no shadow into it; culling.h). Both: leave out
                        // the crotches' fillets under kFilletMinPixels wide in the view
                        // (crotch.h crotch_seen; GL: seen from the scene's camera when the
                        // renderer is made, so a renderer whose camera moves turns it off)
  bool instance = true; // plants that share a skeleton (instances.h) skinned and uploaded
                        // once, drawn through each plant's transform (docs/scatter.md,
                        // "Instancing"); false: every plant skinned where it stands. The
                        // picture is the same either way, within rounding.
  bool displace = true; // mesh: displace each plant's mesh by its height map where it has
                        // one (the paper's GS+R; tessellate.h displace)
  bool relief = true;   // frusta: relief-map every plant whose bark has a height map and a
                        // relief_depth > 0 (relief.h, paper sec. 3); no height map, no marching
  ReliefOptions relief_options;  // how the relief marcher samples
};

// How a scene's fog is rendered (docs/spec/fog.md); every field overrides the scene's `fog` key
// of the same name, and none matters without one.
struct FogRenderOptions {
  std::optional<FogMode> mode;     // --fog-mode
  std::optional<uint32_t> steps;   // --fog-steps, 1 to kFogMaxSteps
  std::optional<uint64_t> photons; // --photons, 1 to kFogMaxPhotons (for the cones)
  std::optional<std::array<uint32_t, 4>> cone_params;  // --cone-params p1,p2,p3,p4; nullopt: auto
  // Shadow cones already built for this scene's plants and sun (viewpoint independent, so
  // one set serves every camera and frame); null: the renderer has none (fog_integrator.h
  // says what each mode then does).
  const FogConeSource* cones = nullptr;
  // Mode map (docs/fog-map.md): the maps' texels a side and disc directions (--fog-map-resolution,
  // --fog-map-directions), and sun maps already built for these plants and sun (with
  // `cones`; empty: the renderer builds its own).
  std::optional<uint32_t> map_resolution, map_directions;
  std::span<const SunDepthMap> maps;
};

// The samples per pixel of `sylva render` and of the Python module's render() when none
// is asked for: the smallest count at which thin needles and twigs stop breaking up at
// 800x600 on both backends (speckle <= 1 %, `sylva bench spp`; docs/benchmarks.md "Samples
// per pixel" has the measurement and the cost). RenderOptions itself keeps 1 (the pixel
// centres), so a caller of the library always says what it pays for.
inline constexpr uint32_t kDefaultRenderSpp = 8;

struct RenderOptions {
  uint32_t spp = 1;                             // samples per pixel, >= 1
  uint32_t aovs = 0;                            // AovFlags
  unsigned threads = 0;                         // 0: every core
  Progress progress = {};                       // fraction done ("geometry", "render"),
                                                //   cancellation (e.g. by SIGINT) between tiles
  SkinOptions skin;                             // how plants are skinned
  GeometryOptions geometry;                     // what stands for the plants
  FogRenderOptions fog;                         // how the scene's fog is rendered
};

// Float images, row-major from the top-left pixel, channels interleaved.
struct RenderImage {
  uint32_t width = 0, height = 0;
  std::vector<float> beauty;  // RGBA, linear
  std::vector<float> depth;   // Z; empty unless kAovDepth
  std::vector<float> normal;  // N.X N.Y N.Z; empty unless kAovNormal
  std::vector<float> uv;      // U V; empty unless kAovUv
  std::vector<float> id;      // id.plant id.chain id.segment; empty unless kAovId
  std::vector<float> fog;     // fog.R fog.G fog.B fog.T; empty unless kAovFog (and the scene has fog)
};

// One pass of the render and what it cost.
struct RenderPass {
  std::string name;    // "skin", "bvh build", "trace", "shade", ...
  double seconds = 0;  // wall time; for per-thread passes, summed thread time
  std::string detail;  // counts: "412 frusta", "786432 rays"
};

struct RenderResult {
  RenderImage image;
  std::vector<RenderPass> passes;
  bool cancelled = false;     // stopped by options.progress: the image is incomplete
  uint64_t frusta = 0;
  uint64_t geometry_bytes = 0;  // what the traced geometry holds (SceneTracer::memory_bytes)
  uint64_t primary_rays = 0;
  uint64_t shadow_rays = 0;
  std::string cone_report;      // the fog's automatic cone parameters, what they measured
                                // (core/cpu/photons.h AutoConeReport::describe); empty when
                                // none were chosen
};

}  // namespace sylva
