// render_cpu.h — the CPU reference ray caster (Bhagvat et al. 2009 sec. 2, docs/spec/scene.md): one ray per sample
// through a pinhole camera, conical frusta (skin.h) found through Embree (frustum_accel.h) and
// intersected exactly (ray_frustum.h), shaded under the scene's sun and sky over a
// ground plane. The GPU ray caster must match it.
//
// Shading: the model of core/light/shading.h (sky ambient, Lambert + normalised Blinn-Phong under the
// sun, the ground, the sky seen by a miss), in double, with E_sun = scene.sun.radiance (the
// sun's irradiance at normal incidence) and L_sky = scene.sky. The sun's visibility V: one
// shadow ray per sample, cast where sun_cosine > 0, toward the sun's centre when its angular
// radius is 0 (hard shadows), else toward a uniform point of the sun's disc (soft shadows
// that converge with --spp); only plants cast shadows. The ground (y = ground.height) is
// shaded the same way, with the plants' shadows.
// Fog (a scene's `fog` key; docs/spec/fog.md, docs/fog.md): the sunlight E_sun is
// multiplied by T_sun(p), the fog's transmittance from p toward the sun (the sky ambient
// is not attenuated), and each sample's pixel value becomes T(0, t_end)·L_end + the fog's
// in-scatter along the sample's ray (core/scene/fog_integrator.h, mode and steps from the scene
// or RenderOptions::fog), L_end the shaded surface or L_sky for a ray that hits nothing
// (with T(0, ∞), which is 0 wherever the ray never leaves the fog). Without a `fog` key
// none of it runs.
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
// miss). For a knuckle frustum id.segment is the joint's index; a leaf writes (plant, kAovLeafChain = −2, its
// index in the plant's leaves), docs/leaves.md. fog (kAovFog, a scene with
// fog only): the fog's in-scatter RGB and T(0, t_end) through the pixel's centre, so that
// beauty = fog.T·L_end + fog.RGB at spp 1 (at spp > 1 the centre ray is integrated again,
// with its own random stream).
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
#include <span>
#include <vector>

#include "core/cpu/instance_tracer.h"  // TracedInstance
#include "core/scene/materials.h"  // kMaterialAlbedo: default albedo by material index
#include "core/geometry/relief.h"
#include "core/scene/render_common.h"  // camera_ray: the camera convention both renderers follow
#include "core/scene/render_types.h"
#include "core/scene/scene.h"
#include "core/geometry/skin.h"
#include "core/geometry/surface.h"
#include "core/geometry/tessellate.h"

