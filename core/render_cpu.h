// render_cpu.h — the CPU reference ray caster (issue 3, sec. 2): one ray per sample
// through a pinhole camera, conical frusta (skin.h) found through Embree (frustum_accel.h) and
// intersected exactly (ray_frustum.h), shaded under the scene's sun and sky over a
// ground plane. The GPU ray caster must match it.
//
// Shading (linear RGB), at a point with albedo ρ, unit shading normal n facing the ray,
// sun direction l, view direction v, half vector h = normalize(l + v):
//   L = ρ/π · E_sun · max(n·l, 0) · V                   (Lambert under the sun)
//     + k_s · (s + 8)/(8π) · (n·h)^s · E_sun · max(n·l, 0) · V   (normalised Blinn-Phong)
//     + ρ · L_sky · (1 + n_y)/2                          (sky ambient: the sky's share
//                                                         of the hemisphere around n)
// with E_sun = scene.sun.radiance, L_sky = scene.sky, k_s = 0.04, s = 40, V the sun's
// visibility: one shadow ray per sample toward the sun's centre when its angular radius
// is 0 (hard shadows), else toward a uniform point of the sun's disc (soft shadows that
// converge with --spp). The ground (y = ground.height, normal +Y, no specular) is shaded
// the same way, with the plants' shadows. A ray that hits nothing sees L_sky.
// Plant albedo comes from the material index (kMaterialAlbedo); bark.albedo given as a
// colour replaces material 0 (wood). Normals: the C0-interpolated normal of eq. 8.
//
// Outputs: beauty RGBA (linear; A = 1 everywhere, the sky is part of the picture) and, on
// request, AOVs of the plant surface seen through each pixel's centre: depth (Euclidean
// distance from the eye, +inf where no plant is hit — the ground and the sky are not
// plants), world-space shading normal (0 on a miss), uv (u turns, v_m metres of arc
// length; 0 on a miss), id (plant, chain, segment as floats, exact below 2^24; −1 on a
// miss). For a knuckle frustum id.segment is the joint's index.
//
// Sampling: --spp N takes N stratified samples per pixel (a jittered ceil(sqrt N)-wide
// grid); N = 1 samples the centre exactly. Random numbers depend only on the pixel and
// sample, so images are identical for every thread count.
//
// Threads: 32×32 tiles handed out by an atomic counter to `threads` workers.
#pragma once

#include <atomic>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <memory>
#include <vector>

#include "core/scene.h"
#include "core/skin.h"
#include "core/surface.h"

namespace sylva {

// Which AOVs to compute (bit flags).
enum AovFlags : uint32_t {
  kAovDepth = 1u << 0,   // channel Z
  kAovNormal = 1u << 1,  // N.X N.Y N.Z
  kAovUv = 1u << 2,      // U V
  kAovId = 1u << 3,      // id.plant id.chain id.segment
};

// Default albedo by material index (materials past the table reuse its last entry).
inline constexpr double kMaterialAlbedo[][3] = {
    {0.30, 0.20, 0.12},  // 0 wood, bark
    {0.16, 0.34, 0.10},  // 1 leaves, needles, cactus skin
    {0.22, 0.40, 0.16},  // 2 succulent skin
    {0.85, 0.75, 0.35},  // 3 flowers, fruit
};

// Which geometry stands for the plants (issue 3: the analytic frusta are the reference,
// the tessellated meshes the polygon baseline).
enum class GeometryKind : uint8_t {
  frusta,  // analytic conical frusta (frustum_tracer.h), relief-mapped where asked
  mesh,    // the frusta tessellated at GS level mesh_level (tessellate.h), in Embree
};

struct GeometryOptions {
  GeometryKind kind = GeometryKind::frusta;
  int mesh_level = 2;   // m: 16·4^m triangles per segment
  bool cull = true;     // leave out plants that can affect no pixel (outside the view
                        // frustum and casting no shadow into it)
};

struct RenderOptions {
  uint32_t spp = 1;                             // samples per pixel, >= 1
  uint32_t aovs = 0;                            // AovFlags
  unsigned threads = 0;                         // 0: every core
  const std::atomic<bool>* cancel = nullptr;    // set (e.g. by SIGINT) to stop early
  bool progress = false;                        // progress bar on stderr after 1 s
  SkinOptions skin;                             // how plants are skinned
  GeometryOptions geometry;                     // what stands for the plants
};

// Float images, row-major from the top-left pixel, channels interleaved.
struct RenderImage {
  uint32_t width = 0, height = 0;
  std::vector<float> beauty;  // RGBA, linear
  std::vector<float> depth;   // Z; empty unless kAovDepth
  std::vector<float> normal;  // N.X N.Y N.Z; empty unless kAovNormal
  std::vector<float> uv;      // U V; empty unless kAovUv
  std::vector<float> id;      // id.plant id.chain id.segment; empty unless kAovId
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
  bool cancelled = false;     // stopped by options.cancel: the image is incomplete
  uint64_t frusta = 0;
  uint64_t primary_rays = 0;
  uint64_t shadow_rays = 0;
};

// World-space geometry of a scene: every plant's skeleton transformed (position,
// rotate_y_deg, scale) and skinned, and what the renderer traces: the frusta themselves
// or a mesh made from them (GeometryOptions).
struct SceneGeometry {
  std::vector<Frustum> frusta;
  std::vector<uint32_t> plant_of_frustum;  // plant index of each frustum
  std::unique_ptr<SceneTracer> tracer;     // over `frusta` (or a mesh made from them)
};

// The skeleton of `plant` placed in the world: p' = position + R_y(rotate_y_deg)·(scale·p),
// radii scaled. Precondition: plant.skeleton is set.
Skeleton place_plant(const ScenePlant& plant);

// Skins and indexes every plant (each plant's skeleton must be set: grow_scene_plants).
SceneGeometry build_scene_geometry(const Scene& scene, const SkinOptions& skin,
                                   const GeometryOptions& geometry = {},
                                   std::vector<RenderPass>* passes = nullptr);

// The primary ray through continuous pixel position (x, y) in [0, width] × [0, height]
// (y downward); pixel (i, j)'s centre is (i + 0.5, j + 0.5). The direction is not unit.
Ray camera_ray(const Scene& scene, double x, double y);

// Renders `scene` (every plant's skeleton set). Deterministic for any thread count.
RenderResult render_cpu(const Scene& scene, const RenderOptions& options);

}  // namespace sylva
