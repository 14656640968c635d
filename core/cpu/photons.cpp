// photons.cpp — sun photons, shadow vectors (Hougs and Day 2001 sec. 3.1, Fig. 2b), the automatic
// choice of the cone parameters (sec. 6.1, the paper's future work) and the cones built
// once per (plants, sun). See photons.h for the contract.
#include "core/cpu/photons.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <glm/geometric.hpp>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <sys/mman.h>
#include <time.h>

#include "core/cpu/bvh.h"  // frustum_bounds
#include "core/cpu/crotch_tracer.h"
#include "core/cpu/frustum_accel.h"
#include "core/cpu/instance_tracer.h"
#include "core/cpu/leaf_tracer.h"
#include "core/cpu/render_cpu.h"
#include "core/scene/render_common.h"
#include "core/geometry/relief.h"
#include "core/util/math.h"
#include "core/util/parallel.h"
#include "core/util/random.h"
#include "core/util/clock.h"

namespace sylva {
namespace {


constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint64_t kChunk = 1u << 15;  // photons per work item (cancellation granularity)


// sin and cos of x for |x| <= π/4, by their Taylor series to x¹⁵ and x¹⁶: the first terms
// left out are below 6e-17·|x| and 2e-18 there, so both are within an ulp or two of libm's and
// several times cheaper (the photons' positions called sincos for every photon).
glm::dvec2 cos_sin_quarter(double x) {
  const double x2 = x * x;
  const double s =
      x * (1 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 + x2 * (-1.0 / 5040 + x2 * (1.0 / 362880 + x2 * (-1.0 / 39916800 +
          x2 * (1.0 / 6227020800 + x2 * (-1.0 / 1307674368000))))))));
  const double c =
      1 + x2 * (-1.0 / 2 + x2 * (1.0 / 24 + x2 * (-1.0 / 720 + x2 * (1.0 / 40320 + x2 * (-1.0 / 3628800 +
          x2 * (1.0 / 479001600 + x2 * (-1.0 / 87178291200 + x2 * (1.0 / 20922789888000))))))));
  return {c, s};
}

// Shirley & Chiu's concentric map of [0,1)² onto the unit disc (area-preserving). Its
// angle is within π/4 of an axis: (r cos φ, r sin φ) with φ = π/4 · b/a, or with
// φ = π/2 − π/4 · a/b its cosine and sine swapped.
glm::dvec2 concentric_disc(double u, double v) {
  const double a = 2 * u - 1, b = 2 * v - 1;
  if (a == 0 && b == 0) return {0, 0};
  if (std::abs(a) > std::abs(b)) return a * cos_sin_quarter((kPi / 4) * (b / a));
  const glm::dvec2 cs = cos_sin_quarter((kPi / 4) * (a / b));
  return b * glm::dvec2(cs.y, cs.x);
}

// The photon's direction, away from the sun: uniform over the disc of angular radius α
// around `to_sun` (one_minus_cos_alpha = 2·sin²(α/2)). With (x, y) uniform in the unit
// disc (by rejection: no trigonometry) and h = (x² + y²)·(1 − cos α) = 1 − cos θ, which is
// then uniform in [0, 1 − cos α] (uniform in solid angle), the direction is
// (1 − h)·s + sin θ·(x, y)/ρ with sin θ/ρ = sqrt((1 − cos α)·(2 − h)).
glm::dvec3 photon_direction(const glm::dvec3& to_sun, const AxisFrame& f, double one_minus_cos_alpha, Rng& rng) {
  if (one_minus_cos_alpha == 0) return -to_sun;
  double x, y;
  do {
    x = 2 * rng.next_double() - 1;
    y = 2 * rng.next_double() - 1;
  } while (x * x + y * y > 1);
  const double h = (x * x + y * y) * one_minus_cos_alpha;
  const double lateral = std::sqrt(one_minus_cos_alpha * (2 - h));
  return -((1 - h) * to_sun + lateral * (x * f.e0 + y * f.e1));
}

// A prototype's frustum placed by `x` (instances.h): the same solid in the world. A plane
// n·p = d of the prototype's frame is (R·n)·q = s·d + (R·n)·position in the world.
FrustumShape placed_shape(const FrustumShape& local, const PlantTransform& x) {
  FrustumShape w = local;
  w.base = x.to_world(local.base);
  w.axis = x.rotate(local.axis);
  w.length = local.length * x.scale;
  w.radius0 = local.radius0 * x.scale;
  w.radius1 = local.radius1 * x.scale;
  for (Plane* plane : {&w.lower, &w.upper}) {
    const double offset = plane->offset;
    plane->normal = x.rotate(plane->normal);
    plane->offset = x.scale * offset + glm::dot(plane->normal, x.position);
  }
  return w;
}

// The instanced plants of a SceneGeometry (render_cpu.h), for the mask and the emitter.
struct PlacedPlants {
  std::span<const SceneGeometry::Prototype> prototypes;
  std::span<const TracedInstance> instances;

  // f(shape) for every instance's frustum placed in the world, g(a, b, c) for every
  // instance's leaf triangle, b(centre, radius) for every instance's crotch ball.
  template <class F, class G, class B>
  void for_each(F&& f, G&& g, B&& b) const {
    for (const TracedInstance& inst : instances) {
      const SceneGeometry::Prototype& proto = prototypes[inst.prototype];
      for (const Frustum& frustum : proto.frusta) f(placed_shape(frustum.shape, inst.transform));
      for (uint32_t i = 0; proto.crotches && i < proto.crotches->count(); ++i)
        b(inst.transform.to_world(proto.crotches->crotch(i).centre),
          proto.crotches->crotch(i).radius * inst.transform.scale);
      if (!proto.leaves) continue;
      const LeafMesh& leaves = proto.leaves->leaves();
      for (size_t t = 0; t < leaves.triangle_count(); ++t)
        g(inst.transform.to_world(leaves.positions[leaves.indices[3 * t]]),
          inst.transform.to_world(leaves.positions[leaves.indices[3 * t + 1]]),
          inst.transform.to_world(leaves.positions[leaves.indices[3 * t + 2]]));
    }
  }
};

// Zeroed words, each tile of 16 on one cache line; a buffer of 2 MiB or more aligned to
// 2 MiB and offered huge pages (where the kernel grants them), since the mask below is
// read at random and with 4 KiB pages nearly every photon missed the TLB.
class MaskWords {
 public:
  void assign(size_t n) {
    constexpr size_t kLine = 64, kHugePage = size_t(2) << 20;
    const size_t align = n * sizeof(uint32_t) >= kHugePage ? kHugePage : kLine;
    const size_t bytes = std::max<size_t>(1, (n * sizeof(uint32_t) + align - 1) / align) * align;
    words_.reset(static_cast<uint32_t*>(std::aligned_alloc(align, bytes)));
    if (!words_) throw std::bad_alloc();
    if (align == kHugePage) madvise(words_.get(), bytes, MADV_HUGEPAGE);  // a hint: failure is harmless
    std::memset(words_.get(), 0, bytes);
    size_ = n;
  }
  bool empty() const { return size_ == 0; }
  size_t size() const { return size_; }
  uint32_t& operator[](size_t i) { return words_[i]; }
  uint32_t operator[](size_t i) const { return words_[i]; }