namespace sylva {

class SceneTextures;  // texture.h
class LeafTracer;     // leaf_tracer.h
class CrotchBalls;    // crotch_tracer.h
class LeafImages;     // leaf_images.h

// World-space geometry of a scene: every plant's skeleton transformed (position,
// rotate_y_deg, scale) and skinned, and what the renderer traces: the frusta themselves
// or a mesh made from them (GeometryOptions).
struct SceneGeometry {
  std::vector<Frustum> frusta;
  std::vector<uint32_t> plant_of_frustum;  // plant index of each frustum
  std::shared_ptr<const SceneTextures> own_textures;  // opened here when the caller gave
                                                      // none and the relief needs them
  std::unique_ptr<SceneTracer> tracer;     // over `frusta` (or a mesh made from them) and the leaves
  const LeafTracer* leaves = nullptr;      // `tracer` when the scene has leaves (leaf_tracer.h), else null
  // The blended crotches (crotch_tracer.h) of the plants whose skin blends them, over
  // `frusta` (null: none): traced by `tracer` when it is the frusta's (a mesh has the
  // fillets' triangles), and by the sun photons either way.
  std::shared_ptr<const CrotchBalls> crotches;
  // The scene's leaf materials (leaf_images.h: images, cut-outs, one-sidedness) every leaf
  // tracer of `tracer` applies; null when the table has none.
  std::shared_ptr<const LeafImages> leaf_images;
  bool cancelled = false;                  // stopped by `progress` between plants: no tracer
  // build_instanced_geometry only: the plants traced as instances of a shared skeleton are
  // not in `frusta` (their prototypes' frusta live in `tracer`); their frusta counted once
  // per plant, the plants, and the distinct skeletons skinned for them.
  uint64_t instance_frusta = 0;
  uint32_t instanced_plants = 0;
  uint32_t instanced_skeletons = 0;
  // build_instanced_geometry only, for the sun photons (photons.h): each shared skeleton's
  // frusta in its own frame and its leaves (null: none), both owned by `tracer`; the
  // instances traced through them (TracedInstance::prototype indexes `prototypes`, plant the
  // scene's plant); and the leaves of the plants skinned in the world (`leaves` is null
  // then: they are inside `tracer`). Empty when nothing is instanced.
  struct Prototype {
    std::span<const Frustum> frusta;
    const LeafTracer* leaves = nullptr;
    const CrotchBalls* crotches = nullptr;  // its blended crotches (null: none)
  };
  std::vector<Prototype> prototypes;
  std::vector<TracedInstance> instances;
  const LeafTracer* world_leaves = nullptr;
};

// Skins and indexes every plant (each plant's skeleton must be set: grow_scene_plants)
// that geometry.cull does not leave out (culling.h; a culled plant has no frusta, its
// index stays valid), then builds the tracer: the frusta, or their GS mesh at
// geometry.mesh_level in Embree (mesh_accel.h), displaced where geometry.displace and the
// plant has a height map (as deep as the relief shell is thick: relief.h's
// max_depth_per_radius thins it on twigs and needles). `textures` supplies the height maps; null: they are opened here
// when a displaced mesh needs them (std::runtime_error naming the file if one cannot be).
// Passes: "culling" (when on), "skin", "tessellate" and "displace" (mesh), "accel build".
// `progress` ("geometry") is told the fraction of plants done and checked between plants.
SceneGeometry build_scene_geometry(const Scene& scene, const SkinOptions& skin,
                                   const GeometryOptions& geometry = {},
                                   std::vector<RenderPass>* passes = nullptr,
                                   const SceneTextures* textures = nullptr, const Progress& progress = {});

// build_scene_geometry, but the plants that share a skeleton with another (plant_instances,
// instances.h) are skinned once per skeleton, in its own frame, and traced as instances
// through their transforms (instance_tracer.h) — unless a plant's geometry depends on where
// it stands: a relief or displacement (its depth is in world metres) or, with
// skin.twist_rad_per_m, a scale other than 1 (the twist turns per world metre). Those, and
// plants whose skeleton no other plant shares, are skinned in the world as
// build_scene_geometry does and are the only ones in `frusta` (the sun photons trace the
// rest through `prototypes` and `instances`: photons.h). Passes: those of
// build_scene_geometry for the plants skinned in the world (when there are any), then
// "instances" (culling and skinning of the prototypes) and "instance accel build".
SceneGeometry build_instanced_geometry(const Scene& scene, const SkinOptions& skin,
                                       const GeometryOptions& geometry = {},
                                       std::vector<RenderPass>* passes = nullptr,
                                       const SceneTextures* textures = nullptr, const Progress& progress = {});

// The fog mode the CPU runs for `mode`: auto is map (docs/spec/fog.md: the fastest mode that
// reaches refined's accuracy, measured by `sylva bench fog` on the bundled canopy scenes;
// docs/fog-map.md and docs/benchmarks.md "Fog mode map"), every other mode itself.
FogMode cpu_fog_mode(FogMode mode);

// Renders `scene` (every plant's skeleton set). Deterministic for any thread count.
// options.progress: "geometry" (the first 5%), then "render", the fraction of tiles done,
// reported from the worker threads; checked before every tile. Cancelled: the result has
// `cancelled` set and an incomplete image. Never prints.
RenderResult render_cpu(const Scene& scene, const RenderOptions& options);

}  // namespace sylva
