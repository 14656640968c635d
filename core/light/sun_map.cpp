// sun_map.cpp — the sun-space depth map and its exact walk (sun_map.h).
#include "core/light/sun_map.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <stdexcept>

namespace sylva {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A ray in the coordinates of a grid of cells: x(t) = ax + t·bx, y(t) = ay + t·by, in cells.
struct GridRay {
  double ax, bx, ay, by;
};

// The part of [t0, t1] where the ray lies inside [0, n]²; false when none.
bool clip_to_grid(const GridRay& r, double n, double* t0, double* t1) {
  const double a[2] = {r.ax, r.ay}, b[2] = {r.bx, r.by};
  for (int k = 0; k < 2; ++k) {
    if (b[k] == 0) {
      if (!(a[k] >= 0 && a[k] <= n)) return false;
      continue;
    }
    double lo = (0 - a[k]) / b[k], hi = (n - a[k]) / b[k];
    if (lo > hi) std::swap(lo, hi);
    *t0 = std::max(*t0, lo), *t1 = std::min(*t1, hi);
  }
  return *t1 > *t0;
}

// Visits the cells of an n × n grid the ray crosses over [t0, t1] (inside the grid: clip
// first), in order: visit(ix, iy, ta, tb) with the cell's part [ta, tb] of the ray
// (Amanatides & Woo 1987; each boundary recomputed from the cell index, so nothing drifts).
// visit returns false to stop early.
template <class Visit>
void walk_cells(const GridRay& r, int n, double t0, double t1, Visit&& visit) {
  // The first cell: where the ray is just after t0 (a point on a boundary belongs to the
  // cell it enters).
  const double start = t0 + std::min(0.5 * (t1 - t0), 1e-12 * (1 + std::abs(t0)) + 1e-9);
  int ix = std::clamp(static_cast<int>(std::floor(r.ax + start * r.bx)), 0, n - 1);
  int iy = std::clamp(static_cast<int>(std::floor(r.ay + start * r.by)), 0, n - 1);
  const int sx = r.bx > 0 ? 1 : r.bx < 0 ? -1 : 0, sy = r.by > 0 ? 1 : r.by < 0 ? -1 : 0;
  double t = t0;
  for (int guard = 0; guard < 4 * n + 8; ++guard) {
    const double nx = sx > 0 ? (ix + 1 - r.ax) / r.bx : sx < 0 ? (ix - r.ax) / r.bx : kInf;
    const double ny = sy > 0 ? (iy + 1 - r.ay) / r.by : sy < 0 ? (iy - r.ay) / r.by : kInf;
    const double next = std::min({nx, ny, t1});
    if (next > t && !visit(ix, iy, t, next)) return;
    if (!(next < t1)) return;
    t = std::max(t, next);
    if (nx <= ny) ix += sx;
    if (ny <= nx) iy += sy;
    if (ix < 0 || iy < 0 || ix >= n || iy >= n) return;
  }
}

}  // namespace

void append_lit(std::vector<FogInterval>* lit, double t0, double t1) {
  if (!(t1 > t0)) return;
  if (!lit->empty() && lit->back().t1 >= t0)
    lit->back().t1 = std::max(lit->back().t1, t1);
  else
    lit->push_back({t0, t1});
}

SunDepthMap::SunDepthMap(const SunMapFrame& frame, const std::vector<uint8_t>& allocated) : frame_(frame) {
  if (frame.size == 0 || frame.size % kTile != 0)
    throw std::invalid_argument("sun map: the size must be a positive multiple of 32 texels");
  if (!(frame.half_extent_m > 0) || !std::isfinite(frame.half_extent_m))
    throw std::invalid_argument("sun map: the extent must be positive and finite");
  tiles_ = frame.size / kTile;
  const size_t count = static_cast<size_t>(tiles_) * tiles_;
  if (allocated.size() != count) throw std::invalid_argument("sun map: one flag per tile");
  slot_of_tile_.assign(count, kNoSlot);
  for (uint32_t t = 0; t < count; ++t)
    if (allocated[t]) {
      slot_of_tile_[t] = static_cast<uint32_t>(slot_tile_.size());
      slot_tile_.push_back(t);
    }
  texels_.assign(slot_tile_.size() * kTile * kTile, kNoPlant);
  tile_max_.assign(slot_tile_.size(), kNoPlant);
  tile_min_.assign(slot_tile_.size(), kNoPlant);
}