 private:
  struct Free {
    void operator()(uint32_t* p) const { std::free(p); }
  };
  std::unique_ptr<uint32_t[], Free> words_;
  size_t size_ = 0;
};

// A conservative occupancy mask of the plants in the sun's frame, so that the photons
// that certainly miss every frustum (most of them: a crown is porous) skip Embree.
// Depth z runs along the photons from the emitter plane; the frusta's depth range is cut
// into at most 32 slabs, thin enough that a photon drifts sideways by about half a cell
// within one (tan α per metre of depth). A grid of cells over the plants' lateral extent
// holds, per cell, one bit per slab: set where a frustum overlapping the slab may be —
// within the capsule around its projected axis whose radius reaches every vertex of its
// bounding pyramid (skin.h), grown by the slab's drift and half a cell's diagonal. A
// photon whose lateral position at every slab's middle falls on a clear bit cannot hit a
// frustum. The bits of a cell sit in one word (a photon drifts over a few neighbouring
// cells, so its test touches a cache line or two), and a coarse bitmap (8×8 cells per
// bit, grown by the whole depth's drift) that fits in L1 answers most photons first.
// The tests check that the mask changes no shadow vector.
class SunMask {
 public:
  // Over the frusta and, when given, the leaves' triangles (each in the capsule around its
  // first edge as wide as its third vertex is far: the triangle lies within it), and the
  // instances of `placed` (their capsules made again from the prototypes for each band of
  // the rasterisation, never stored: a scatter's placed frusta would not fit).
  SunMask(std::span<const Frustum> frusta, const LeafMesh* leaves, const CrotchBalls* crotches, const SunEmitter& e,
          unsigned threads, const PlacedPlants* placed = nullptr)
      : frame_(axis_frame(e.to_sun)), e_(e) {
    std::vector<Capsule> capsules;
    capsules.reserve(frusta.size());
    glm::dvec2 lo(kInf), hi(-kInf);
    double z_lo = kInf, z_hi = -kInf;
    auto extend = [&](const Capsule& c) {
      lo = glm::min(lo, glm::min(c.a, c.b) - c.radius);
      hi = glm::max(hi, glm::max(c.a, c.b) + c.radius);
      z_lo = std::min(z_lo, c.z0);
      z_hi = std::max(z_hi, c.z1);
    };
    for (const Frustum& f : frusta) {
      capsules.push_back(frustum_capsule(f.shape));
      extend(capsules.back());
    }
    for (uint32_t i = 0; crotches && i < crotches->count(); ++i) {
      capsules.push_back(ball_capsule(crotches->crotch(i).centre, crotches->crotch(i).radius));
      extend(capsules.back());
    }
    for (size_t t = 0; leaves && t < leaves->triangle_count(); ++t) {
      const glm::dvec3* v[3];
      for (int k = 0; k < 3; ++k) v[k] = &leaves->positions[leaves->indices[3 * t + static_cast<size_t>(k)]];
      capsules.push_back(triangle_capsule(*v[0], *v[1], *v[2]));
      extend(capsules.back());
    }
    bool any_placed = false;
    auto for_each_placed = [&](auto&& visit) {
      if (placed)
        placed->for_each([&](const FrustumShape& shape) { visit(frustum_capsule(shape)); },
                         [&](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
                           visit(triangle_capsule(a, b, c));
                         },
                         [&](const glm::dvec3& centre, double radius) { visit(ball_capsule(centre, radius)); });
    };
    for_each_placed([&](const Capsule& c) { extend(c), any_placed = true; });
    if (capsules.empty() && !any_placed) return;
    // Cells: the larger extent in kCells, at least a hair (a single thin frustum).
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, 1e-6});
    cell_ = extent / kCells;
    // A border as wide as the drift over half the depth range: a photon outside the grid
    // at the middle depth cannot reach an occupied cell at any depth.
    const double tan_a = std::tan(e.sun_radius_rad);
    const double border = 0.5 * (z_hi - z_lo) * tan_a * 1.001 + cell_;
    lo_ = lo - border;
    nx_ = round_up_to_tile(static_cast<uint32_t>((hi.x + border - lo_.x) / cell_) + 2);
    ny_ = round_up_to_tile(static_cast<uint32_t>((hi.y + border - lo_.y) / cell_) + 2);
    slabs_ = static_cast<uint32_t>(std::clamp(std::ceil((z_hi - z_lo) * tan_a / (0.5 * cell_)), 1.0, double(kMaxSlabs)));
    z0_ = z_lo;
    thickness_ = std::max(1e-9, (z_hi - z_lo) / slabs_) * (1 + 1e-9);
    const double drift = 0.5 * thickness_ * tan_a * 1.001 + 1e-9;
    cells_.assign(size_t(nx_) * ny_);
    // Rows of cells in bands of whole tiles, one band per thread (every band reads every
    // capsule).
    const unsigned bands = std::max(1u, std::min(threads, ny_ / 16 + 1));
    auto band_row = [&](unsigned b) { return uint32_t(uint64_t(ny_ / kTile) * b / bands) * kTile; };
    auto rasterise = [&](uint32_t row_begin, uint32_t row_end) {
      auto draw = [&](const Capsule& c) {
        const uint32_t s0 = slab_of(c.z0), s1 = slab_of(c.z1);
        const uint32_t bits = static_cast<uint32_t>(((uint64_t(1) << (s1 + 1)) - 1) & ~((uint64_t(1) << s0) - 1));
        const double r = c.radius + drift + cell_ * 0.7072;
        const glm::dvec2 box_lo = glm::min(c.a, c.b) - r, box_hi = glm::max(c.a, c.b) + r;
        const uint32_t y0 = std::max(row_begin, cell_y(box_lo.y)), y1 = std::min(row_end - 1, cell_y(box_hi.y));
        if (y0 > y1 || cell_y(box_lo.y) >= row_end || cell_y(box_hi.y) < row_begin) return;
        const uint32_t x0 = cell_x(box_lo.x), x1 = cell_x(box_hi.x);
        for (uint32_t y = y0; y <= y1; ++y)
          for (uint32_t x = x0; x <= x1; ++x) {
            const glm::dvec2 centre = lo_ + (glm::dvec2(x, y) + 0.5) * cell_;
            if (segment_distance(centre, c.a, c.b) <= r) cells_[cell_index(x, y)] |= bits;
          }
      };
      for (const Capsule& c : capsules) draw(c);
      for_each_placed(draw);
    };
    run_on_workers(bands, [&](unsigned b) { rasterise(band_row(b), band_row(b + 1)); });
    // The coarse bitmap, keyed by the position at the middle depth: grown by the drift
    // from there to either end of the depth range, in coarse cells, and one more.
    z_mid_ = 0.5 * (z_lo + z_hi);
    cx_ = (nx_ + kCoarse - 1) / kCoarse;
    cy_ = (ny_ + kCoarse - 1) / kCoarse;
    coarse_words_ = (cx_ + 63) / 64;
    coarse_.assign(size_t(cy_) * coarse_words_, 0);
    const int grow = static_cast<int>(std::ceil(0.5 * (z_hi - z_lo) * tan_a * 1.001 / cell_ / kCoarse)) + 1;
    std::vector<uint8_t> occupied(size_t(cx_) * cy_, 0);
    for (uint32_t y = 0; y < ny_; ++y)
      for (uint32_t x = 0; x < nx_; ++x)
        if (cells_[cell_index(x, y)]) occupied[size_t(y / kCoarse) * cx_ + x / kCoarse] = 1;
    for (int gy = 0; gy < int(cy_); ++gy)
      for (int gx = 0; gx < int(cx_); ++gx) {
        if (!occupied[size_t(gy) * cx_ + gx]) continue;
        for (int yy = std::max(0, gy - grow); yy <= std::min(int(cy_) - 1, gy + grow); ++yy)
          for (int xx = std::max(0, gx - grow); xx <= std::min(int(cx_) - 1, gx + grow); ++xx)
            coarse_[size_t(yy) * coarse_words_ + xx / 64] |= 1ull << (xx % 64);
      }
  }

  // Whether a photon from `origin` (on the emitter plane) along `direction` may hit.
  bool may_hit(const glm::dvec3& origin, const glm::dvec3& direction) const {
    if (cells_.empty()) return false;
    const double dz = -glm::dot(direction, e_.to_sun);
    const glm::dvec2 o = (lateral(origin) - lo_) / cell_, d = lateral_direction(direction) / (dz * cell_);
    const double z_origin = depth(origin);
    // The coarse test at the middle depth.
    const glm::dvec2 m = (o + (z_mid_ - z_origin) * d) / double(kCoarse);
    if (!(m.x >= 0 && m.y >= 0 && m.x < cx_ && m.y < cy_)) return false;
    const uint32_t mx = static_cast<uint32_t>(m.x), my = static_cast<uint32_t>(m.y);
    if (!(coarse_[size_t(my) * coarse_words_ + mx / 64] >> (mx % 64) & 1)) return false;
    // The slabs, at each one's middle.
    glm::dvec2 p = o + (z0_ + 0.5 * thickness_ - z_origin) * d;
    const glm::dvec2 step = thickness_ * d;
    for (uint32_t s = 0; s < slabs_; ++s, p += step) {
      if (!(p.x >= 0 && p.y >= 0 && p.x < nx_ && p.y < ny_)) continue;
      const uint32_t x = static_cast<uint32_t>(p.x), y = static_cast<uint32_t>(p.y);
      if (cells_[cell_index(x, y)] >> s & 1) return true;
    }
    return false;
  }

  size_t bytes() const { return cells_.size() * sizeof(uint32_t) + coarse_.size() * sizeof(uint64_t); }

 private:
  static constexpr uint32_t kCells = 2048;
  static constexpr uint32_t kMaxSlabs = 32;
  static constexpr uint32_t kCoarse = 8;
  // Cells are stored in tiles of kTile × kTile, one 64-byte cache line each: a photon's
  // slabs walk a few cells diagonally, which in rows 8 KiB apart touched a line (and a
  // page) per row.
  static constexpr uint32_t kTile = 4;
  static uint32_t round_up_to_tile(uint32_t n) { return (n + kTile - 1) / kTile * kTile; }
  size_t cell_index(uint32_t x, uint32_t y) const {
    return ((size_t(y / kTile) * (nx_ / kTile) + x / kTile) * kTile + y % kTile) * kTile + x % kTile;
  }

  struct Capsule {
    glm::dvec2 a, b;
    double radius, z0, z1;
  };
  Capsule frustum_capsule(const FrustumShape& shape) const {
    const BoundingPyramid pyramid = bounding_pyramid(shape);
    Capsule c;
    c.a = lateral(shape.base);
    c.b = lateral(shape.base + shape.length * shape.axis);
    c.radius = 0;
    c.z0 = kInf, c.z1 = -kInf;
    for (const glm::dvec3& v : pyramid.vertices) {
      c.radius = std::max(c.radius, segment_distance(lateral(v), c.a, c.b));
      c.z0 = std::min(c.z0, depth(v));
      c.z1 = std::max(c.z1, depth(v));
    }
    c.radius = c.radius * (1 + 1e-9) + 1e-9;
    return c;
  }
  // A blended crotch's ball (crotch_tracer.h): a capsule of no length.
  Capsule ball_capsule(const glm::dvec3& centre, double radius) const {
    Capsule c;
    c.a = c.b = lateral(centre);
    c.radius = radius * (1 + 1e-9) + 1e-9;
    c.z0 = depth(centre) - c.radius;
    c.z1 = depth(centre) + c.radius;
    return c;
  }
  Capsule triangle_capsule(const glm::dvec3& v0, const glm::dvec3& v1, const glm::dvec3& v2) const {
    Capsule c;
    c.a = lateral(v0);
    c.b = lateral(v1);
    c.radius = segment_distance(lateral(v2), c.a, c.b) * (1 + 1e-9) + 1e-9;
    c.z0 = std::min({depth(v0), depth(v1), depth(v2)});
    c.z1 = std::max({depth(v0), depth(v1), depth(v2)});
    return c;
  }

  glm::dvec2 lateral(const glm::dvec3& p) const {
    const glm::dvec3 q = p - e_.disc_centre;
    return {glm::dot(q, frame_.e0), glm::dot(q, frame_.e1)};
  }
  glm::dvec2 lateral_direction(const glm::dvec3& d) const { return {glm::dot(d, frame_.e0), glm::dot(d, frame_.e1)}; }
  double depth(const glm::dvec3& p) const { return -glm::dot(p - e_.disc_centre, e_.to_sun); }
  static double segment_distance(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * ab));
  }
  uint32_t cell_x(double x) const { return static_cast<uint32_t>(std::clamp((x - lo_.x) / cell_, 0.0, nx_ - 1.0)); }
  uint32_t cell_y(double y) const { return static_cast<uint32_t>(std::clamp((y - lo_.y) / cell_, 0.0, ny_ - 1.0)); }
  uint32_t slab_of(double z) const {
    return static_cast<uint32_t>(std::clamp((z - z0_) / thickness_, 0.0, slabs_ - 1.0));
  }

  AxisFrame frame_;
  SunEmitter e_;
  glm::dvec2 lo_{0, 0};
  double cell_ = 1, z0_ = 0, thickness_ = 1, z_mid_ = 0;
  uint32_t nx_ = 0, ny_ = 0, slabs_ = 0, cx_ = 0, cy_ = 0;
  size_t coarse_words_ = 0;
  MaskWords cells_;  // per cell (cell_index): bit s = slab s may hold a frustum
  std::vector<uint64_t> coarse_;
};

}  // namespace

