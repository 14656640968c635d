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
// colour replaces material 0 (wood); bark.albedo given as a texture covers every segment
// of its plant whatever its material (texture.h: mipmapped lookup, sRGB decoded after
// filtering), filtered over the footprint of the ray differentials through the
// neighbouring pixel positions, one pixel step / sqrt(spp) away (texture.h uv_footprint).
// Normals: the C0-interpolated normal of eq. 8; on a relief-mapped plant (bark.height,
// GeometryOptions::relief) the relief surface of relief.h with its perturbed normal,
// filtered over the pixel's footprint (ReliefOptions::pixel_spread_rad, set here from the
// camera: 2·tan(fov_y/2)/height/sqrt(spp)). A relief hit's shadow ray starts one pixel
// footprint (t·|∂direction/∂y|) above it along its geometric normal, instead of the usual
// 1e-7·scale: relief roughness below a pixel is shaded through the filtered normal and
// must not also shadow itself from the finest-level geometry (which aliases to speckles).
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

#include "core/materials.h"  // kMaterialAlbedo: default albedo by material index
#include "core/relief.h"
#include "core/scene.h"
#include "core/skin.h"
#include "core/surface.h"
#include "core/tessellate.h"

namespace sylva {

class SceneTextures;  // texture.h

// Which AOVs to compute (bit flags).
enum AovFlags : uint32_t {
  kAovDepth = 1u << 0,   // channel Z
  kAovNormal = 1u << 1,  // N.X N.Y N.Z
  kAovUv = 1u << 2,      // U V
  kAovId = 1u << 3,      // id.plant id.chain id.segment
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
                        // frustum and casting no shadow into it; culling.h)
  bool displace = true; // mesh: displace each plant's mesh by its height map where it has
                        // one (the paper's GS+R; tessellate.h displace)
  bool relief = true;   // frusta: relief-map every plant whose bark has a height map and a
                        // relief_depth > 0 (relief.h, paper sec. 3); no height map, no marching
  ReliefOptions relief_options;  // how the relief marcher samples
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
  uint64_t geometry_bytes = 0;  // what the traced geometry holds (SceneTracer::memory_bytes)
  uint64_t primary_rays = 0;
  uint64_t shadow_rays = 0;
};

// World-space geometry of a scene: every plant's skeleton transformed (position,
// rotate_y_deg, scale) and skinned, and what the renderer traces: the frusta themselves
// or a mesh made from them (GeometryOptions).
struct SceneGeometry {
  std::vector<Frustum> frusta;
  std::vector<uint32_t> plant_of_frustum;  // plant index of each frustum
  std::shared_ptr<const SceneTextures> own_textures;  // opened here when the caller gave
                                                      // none and the relief needs them
  std::unique_ptr<SceneTracer> tracer;     // over `frusta` (or a mesh made from them)
};

// The skeleton of `plant` placed in the world: p' = position + R_y(rotate_y_deg)·(scale·p),
// radii scaled. Precondition: plant.skeleton is set.
Skeleton place_plant(const ScenePlant& plant);

// Skins and indexes every plant (each plant's skeleton must be set: grow_scene_plants)
// that geometry.cull does not leave out (culling.h; a culled plant has no frusta, its
// index stays valid), then builds the tracer: the frusta, or their GS mesh at
// geometry.mesh_level in Embree (mesh_accel.h), displaced where geometry.displace and the
// plant has a height map (as deep as the relief shell is thick: relief.h's
// max_depth_per_radius thins it on twigs and needles). `textures` supplies the height maps; null: they are opened here
// when a displaced mesh needs them (std::runtime_error naming the file if one cannot be).
// Passes: "culling" (when on), "skin", "tessellate" and "displace" (mesh), "accel build".
SceneGeometry build_scene_geometry(const Scene& scene, const SkinOptions& skin,
                                   const GeometryOptions& geometry = {},
                                   std::vector<RenderPass>* passes = nullptr,
                                   const SceneTextures* textures = nullptr);

// The displacement of plant `plant`'s mesh: d·H(u·u_repeat, v_m·v_per_metre) metres with
// H its height map in [0, 1] (texture.h: bilinear, finest MIP level, periodic; the field
// the relief marcher reads) and d its bark's relief_depth_m; an empty function when the
// plant has no height map or no depth. The function reads `textures`, which must outlive it.
HeightFn height_function_for(const SceneTextures& textures, uint32_t plant);

// One plant's GS mesh as every mesh path builds it (the CPU's MeshTracer here, GL's
// GlMesh): `skinned` tessellated with `tessellation`, then, where `height` is set
// (height_function_for), displaced by it (GS+R) as deep as the relief shell is thick —
// relief.h's min(relief_depth_m, max_depth_per_radius·r) at each end of a vertex's
// frustum, linear between — so that GS+R lifts a twig or needle no more than the relief
// marcher's shell does. Adds the seconds spent to *tessellate_s and *displace_s.
TriangleMesh plant_mesh(const SkinnedSkeleton& skinned, const TessellateOptions& tessellation, const HeightFn& height,
                        double relief_depth_m, double max_depth_per_radius, double* tessellate_s, double* displace_s);

// The primary ray through continuous pixel position (x, y) in [0, width] × [0, height]
// (y downward); pixel (i, j)'s centre is (i + 0.5, j + 0.5). The direction is not unit.
Ray camera_ray(const Scene& scene, double x, double y);

// Renders `scene` (every plant's skeleton set). Deterministic for any thread count.
RenderResult render_cpu(const Scene& scene, const RenderOptions& options);

}  // namespace sylva