void SunDepthMap::finish_tile(size_t k) {
  const float* h = &texels_[k * kTile * kTile];
  float hi = kNoPlant, lo = std::numeric_limits<float>::infinity();
  for (uint32_t i = 0; i < kTile * kTile; ++i) hi = std::max(hi, h[i]), lo = std::min(lo, h[i]);
  tile_max_[k] = hi, tile_min_[k] = lo;
}

glm::dvec3 SunDepthMap::texel_centre(uint32_t i, uint32_t j) const {
  const double texel = frame_.texel_m();
  const double u = -frame_.half_extent_m + (i + 0.5) * texel, v = -frame_.half_extent_m + (j + 0.5) * texel;
  return frame_.centre + u * frame_.e0 + v * frame_.e1;
}

float SunDepthMap::height_at(const glm::dvec3& point) const {
  const glm::dvec3 p = point - frame_.centre;
  const double texel = frame_.texel_m();
  const double x = (glm::dot(p, frame_.e0) + frame_.half_extent_m) / texel;
  const double y = (glm::dot(p, frame_.e1) + frame_.half_extent_m) / texel;
  if (!(x >= 0 && y >= 0 && x < frame_.size && y < frame_.size)) return kNoPlant;
  const uint32_t i = static_cast<uint32_t>(x), j = static_cast<uint32_t>(y);
  const uint32_t slot = slot_of_tile_[(j / kTile) * tiles_ + i / kTile];
  if (slot == kNoSlot) return kNoPlant;
  return texels_[static_cast<size_t>(slot) * kTile * kTile + (j % kTile) * kTile + i % kTile];
}

bool SunDepthMap::lit(const glm::dvec3& point) const {
  return glm::dot(point - frame_.centre, frame_.to_sun) > height_at(point);
}

namespace {

// The lit pieces of one walk, collected as one open run: a piece touching the run extends
// it, so adjacent lit texels cost no vector operation (they are most of them).
class LitRun {
 public:
  explicit LitRun(std::vector<FogInterval>* out) : out_(out) {
    if (!out->empty()) open_ = true, start_ = out->back().t0, end_ = out->back().t1, out->pop_back();
  }
  [[gnu::always_inline]] void add(double a, double b) {
    if (!(b > a)) return;
    if (open_ && a <= end_) {
      end_ = std::max(end_, b);
      return;
    }
    if (open_) out_->push_back({start_, end_});
    open_ = true, start_ = a, end_ = b;
  }
  void finish() {
    if (open_) out_->push_back({start_, end_});
    open_ = false;
  }

 private:
  std::vector<FogInterval>* out_;
  bool open_ = false;
  double start_ = 0, end_ = 0;
};

// The texels of one tile (heights row-major kTile × kTile) the ray crosses over [ta, tb]
// (inside the tile), in tile-local texel coordinates: each one's lit part to `run`.
// Amanatides & Woo's incremental walk (a tile is at most 2·kTile steps, so the boundaries'
// rounding stays far below a texel; the walk is clamped to [ta, tb] and to the tile).
template <bool kClimbs>
uint32_t walk_tile(const float* heights, const GridRay& r, double ta, double tb, double h0, double inv_hd,
                   LitRun& run) {
  constexpr int n = static_cast<int>(SunDepthMap::kTile);
  const double start = ta + std::min(0.5 * (tb - ta), 1e-12 * (1 + std::abs(ta)) + 1e-9);
  int ix = std::clamp(static_cast<int>(std::floor(r.ax + start * r.bx)), 0, n - 1);
  int iy = std::clamp(static_cast<int>(std::floor(r.ay + start * r.by)), 0, n - 1);
  const int sx = r.bx > 0 ? 1 : r.bx < 0 ? -1 : 0, sy = r.by > 0 ? 1 : r.by < 0 ? -1 : 0;
  double tx = sx > 0 ? (ix + 1 - r.ax) / r.bx : sx < 0 ? (ix - r.ax) / r.bx : kInf;
  double ty = sy > 0 ? (iy + 1 - r.ay) / r.by : sy < 0 ? (iy - r.ay) / r.by : kInf;
  const double dx = sx != 0 ? 1 / std::abs(r.bx) : kInf, dy = sy != 0 ? 1 / std::abs(r.by) : kInf;
  double t = ta;
  uint32_t texels = 0;
  for (;;) {
    const double next = std::min({tx, ty, tb});
    ++texels;
    // Lit where h0 + t·hd > w: after the crossing when the ray climbs toward the sun, before
    // it when it descends. A texel without a plant (w = −inf) puts the crossing at ∓inf: lit
    // whole, with no branch of its own.
    const double cross = (static_cast<double>(heights[iy * n + ix]) - h0) * inv_hd;
    if constexpr (kClimbs)
      run.add(std::max(cross, t), next);
    else
      run.add(t, std::min(cross, next));
    t = std::max(t, next);
    if (!(next < tb)) break;
    if (tx < ty) {
      ix += sx, tx += dx;
    } else if (ty < tx) {
      iy += sy, ty += dy;
    } else {  // through a corner
      ix += sx, tx += dx;
      iy += sy, ty += dy;
    }
    if (ix < 0 || iy < 0 || ix >= n || iy >= n) break;
  }
  return texels;
}

}  // namespace