namespace {

// The emitter around the box [lo, hi] (any: whether there are frusta) under `sun`.
SunEmitter sun_emitter_of_box(const glm::dvec3& lo, const glm::dvec3& hi, bool any, const Sun& sun);

}  // namespace

SunEmitter sun_emitter(std::span<const Frustum> frusta, const Sun& sun, const Aabb& leaves) {
  glm::dvec3 lo(kInf), hi(-kInf);
  for (const Frustum& f : frusta) {
    const Aabb b = frustum_bounds(f.shape);
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  if (!frusta.empty() && leaves.lo.x <= leaves.hi.x) lo = glm::min(lo, leaves.lo), hi = glm::max(hi, leaves.hi);
  return sun_emitter_of_box(lo, hi, !frusta.empty(), sun);
}

namespace {

SunEmitter sun_emitter_of_box(const glm::dvec3& lo, const glm::dvec3& hi, bool any, const Sun& sun) {
  SunEmitter e;
  if (any) {
    e.centre = 0.5 * (lo + hi);
    e.sphere_radius_m = 0.5 * glm::length(hi - lo);
  }
  e.to_sun = glm::normalize(sun.direction);
  e.sun_radius_rad = std::max(0.0, sun.angular_radius_deg) * kRadPerDeg;
  // Every line through the sphere within α of the sun's axis crosses the tangent plane
  // within R/cos α + 2R·tan α of the disc's centre (its point nearest the centre is within
  // R of it, and it travels at most 2R/cos α along itself to the plane, drifting sideways
  // by tan α per unit of depth); a hair more for rounding.
  const double tan_a = std::tan(e.sun_radius_rad), cos_a = std::cos(e.sun_radius_rad);
  e.disc_centre = e.centre + e.sphere_radius_m * 1.001 * e.to_sun;
  e.disc_radius_m = e.sphere_radius_m * (1 + 2 * tan_a) / cos_a * 1.001;
  return e;
}

// The leaves as the photons see them: the triangles, and per plant the frustum its leaves'
// shadow vectors name (its first: the clustering keeps plants apart by it).
constexpr uint32_t kNoFrustum = 0xFFFFFFFFu;
struct PhotonLeaves {
  const LeafTracer* tracer = nullptr;  // null: no leaves
  std::vector<uint32_t> first_frustum_of_plant;
};

// The photons of `e`, those `mask` clears skipped, each given to vector_of(ray, &local):
// it appends the photon's shadow vector, if any, to `local`.
template <class VectorOf>
SunPhotons trace_photons(const SunMask& mask, const SunEmitter& e, const SunPhotonOptions& options,
                         VectorOf&& vector_of) {
  SunPhotons out;
  out.emitter = e;
  out.vectors.origin = e.centre;
  if (options.photons == 0) return out;
  const Clock::time_point start = Clock::now();
  const double cpu_start = process_cpu_seconds();
  const AxisFrame frame = axis_frame(e.to_sun);
  const double one_minus_cos = 2 * std::pow(std::sin(0.5 * e.sun_radius_rad), 2);
  const uint64_t offset0 = mix_pair(options.seed, 0x52325f6f666673ULL);  // the rotation
  const uint64_t offset1 = mix_pair(options.seed, 0x52325f6f666674ULL);
  const uint64_t chunks = (options.photons + kChunk - 1) / kChunk;
  std::vector<std::vector<ShadowVector>> per_chunk(chunks);
  std::vector<uint8_t> ran(chunks, 0);

  auto trace_chunk = [&](uint64_t c, unsigned) {
    std::vector<ShadowVector>& local = per_chunk[c];
    const uint64_t end = std::min(options.photons, (c + 1) * kChunk);
    for (uint64_t i = c * kChunk; i < end; ++i) {
      const glm::dvec2 q = concentric_disc(unit_from_fixed(offset0 + i * kR2Step0), unit_from_fixed(offset1 + i * kR2Step1));
      Rng rng(mix_pair(options.seed, i));
      Ray ray;
      ray.origin = e.disc_centre + e.disc_radius_m * (q.x * frame.e0 + q.y * frame.e1);
      ray.direction = photon_direction(e.to_sun, frame, one_minus_cos, rng);
      if (options.occupancy_mask && !mask.may_hit(ray.origin, ray.direction)) continue;
      vector_of(ray, local);
    }
    ran[c] = 1;
  };
  out.cancelled = !parallel_for(chunks, options.threads, options.cancel, trace_chunk);
  size_t total = 0;
  for (const auto& v : per_chunk) total += v.size();
  out.vectors.vectors.reserve(total);
  for (uint64_t c = 0; c < chunks; ++c) {
    out.vectors.vectors.insert(out.vectors.vectors.end(), per_chunk[c].begin(), per_chunk[c].end());
    if (ran[c]) out.traced += std::min(options.photons, (c + 1) * kChunk) - c * kChunk;
  }
  out.seconds = seconds_since(start);
  out.cpu_seconds = process_cpu_seconds() - cpu_start;
  return out;
}

// The vector a photon leaves at a leaf hit (a leaf is thin, so its far side is its hit
// point: docs/leaves.md) naming `frustum`, the first frustum of the leaf's plant.
void leave_at_leaf(const SurfaceHit& leaf, uint32_t frustum, const Ray& ray, const SunEmitter& e,
                   std::vector<ShadowVector>& local) {
  if (frustum != kNoFrustum) local.push_back({glm::vec3(leaf.position - e.centre), glm::vec3(ray.direction), frustum});
}

// Fig. 2b: the vector where the photon, which hit `shape` at t_hit, leaves its convex solid.
void leave_at_exit(const FrustumShape& shape, double t_hit, uint32_t frustum, const Ray& ray, const SunEmitter& e,
                   std::vector<ShadowVector>& local) {
  const SolidInterval solid = frustum_solid_interval(ray, shape, 0, kInf);
  const double t_exit = solid.hit ? std::max(solid.t_exit, t_hit) : t_hit;
  const glm::dvec3 exit = ray.origin + t_exit * ray.direction;
  local.push_back({glm::vec3(exit - e.centre), glm::vec3(ray.direction), frustum});
}

// One prototype of the instanced photon tracer: exact frusta (no relief) and leaves in one
// frame, hit as the non-instanced photons hit them — the nearest frustum, unless a leaf
// comes first (then the leaf hit, is_leaf()), with the blended crotches' fillets (nearest_wood).
// Its hits' plant: plant_of_frustum's, or 0 (an instance's hits take the instance's plant).
class PhotonPrototype final : public SceneTracer {
 public:
  PhotonPrototype(std::span<const Frustum> frusta, const LeafTracer* leaves, std::span<const uint32_t> plant_of_frustum,
                  const CrotchBalls* crotches)
      : frusta_(frusta),
        leaves_(leaves && !leaves->leaves().empty() ? leaves : nullptr),
        plants_(plant_of_frustum),
        crotches_(crotches && crotches->count() > 0 ? crotches : nullptr) {
    if (!frusta.empty()) accel_.emplace(frusta, CustomFrusta{}, crotches_);
    for (const Frustum& f : frusta) grow(bounds_, frustum_bounds(f.shape));
    if (leaves_) grow(bounds_, leaves_->leaves().bounds());
    if (crotches_) grow(bounds_, crotches_->all_bounds());
  }
  SurfaceHit nearest(const Ray& ray, double t_min, double t_max) const override {
    // t_min is 0 for every photon query (the instance tracer passes it on).
    const BvhHit hit = accel_ ? nearest_wood(*accel_, crotches_, ray, 0, t_max) : BvhHit{};
    if (leaves_) {
      const SurfaceHit leaf = leaves_->nearest_leaf(ray, t_min, hit.hit_any() ? hit.hit.t : t_max);
      if (leaf.hit()) return leaf;
    }
    SurfaceHit s;
    if (!hit.hit_any()) return s;
    s.t = hit.hit.t;
    s.position = ray.origin + s.t * ray.direction;
    s.frustum = hit.frustum;
    s.plant = hit.frustum < plants_.size() ? plants_[hit.frustum] : 0;
    return s;
  }
  bool any(const Ray& ray, double t_min, double t_max) const override {
    return (accel_ && accel_->any(ray, t_min, t_max)) || (leaves_ && leaves_->nearest_leaf(ray, t_min, t_max).hit());
  }
  Aabb bounds() const override { return bounds_; }
  size_t memory_bytes() const override { return accel_ ? accel_->memory_bytes() : 0; }
  std::string describe() const override { return std::to_string(frusta_.size()) + " frusta"; }

 private:
  std::span<const Frustum> frusta_;
  const LeafTracer* leaves_;
  std::span<const uint32_t> plants_;
  const CrotchBalls* crotches_;
  std::optional<FrustumAccel> accel_;
  Aabb bounds_ = empty_box();
};

}  // namespace

struct SunPhotonTracer::Impl {
  std::span<const Frustum> frusta;
  std::span<const uint32_t> plant_of_frustum;
  PhotonLeaves leaves;
  const CrotchBalls* crotches = nullptr;  // the blended crotches' balls (null: none)
  SunEmitter emitter;
  std::optional<FrustumAccel> accel;  // none without frusta
  std::optional<SunMask> mask;
  double build_seconds = 0;
  // With instances (photons.h): the tracer over every plant, the instances, the first
  // index of each instance's block in the frustum space and the space's plants.
  std::unique_ptr<InstanceTracer> placed;
  std::vector<SceneGeometry::Prototype> prototypes;
  std::vector<TracedInstance> instances;
  std::vector<uint32_t> instance_of_plant;  // kNoFrustum: skinned in the world
  std::vector<uint32_t> first_of_instance;
  std::vector<uint32_t> placed_plant_of_frustum;
  bool any_frusta = false;
};

namespace {

// The first frustum of each plant in `plant_of_frustum` (kNoFrustum: none).
std::vector<uint32_t> first_frustum_of_plants(std::span<const uint32_t> plant_of_frustum) {
  std::vector<uint32_t> first;
  for (uint32_t f = 0; f < plant_of_frustum.size(); ++f) {
    const uint32_t p = plant_of_frustum[f];
    if (p >= first.size()) first.resize(p + 1, kNoFrustum);
    if (first[p] == kNoFrustum) first[p] = f;
  }
  return first;
}

}  // namespace

SunPhotonTracer::SunPhotonTracer(std::span<const Frustum> frusta, const Sun& sun, unsigned threads,
                                 const LeafTracer* leaves, std::span<const uint32_t> plant_of_frustum,
                                 const CrotchBalls* crotches)
    : impl_(std::make_unique<Impl>()) {
  const Clock::time_point start = Clock::now();
  impl_->frusta = frusta;
  const LeafMesh* leaf_mesh = leaves && !leaves->leaves().empty() ? &leaves->leaves() : nullptr;
  impl_->plant_of_frustum = plant_of_frustum;
  if (leaf_mesh) {
    impl_->leaves.tracer = leaves;
    impl_->leaves.first_frustum_of_plant = first_frustum_of_plants(plant_of_frustum);
  }
  impl_->any_frusta = !frusta.empty();
  impl_->crotches = crotches && crotches->count() > 0 && !frusta.empty() ? crotches : nullptr;
  Aabb beside = leaf_mesh ? leaf_mesh->bounds() : empty_box();  // what the frusta's box leaves out
  if (impl_->crotches) grow(beside, impl_->crotches->all_bounds());
  impl_->emitter = sun_emitter(frusta, sun, beside);
  if (!frusta.empty()) {
    impl_->accel.emplace(frusta, CustomFrusta{}, impl_->crotches);
    impl_->mask.emplace(frusta, leaf_mesh, impl_->crotches, impl_->emitter, worker_count(threads));
  }
  impl_->build_seconds = seconds_since(start);
}

SunPhotonTracer::SunPhotonTracer(const SceneGeometry& geometry, const Sun& sun, unsigned threads)
    : SunPhotonTracer(geometry.instances.empty() ? std::span<const Frustum>(geometry.frusta) : std::span<const Frustum>{},
                      sun, threads, geometry.instances.empty() ? geometry.leaves : nullptr,
                      geometry.instances.empty() ? std::span<const uint32_t>(geometry.plant_of_frustum)
                                                 : std::span<const uint32_t>{},
                      geometry.instances.empty() ? geometry.crotches.get() : nullptr) {
  if (geometry.instances.empty()) return;
  const Clock::time_point start = Clock::now();
  Impl& m = *impl_;
  m.frusta = geometry.frusta;
  m.prototypes = geometry.prototypes;
  m.instances = geometry.instances;
  // The frustum space: the world's frusta, then each instance's block.
  m.placed_plant_of_frustum.assign(geometry.plant_of_frustum.begin(), geometry.plant_of_frustum.end());
  m.first_of_instance.reserve(m.instances.size());
  for (uint32_t i = 0; i < m.instances.size(); ++i) {
    const TracedInstance& inst = m.instances[i];
    if (inst.plant >= m.instance_of_plant.size()) m.instance_of_plant.resize(inst.plant + 1, kNoFrustum);
    m.instance_of_plant[inst.plant] = i;
    m.first_of_instance.push_back(static_cast<uint32_t>(m.placed_plant_of_frustum.size()));
    m.placed_plant_of_frustum.insert(m.placed_plant_of_frustum.end(), m.prototypes[inst.prototype].frusta.size(),
                                     inst.plant);
  }
  if (m.placed_plant_of_frustum.size() >= kNoFrustum)
    throw std::runtime_error("sun photons: more than 2^32 - 1 placed frusta");
  m.plant_of_frustum = m.placed_plant_of_frustum;
  m.leaves.tracer = nullptr;
  m.leaves.first_frustum_of_plant = first_frustum_of_plants(m.plant_of_frustum);
  // The tracer: a photon prototype per skeleton, the world's plants one more at the identity.
  std::vector<std::unique_ptr<SceneTracer>> prototypes;
  for (const SceneGeometry::Prototype& p : m.prototypes)
    prototypes.push_back(
        std::make_unique<PhotonPrototype>(p.frusta, p.leaves, std::span<const uint32_t>{}, p.crotches));
  std::vector<TracedInstance> instances = m.instances;
  instances.push_back({static_cast<uint32_t>(prototypes.size()), TracedInstance::kOwnPlant, PlantTransform{}});
  prototypes.push_back(std::make_unique<PhotonPrototype>(geometry.frusta, geometry.world_leaves,
                                                         geometry.plant_of_frustum, geometry.crotches.get()));
  m.placed = std::make_unique<InstanceTracer>(std::move(prototypes), std::move(instances));
  // The emitter over every placed frustum and leaf, as sun_emitter over the world's.
  const PlacedPlants placed{m.prototypes, m.instances};
  glm::dvec3 lo(kInf), hi(-kInf), leaf_lo(kInf), leaf_hi(-kInf);
  for (const Frustum& f : geometry.frusta) {
    const Aabb b = frustum_bounds(f.shape);
    lo = glm::min(lo, b.lo), hi = glm::max(hi, b.hi);
  }
  bool any_frusta = !geometry.frusta.empty();
  placed.for_each(
      [&](const FrustumShape& shape) {
        const Aabb b = frustum_bounds(shape);
        lo = glm::min(lo, b.lo), hi = glm::max(hi, b.hi), any_frusta = true;
      },
      [&](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
        leaf_lo = glm::min(glm::min(leaf_lo, a), glm::min(b, c));
        leaf_hi = glm::max(glm::max(leaf_hi, a), glm::max(b, c));
      },
      [&](const glm::dvec3& centre, double radius) {  // a crotch's ball: beside the frusta, as the leaves
        leaf_lo = glm::min(leaf_lo, centre - radius), leaf_hi = glm::max(leaf_hi, centre + radius);
      });
  const LeafMesh* world_leaves =
      geometry.world_leaves && !geometry.world_leaves->leaves().empty() ? &geometry.world_leaves->leaves() : nullptr;
  if (world_leaves) {
    const Aabb b = world_leaves->bounds();
    leaf_lo = glm::min(leaf_lo, b.lo), leaf_hi = glm::max(leaf_hi, b.hi);
  }
  const CrotchBalls* world_crotches = geometry.crotches && !geometry.frusta.empty() ? geometry.crotches.get() : nullptr;
  if (world_crotches) {
    const Aabb b = world_crotches->all_bounds();
    leaf_lo = glm::min(leaf_lo, b.lo), leaf_hi = glm::max(leaf_hi, b.hi);
  }
  if (any_frusta && leaf_lo.x <= leaf_hi.x) lo = glm::min(lo, leaf_lo), hi = glm::max(hi, leaf_hi);
  m.any_frusta = any_frusta;
  m.emitter = sun_emitter_of_box(lo, hi, any_frusta, sun);
  if (any_frusta)
    m.mask.emplace(geometry.frusta, world_leaves, world_crotches, m.emitter, worker_count(threads), &placed);
  m.build_seconds += seconds_since(start);
}

SunPhotonTracer::~SunPhotonTracer() = default;

const SunEmitter& SunPhotonTracer::emitter() const { return impl_->emitter; }
double SunPhotonTracer::build_seconds() const { return impl_->build_seconds; }
std::span<const Frustum> SunPhotonTracer::frusta() const { return impl_->frusta; }
std::span<const uint32_t> SunPhotonTracer::plant_of_frustum() const { return impl_->plant_of_frustum; }

SunPhotons SunPhotonTracer::trace(const SunPhotonOptions& options) const {
  const Impl& m = *impl_;
  const SunEmitter& e = m.emitter;
  if (!m.any_frusta) {
    SunPhotons out;
    out.emitter = e;
    out.vectors.origin = e.centre;
    return out;
  }
  if (m.placed)
    return trace_photons(*m.mask, e, options, [&](const Ray& ray, std::vector<ShadowVector>& local) {
      const SurfaceHit hit = m.placed->nearest(ray, 0, kInf);
      if (!hit.hit()) return;
      if (hit.is_leaf()) {
        const auto& first = m.leaves.first_frustum_of_plant;
        return leave_at_leaf(hit, hit.plant < first.size() ? first[hit.plant] : kNoFrustum, ray, e, local);
      }
      const uint32_t i = hit.plant < m.instance_of_plant.size() ? m.instance_of_plant[hit.plant] : kNoFrustum;
      if (i == kNoFrustum) return leave_at_exit(m.frusta[hit.frustum].shape, hit.t, hit.frustum, ray, e, local);
      const TracedInstance& inst = m.instances[i];
      leave_at_exit(placed_shape(m.prototypes[inst.prototype].frusta[hit.frustum].shape, inst.transform), hit.t,
                    m.first_of_instance[i] + hit.frustum, ray, e, local);
    });
  return trace_photons(*m.mask, e, options, [&](const Ray& ray, std::vector<ShadowVector>& local) {
    const BvhHit hit = nearest_wood(*m.accel, m.crotches, ray, 0, kInf);
    // A leaf before the first frustum (or instead of one) stops the photon, naming the
    // first frustum of the leaf's plant.
    if (m.leaves.tracer) {
      const SurfaceHit leaf = m.leaves.tracer->nearest_leaf(ray, 0, hit.hit_any() ? hit.hit.t : kInf);
      if (leaf.hit()) {
        const auto& first = m.leaves.first_frustum_of_plant;
        return leave_at_leaf(leaf, leaf.plant < first.size() ? first[leaf.plant] : kNoFrustum, ray, e, local);
      }
    }
    if (hit.hit_any()) leave_at_exit(m.frusta[hit.frustum].shape, hit.hit.t, hit.frustum, ray, e, local);
  });
}

bool SunPhotonTracer::toward_sun_blocked(const glm::dvec3& point) const {
  const Ray ray{point, impl_->emitter.to_sun};
  if (impl_->placed) return impl_->placed->any(ray, 0, kInf);
  return impl_->accel && (impl_->accel->any(ray, 0, kInf) ||
                          (impl_->leaves.tracer && impl_->leaves.tracer->nearest_leaf(ray, 0, kInf).hit()));
}

double SunPhotonTracer::first_hit(const Ray& ray) const {
  const Impl& m = *impl_;
  if (!m.any_frusta || (m.mask && !m.mask->may_hit(ray.origin, ray.direction))) return kInf;
  if (m.placed) {
    const SurfaceHit hit = m.placed->nearest(ray, 0, kInf);
    return hit.hit() ? hit.t : kInf;
  }
  const BvhHit hit = nearest_wood(*m.accel, m.crotches, ray, 0, kInf);
  double t = hit.hit_any() ? hit.hit.t : kInf;
  if (m.leaves.tracer) {
    const SurfaceHit leaf = m.leaves.tracer->nearest_leaf(ray, 0, t);
    if (leaf.hit()) t = leaf.t;
  }
  return t;
}

SunPhotons trace_sun_photons(std::span<const Frustum> frusta, const Sun& sun, const SunPhotonOptions& options) {
  const SunPhotonTracer tracer(frusta, sun, options.threads);
  SunPhotons out = tracer.trace(options);
  out.build_seconds = tracer.build_seconds();
  return out;
}

// ---- Coverage and the automatic choice -------------------------------------------------

namespace {

// Sample points of a shadow region and whether each is in the exact shadow.
struct ShadowSamples {
  std::vector<glm::dvec3> points;
  std::vector<uint8_t> shadowed;
  uint64_t shadowed_count = 0;
};

// A square window of the emitter plane (centre (a, b) in the emitter's frame, half size),
// or the sphere's whole cross-section (half_size <= 0).
struct Window {
  double a = 0, b = 0, half_size = 0;
};

// Points uniform in the region `window` sweeps along the sun from the sphere's sunward
// tangent plane to 2R beyond its far side, above the ground; drawn until `min_shadowed`
// are in the exact shadow (a ray toward the sun's centre hits a frustum) or `max_points`
// were drawn. Deterministic for `seed`.
ShadowSamples sample_shadow_region(const SunPhotonTracer& tracer, const Window& w, double ground,
                                   uint64_t max_points, uint64_t min_shadowed, uint64_t seed) {
  ShadowSamples out;
  const SunEmitter& e = tracer.emitter();
  const AxisFrame f = axis_frame(e.to_sun);
  const double depth = 4 * e.sphere_radius_m;
  const glm::dvec3 top = e.centre + e.sphere_radius_m * e.to_sun;
  Rng rng(mix_pair(seed, 0x636f766572616765ULL));
  for (uint64_t i = 0; i < max_points && out.shadowed_count < min_shadowed; ++i) {
    double a, b;
    if (w.half_size > 0) {
      a = w.a + w.half_size * (2 * rng.next_double() - 1);
      b = w.b + w.half_size * (2 * rng.next_double() - 1);
    } else {
      const glm::dvec2 q = concentric_disc(rng.next_double(), rng.next_double());
      a = e.sphere_radius_m * q.x;
      b = e.sphere_radius_m * q.y;
    }
    const glm::dvec3 p = top + a * f.e0 + b * f.e1 - depth * rng.next_double() * e.to_sun;
    if (p.y < ground) continue;
    const bool shadowed = tracer.toward_sun_blocked(p);
    out.points.push_back(p);
    out.shadowed.push_back(shadowed);
    out.shadowed_count += shadowed;
  }
  return out;
}

ConeCoverage measure_coverage(const ConeSet& cones, const ShadowSamples& samples) {
  ConeCoverage c;
  c.points = samples.points.size();
  c.shadowed = samples.shadowed_count;
  uint64_t missed = 0, covered_lit = 0;
  for (size_t i = 0; i < samples.points.size(); ++i) {
    const bool in = cones.contains(samples.points[i]);
    if (samples.shadowed[i] && !in) ++missed;
    if (!samples.shadowed[i] && in) ++covered_lit;
  }
  if (c.shadowed > 0) {
    c.missed_shadow = double(missed) / c.shadowed;
    c.covered_lit = double(covered_lit) / c.shadowed;
  }
  return c;
}

// The automatic choice's grid: p3 vectors per ring, p2 sectors, the threshold on the
// index of dispersion, and p4 as a multiple of p3 (a cone takes at least that many new
// vectors); five rings (p1 = 5·p3 + 1: measured on the pine, 2..8 rings changed the
// error by less than its noise). Searched by coordinate descent from the middle, a move
// only for a gain above the measurement's noise (kMinGain).
constexpr uint32_t kP3[] = {6, 8, 12, 16, 24, 32};
constexpr uint32_t kP2[] = {4, 6, 8, 12, 16};
constexpr double kThreshold[] = {1.25, 1.5, 2, 2.5, 3, 4, 6};
constexpr double kP4PerP3[] = {0.5, 1, 2};
constexpr uint32_t kRings = 5;
constexpr int kAxes = 4;
constexpr int kAxisSize[kAxes] = {6, 5, 7, 3};
constexpr int kStart[kAxes] = {3, 2, 3, 1};  // p3 16, p2 8, threshold 2.5, p4 = p3
constexpr double kMinGain = 0.005;           // ≈ the error's noise on 2000 shadowed points

ConeParams params_at(const std::array<int, kAxes>& g) {
  ConeParams p;
  p.p3 = kP3[g[0]];
  p.p2 = kP2[g[1]];
  p.variance_threshold = kThreshold[g[2]];
  p.p1 = kRings * p.p3 + 1;
  p.p4 = std::max(1u, static_cast<uint32_t>(kP4PerP3[g[3]] * p.p3));
  return p;
}

// Sec. 6.1: the parameters that minimise the measured error (miss_weight·missed shadow +
// covered lit space) on a window of about kWindowVectors vectors at the full density.
constexpr uint64_t kWindowVectors = 8000;

AutoConeReport choose_cone_params(const SunPhotonTracer& tracer, const ShadowVectors& vectors,
                                  std::span<const uint32_t> plant_of_frustum, const ConeLimits& limits,
                                  uint64_t photons, double ground, uint64_t seed,
                                  double miss_weight, unsigned threads) {
  AutoConeReport report;
  report.miss_weight = miss_weight;
  const SunEmitter& e = tracer.emitter();
  const Clock::time_point start = Clock::now();
  report.density_per_m2 = photons / (kPi * e.disc_radius_m * e.disc_radius_m);
  report.spacing_m = report.density_per_m2 > 0 ? 1 / std::sqrt(report.density_per_m2) : 0;
  const AxisFrame f = axis_frame(e.to_sun);
  const size_t n = vectors.vectors.size();
  std::vector<double> a(n), b(n);
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3 p(vectors.vectors[i].position);
    a[i] = glm::dot(p, f.e0);
    b[i] = glm::dot(p, f.e1);
  }
  // The window: around the median position, as large as kWindowVectors vectors need.
  Window w;
  {
    std::vector<double> sa = a, sb = b;
    std::nth_element(sa.begin(), sa.begin() + n / 2, sa.end());
    std::nth_element(sb.begin(), sb.begin() + n / 2, sb.end());
    w.a = sa[n / 2], w.b = sb[n / 2];
    std::vector<double> reach(n);
    for (size_t i = 0; i < n; ++i) reach[i] = std::max(std::abs(a[i] - w.a), std::abs(b[i] - w.b));
    const size_t k = std::min<size_t>(n, kWindowVectors) - 1;
    std::nth_element(reach.begin(), reach.begin() + k, reach.end());
    w.half_size = reach[k];
  }
  ShadowVectors window;
  window.origin = vectors.origin;
  for (size_t i = 0; i < n; ++i)
    if (std::abs(a[i] - w.a) <= w.half_size && std::abs(b[i] - w.b) <= w.half_size)
      window.vectors.push_back(vectors.vectors[i]);
  report.window_vectors = window.vectors.size();
  // Points away from the window's border, where cones lack the neighbours outside it:
  // a margin of twice the largest K's radius at this density (on a flat occluder).
  const uint32_t p1_max = kRings * kP3[kAxisSize[0] - 1] + 1;
  const double margin = 2 * report.spacing_m * std::sqrt(p1_max / kPi);
  Window inner = w;
  inner.half_size = std::max(0.5 * w.half_size, w.half_size - margin);
  const ShadowSamples samples = sample_shadow_region(tracer, inner, ground, 40000, 2000, seed);
  // Every candidate's K is a prefix of the largest: neighbours found once.
  const ShadowVectorIndex index(window, plant_of_frustum, p1_max, threads);
  std::map<std::array<int, kAxes>, size_t> tried;  // grid point → candidate
  auto evaluate = [&](const std::array<int, kAxes>& g) {
    if (auto it = tried.find(g); it != tried.end()) return it->second;
    ConeCandidate c;
    c.params = params_at(g);
    const std::vector<ShadowCone> cones = index.cluster(c.params, limits, nullptr, nullptr, threads);
    c.cones = cones.size();
    c.coverage = measure_coverage(ConeSet(cones), samples);
    report.candidates.push_back(c);
    return tried[g] = report.candidates.size() - 1;
  };
  auto better = [&](size_t x, size_t y) {  // candidate x clearly better than y
    return report.candidates[x].coverage.error(miss_weight) <
           report.candidates[y].coverage.error(miss_weight) - kMinGain;
  };
  std::array<int, kAxes> at;
  std::copy(std::begin(kStart), std::end(kStart), at.begin());
  size_t best = evaluate(at);
  for (bool moved = true; moved;) {
    moved = false;
    std::array<int, kAxes> next = at;
    for (int axis = 0; axis < kAxes; ++axis)
      for (int step : {-1, 1}) {
        std::array<int, kAxes> g = at;
        g[axis] += step;
        if (g[axis] < 0 || g[axis] >= kAxisSize[axis]) continue;
        const size_t c = evaluate(g);
        if (better(c, best)) best = c, next = g, moved = true;  // the best neighbour
      }
    at = next;
  }
  report.chosen = best;
  report.seconds = seconds_since(start);
  return report;
}

std::string params_text(const ConeParams& p) {
  char line[128];
  std::snprintf(line, sizeof line, "p1 %u, p2 %u, p3 %u, p4 %u, threshold %.3g", p.p1, p.p2, p.p3, p.p4,
                p.variance_threshold);
  return line;
}

}  // namespace

