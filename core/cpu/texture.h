// texture.h — the bark textures of a scene (docs/spec/scene.md `bark`: albedo and height maps), and
// the albedo images its `materials` table lays on segments (docs/materials.md, scene.h
// segment_texture), read with OpenImageIO's TextureSystem: MIP-mapped, filtered lookups
// (Bhagvat et al. 2009 sec. 2.3), and the ray-differential footprint that drives the filter.
//
// One TextureSystem per SceneTextures (created unshared, so renders do not share caches or
// state), with "automip" = 1 (plain PNGs are MIP-mapped on the fly), "autotile" = 0 (an
// untiled file is read whole, one tile per MIP level; measured on cactus.png, 2·10^6
// random mipmapped RGB lookups on one thread: 0.57–0.63 µs each with autotile 0,
// 0.71–0.76 µs with 64-texel tiles — tiles only pay for textures larger than memory) and
// "gray_to_rgb" = 1 (a gray albedo gives gray, not red). Every lookup goes through a
// TextureHandle resolved once and a Perthread record owned by this object, one per
// calling thread (created on a thread's first lookup, destroyed with the object: callers'
// threads must have stopped looking up by then). The height maps' finest level is also
// read once into memory for the relief marcher's point lookups (HeightField::height).
//
// Texture coordinates (docs/spec/scene.md's bark keys): s = u·u_repeat with u in turns around the
// axis, t = v_m·v_per_metre with v_m metres of arc length along the chain; image columns
// run along s and rows along t (row 0 at t = 0). Both wrap periodically, so u_repeat
// should be a whole number for a seamless wrap around a stem.
//
// Albedo: the PNG stores sRGB-encoded values; the lookup filters the encoded values (the
// MIP levels are averages of encoded texels) and then decodes the filtered value with the
// sRGB transfer function (IEC 61966-2-1). This is an approximation: decoding after
// averaging darkens a minified high-contrast texture slightly against averaging linear
// values (at most ~0.1 in linear units for a black/white checker; 0 where the texture is
// smooth at the footprint's scale). The exact alternative, a linear-space MIP pyramid
// (maketx --colorconvert), would cost a converted copy of every texture.
//
// Height: channel 0 as one float in [0, 1] (a 16-bit gray PNG is read at full precision),
// 1 = the outermost relief (relief.h). The relief marcher reads it at the finest MIP level
// with bilinear interpolation (texels read once, core/scene/height_maps.h, sampled
// exactly as texture() with MipModeNoMIP + InterpBilinear would, ~10× cheaper per call)
// and no footprint: the relief is one fixed surface, the same
// for primary and shadow rays and for every pixel size (its aliasing is the pixel
// sampler's business, --spp). The relief's shading normal differences H over the larger
// of a texel and the pixel's footprint, MIP-filtered over that footprint
// (HeightField::filtered_height, relief.h).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/geometry/relief.h"
#include "core/scene/scene.h"
#include "core/geometry/surface.h"
#include "core/geometry/tessellate.h"

namespace sylva {

// How u and v_m change from a pixel to the next (x: to the right, y: downward), turns and
// metres per pixel step. Zero: no filtering (the finest MIP level).
struct UvFootprint {
  double du_dx = 0, dv_dx = 0;
  double du_dy = 0, dv_dy = 0;
};

// PBRT's ray differentials (Pharr et al., sec. 10.1): the rays through the neighbouring
// pixel positions `ray_dx` and `ray_dy` (one pixel step, divided by sqrt(spp) when several
// samples share a pixel) meet the tangent plane of `hit` (position, geometric normal) at
// p_x and p_y; Δp = p_x − p ≈ dp_du·Δu + dp_dv·Δv_m is solved for (Δu, Δv_m) by least
// squares (the 2×2 normal equations of hit.dp_du, hit.dp_dv). A ray parallel to the plane,
// a degenerate tangent pair or any non-finite value gives the zero footprint, never NaN.
UvFootprint uv_footprint(const SurfaceHit& hit, const Ray& ray_dx, const Ray& ray_dy);

class SceneTextures {
 public:
  // Opens the bark textures of every plant of `scene` and the images its `materials` table
  // lays on segments (scene.h segment_texture; the same file is opened once). On failure a
  // Diagnostic for the file whose message names it and gives OIIO's reason ("cannot open
  // texture 'bark.png': ...").
  static Expected<std::unique_ptr<SceneTextures>> open(const Scene& scene);
  ~SceneTextures();
  SceneTextures(const SceneTextures&) = delete;
  SceneTextures& operator=(const SceneTextures&) = delete;

  // Whether the segments of `material` on plant `plant` have an albedo texture (scene.h
  // segment_texture: the bark's for material 0, else the table's); whether `plant` has a
  // height texture.
  bool has_albedo(uint32_t plant, uint32_t material) const;
  bool has_height(uint32_t plant) const;
  // Linear albedo of the segments of `material` on `plant` at (u, v_m), filtered over
  // `footprint` (has_albedo(plant, material)), with that texture's repeats.
  glm::dvec3 albedo(uint32_t plant, uint32_t material, double u, double v_m, const UvFootprint& footprint) const;
  // The relief of `plant` (has_height(plant)): its height field (owned by this object),
  // depth and repeats from its bark.
  ReliefMap relief_map(uint32_t plant) const;
  // Distinct files open.
  size_t file_count() const;

 private:
  SceneTextures();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The displacement of plant `plant`'s mesh: d·H(u·u_repeat, v_m·v_per_metre) metres with
// H its height map in [0, 1] (bilinear, finest MIP level, periodic; the field
// the relief marcher reads) and d its bark's relief_depth_m; an empty function when the
// plant has no height map or no depth. The function reads `textures`, which must outlive it.
HeightFn height_function_for(const SceneTextures& textures, uint32_t plant);

}  // namespace sylva