void SunDepthMap::lit_parts(const glm::dvec3& origin, const glm::dvec3& direction, double t0, double t1,
                            std::vector<FogInterval>* lit, SunMapWalkStats* stats) const {
  if (!(t1 > t0)) return;
  const glm::dvec3 o = origin - frame_.centre;
  const double texel = frame_.texel_m();
  // In texels: x(t) = ax + t·bx …; the height h(t) = h0 + t·hd in metres.
  const GridRay texels{(glm::dot(o, frame_.e0) + frame_.half_extent_m) / texel, glm::dot(direction, frame_.e0) / texel,
                       (glm::dot(o, frame_.e1) + frame_.half_extent_m) / texel, glm::dot(direction, frame_.e1) / texel};
  const double h0 = glm::dot(o, frame_.to_sun), hd = glm::dot(direction, frame_.to_sun);
  // A level ray (hd = 0) is taken as climbing by 1e-300: its crossings land beyond ±1e290, so
  // a texel is lit whole or dark whole as h0 > w says (h0 = w, a set of measure zero, lit).
  const bool climbs = hd >= 0;
  const double inv_hd = 1 / (hd != 0 ? hd : 1e-300);
  LitRun run(lit);
  double g0 = t0, g1 = t1;
  if (!clip_to_grid(texels, frame_.size, &g0, &g1)) {
    run.add(t0, t1);
    return run.finish();
  }
  run.add(t0, g0);
  // The same ray in tiles.
  const GridRay tiles{texels.ax / kTile, texels.bx / kTile, texels.ay / kTile, texels.by / kTile};
  uint64_t tiles_crossed = 0, texels_walked = 0;
  walk_cells(tiles, static_cast<int>(tiles_), g0, g1, [&](int tx, int ty, double ta, double tb) {
    ++tiles_crossed;
    const uint32_t slot = slot_of_tile_[static_cast<size_t>(ty) * tiles_ + tx];
    if (slot == kNoSlot) return run.add(ta, tb), true;
    const double ha = h0 + ta * hd, hb = h0 + tb * hd;
    if (std::min(ha, hb) > tile_max_[slot]) return run.add(ta, tb), true;  // above every plant
    if (std::max(ha, hb) <= tile_min_[slot]) return true;                  // below, no gap
    const GridRay local{texels.ax - tx * double(kTile), texels.bx, texels.ay - ty * double(kTile), texels.by};
    const float* heights = &texels_[static_cast<size_t>(slot) * kTile * kTile];
    texels_walked += climbs ? walk_tile<true>(heights, local, ta, tb, h0, inv_hd, run)
                            : walk_tile<false>(heights, local, ta, tb, h0, inv_hd, run);
    return true;
  });
  run.add(g1, t1);
  run.finish();
  if (stats) stats->tiles += tiles_crossed, stats->texels += texels_walked;
}

size_t SunDepthMap::memory_bytes() const {
  return texels_.size() * sizeof(float) + slot_of_tile_.size() * sizeof(uint32_t) +
         slot_tile_.size() * (sizeof(uint32_t) + 2 * sizeof(float));
}

}  // namespace sylva