std::string AutoConeReport::describe() const {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line,
                "cone parameters (automatic): %.4g photons/m2 (spacing %.3g mm), %llu vectors in the trial window, "
                "error = %.3g x missed shadow + covered lit\n",
                density_per_m2, spacing_m * 1e3, static_cast<unsigned long long>(window_vectors), miss_weight);
  out += line;
  for (size_t i = 0; i < candidates.size(); ++i) {
    const ConeCandidate& c = candidates[i];
    std::snprintf(line, sizeof line, "  %c %s: %llu cones, missed shadow %.4f, covered lit %.4f\n",
                  i == chosen ? '*' : ' ', params_text(c.params).c_str(), static_cast<unsigned long long>(c.cones),
                  c.coverage.missed_shadow, c.coverage.covered_lit);
    out += line;
  }
  return out;
}

// ---- Photons and cones -----------------------------------------------------------------

std::unique_ptr<const SunCones> build_sun_cones(const SceneGeometry& geometry, const Scene& scene,
                                                const SunConeOptions& options, const SunPhotonTracer* tracer) {
  auto out = std::make_unique<SunCones>();
  const bool instanced = !geometry.instances.empty();
  out->emitter = sun_emitter(geometry.frusta, scene.sun, geometry.leaves ? geometry.leaves->leaves().bounds() : empty_box());
  out->params = options.params.value_or(ConeParams{});
  if (!(out->emitter.to_sun.y > 0) || (geometry.frusta.empty() && !instanced) || options.photons.photons == 0)
    return out;

  const Clock::time_point start = Clock::now();
  const double cpu_start = process_cpu_seconds();
  std::optional<SunPhotonTracer> own;
  if (!tracer) tracer = &own.emplace(geometry, scene.sun, options.photons.threads);
  out->emitter = tracer->emitter();  // with instances: over every placed plant
  const SunEmitter& e = out->emitter;
  // The plants of the frustum indices the vectors name (with instances: the tracer's space).
  const std::span<const uint32_t> plant_of_frustum =
      instanced ? tracer->plant_of_frustum() : std::span<const uint32_t>(geometry.plant_of_frustum);
  SunPhotons photons = tracer->trace(options.photons);
  out->photon_seconds = seconds_since(start);
  out->photon_cpu_seconds = process_cpu_seconds() - cpu_start;
  out->photons = photons.traced;
  out->cancelled = photons.cancelled;
  out->vectors = std::move(photons.vectors);
  char detail[160];
  std::snprintf(detail, sizeof detail, "%llu photons, %zu shadow vectors, %s",
                static_cast<unsigned long long>(out->photons), out->vectors.vectors.size(),
                (std::to_string(worker_count(options.photons.threads)) + " threads").c_str());
  out->passes.push_back({"photons", out->photon_seconds, detail});
  if (out->cancelled) return out;

  const Clock::time_point cones_start = Clock::now();
  const double cones_cpu_start = process_cpu_seconds();
  const double ground = scene.ground.height;
  // Cones end below the ground; the length limit only matters for a sun near the
  // horizon: the sweep from the sphere's top to the ground, and 2R more.
  const double top = e.centre.y + e.sphere_radius_m;
  out->limits.ground = true;
  out->limits.ground_height = ground;
  out->limits.max_length_m =
      std::min(1e6, std::max(0.0, top - ground) / std::max(e.to_sun.y, 1e-3) + 2 * e.sphere_radius_m + 1e-3);
  if (!options.params && !out->vectors.vectors.empty()) {
    const Clock::time_point t = Clock::now();
    out->automatic = choose_cone_params(*tracer, out->vectors, plant_of_frustum, out->limits,
                                        out->photons, ground, options.photons.seed, options.miss_weight,
                                        options.photons.threads);
    out->params = out->automatic->candidates[out->automatic->chosen].params;
    out->passes.push_back({"cone params", seconds_since(t),
                           std::to_string(out->automatic->candidates.size()) + " candidates on " +
                               std::to_string(out->automatic->window_vectors) + " vectors: " +
                               params_text(out->params)});
  }
  {
    const Clock::time_point t = Clock::now();
    out->cones = ConeSet(cluster_shadow_cones(out->vectors, plant_of_frustum, out->params, out->limits,
                                              &out->cluster, nullptr, options.photons.threads));
    std::snprintf(detail, sizeof detail, "%llu cones from %llu of %llu vectors (%s)",
                  static_cast<unsigned long long>(out->cluster.cones),
                  static_cast<unsigned long long>(out->cluster.covered),
                  static_cast<unsigned long long>(out->cluster.vectors), params_text(out->params).c_str());
    out->passes.push_back({"cones", seconds_since(t), detail});
  }
  if (options.coverage_points > 0) {
    const Clock::time_point t = Clock::now();
    const double cpu_t = process_cpu_seconds();
    const ShadowSamples samples =
        sample_shadow_region(*tracer, Window{}, ground, options.coverage_points, options.coverage_points,
                             options.photons.seed + 1);
    out->coverage = measure_coverage(out->cones, samples);
    std::snprintf(detail, sizeof detail, "%llu points, %llu shadowed: missed shadow %.4f, covered lit %.4f",
                  static_cast<unsigned long long>(out->coverage->points),
                  static_cast<unsigned long long>(out->coverage->shadowed), out->coverage->missed_shadow,
                  out->coverage->covered_lit);
    out->coverage_seconds = seconds_since(t);
    out->coverage_cpu_seconds = process_cpu_seconds() - cpu_t;
    out->passes.push_back({"cone coverage", out->coverage_seconds, detail});
  }
  out->cone_seconds = seconds_since(cones_start);
  out->cone_cpu_seconds = process_cpu_seconds() - cones_cpu_start;
  return out;
}

bool fog_mode_needs_cones(FogMode mode) {
  return mode == FogMode::medium || mode == FogMode::fast || mode == FogMode::refined;
}

SunConeOptions sun_cone_options_for(FogMode mode, uint64_t photons, const std::optional<std::array<uint32_t, 4>>& params,
                                    unsigned threads, const std::atomic<bool>* cancel, uint64_t seed) {
  SunConeOptions o;
  o.photons.photons = photons;
  o.photons.seed = seed;
  o.photons.threads = threads;
  o.photons.cancel = cancel;
  if (params) {
    ConeParams p;
    p.p1 = (*params)[0];
    p.p2 = (*params)[1];
    p.p3 = (*params)[2];
    p.p4 = (*params)[3];
    o.params = p;
  }
  o.miss_weight = mode == FogMode::fast ? 1.0 : 4.0;
  return o;
}

}  // namespace sylva
