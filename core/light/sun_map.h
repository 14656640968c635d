// sun_map.h — a sun-space depth map of the plants (docs/spec/fog.md, mode `map`;
// docs/fog-map.md): on a square grid perpendicular to one sun direction, per texel the
// height toward the sun at which sunlight through the texel's centre first meets a plant,
// and the walk that finds, along any camera ray, the parts lying in front of that height
// (lit) — texel by texel, exactly with respect to the map (Billeter et al. 2010; Chen et
// al. 2011: within a texel the ray's height is linear in t, so it crosses the texel's
// depth at most once).
//
// Frame: world metres, Y up. A map has a centre c (the plants' bounding sphere), the unit
// direction s toward the sun (one direction of its disc) and e0, e1 = axis_frame(s). A
// point p has grid coordinates ((p − c)·e0 + half)/texel, ((p − c)·e1 + half)/texel and
// height h(p) = (p − c)·s. The grid covers [−half, half]² in (e0, e1) with size × size
// texels. Texel (i, j) holds the height of the first plant surface met by the sun ray
// through its centre (−inf where that ray meets none): p is lit in the map iff h(p) >
// the height of p's texel. Outside the grid, and in tiles not allocated, everything is lit.
//
// Storage: tiles of kTile × kTile texels, allocated only where the builder says plants may
// be (the photon pass's shadow vectors, core/cpu/sun_maps.h); a tile's heights are floats
// relative to c (a 100 m stand keeps them to micrometres). Each tile also keeps its largest
// and smallest height, so the walk crosses a tile the ray passes above (all lit) or below
// with no gap (all dark) in one step.
//
// Thread-safe for concurrent lit_parts once filled.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <limits>
#include <vector>

#include "core/light/fog.h"

namespace sylva {

struct SunMapFrame {
  glm::dvec3 centre{0, 0, 0};
  glm::dvec3 to_sun{0, 1, 0};  // s, unit
  glm::dvec3 e0{1, 0, 0}, e1{0, 0, 1};  // axis_frame(s)
  double half_extent_m = 1;    // the grid covers [−half, half]² in (e0, e1), > 0
  uint32_t size = 1;           // texels per side, a multiple of SunDepthMap::kTile
  double texel_m() const { return 2 * half_extent_m / size; }
};

// Counts of one walk (for --verbose and the benchmarks).
struct SunMapWalkStats {
  uint64_t tiles = 0;   // tiles crossed
  uint64_t texels = 0;  // texels tested one by one
};

class SunDepthMap {
 public:
  static constexpr uint32_t kTile = 32;
  static constexpr float kNoPlant = -std::numeric_limits<float>::infinity();

  // A map over `frame` (frame.size a positive multiple of kTile) with the tiles whose
  // flag is set in `allocated` (row-major, (size/kTile)² flags) allocated and every
  // texel kNoPlant until set.
  SunDepthMap(const SunMapFrame& frame, const std::vector<uint8_t>& allocated);

  const SunMapFrame& frame() const { return frame_; }
  uint32_t tiles_per_side() const { return tiles_; }
  size_t allocated_tiles() const { return slot_tile_.size(); }
  // The tile of allocated slot k (row-major index), and its texels to fill (row-major,
  // kTile × kTile heights relative to the frame's centre). Call finish_tile(k) after.
  uint32_t tile_of_slot(size_t k) const { return slot_tile_[k]; }
  float* slot_texels(size_t k) { return &texels_[k * kTile * kTile]; }
  void finish_tile(size_t k);  // records the slot's largest and smallest height

  // The centre of texel (i, j) (0 <= i, j < size) in the world, on the plane h = 0.
  glm::dvec3 texel_centre(uint32_t i, uint32_t j) const;
  // The height stored for the texel holding `point` (kNoPlant outside the grid or tiles).
  float height_at(const glm::dvec3& point) const;
  // Whether `point` is lit in the map: h(point) > height_at(point).
  bool lit(const glm::dvec3& point) const;

  // Appends to *lit, in increasing t, the parts of [t0, t1] (t0 <= t1, finite) where the
  // ray origin + t·direction is lit in the map, merging a part with the last one already
  // there when they touch (so callers can collect several intervals of one ray).
  void lit_parts(const glm::dvec3& origin, const glm::dvec3& direction, double t0, double t1,
                 std::vector<FogInterval>* lit, SunMapWalkStats* stats = nullptr) const;

  size_t memory_bytes() const;

  // The storage as it is, for an upload (core/gl/gl_fog.h): the slot of every tile of the
  // grid (row-major, kNoSlot: not allocated), every slot's texels (kTile² row-major heights
  // relative to the centre, kNoPlant where none) and its smallest and largest height.
  static constexpr uint32_t kNoSlot = 0xFFFFFFFFu;
  const std::vector<uint32_t>& slot_of_tile() const { return slot_of_tile_; }
  const std::vector<float>& texels() const { return texels_; }
  const std::vector<float>& tile_min() const { return tile_min_; }
  const std::vector<float>& tile_max() const { return tile_max_; }

 private:
  SunMapFrame frame_;
  uint32_t tiles_ = 0;
  std::vector<uint32_t> slot_of_tile_;  // kNoSlot: not allocated
  std::vector<uint32_t> slot_tile_;
  std::vector<float> texels_;
  std::vector<float> tile_max_, tile_min_;  // per slot
};

// Appends [t0, t1] to a sorted list of lit pieces, merging with the last when they touch;
// an empty or reversed piece is dropped.
void append_lit(std::vector<FogInterval>* lit, double t0, double t1);

}  // namespace sylva
