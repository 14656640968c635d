// frustum_accel.h — the CPU renderer's ray acceleration: Embree 3's BVH over frusta as
// user geometry, intersected by sylva's own double-precision intersect_frustum.
//
// Chosen by measurement (docs/benchmarks.md, `sylva bench raycast`): on the pine preset
// it traces primary rays 2.0× faster than sylva's own BVH (core/bvh.h) with identical
// hits, in 2.6× less memory. Embree traverses in float; to keep that conservative,
// boxes are rounded outward and padded, and rays and boxes are expressed relative to the
// scene's centre (so offsets of 10⁶ m lose nothing). Every candidate is tested by
// intersect_frustum on the caller's double ray with the current double t_max, and the
// float tfar Embree culls with is rounded up, so the nearest hit is exactly the one a
// brute-force loop over intersect_frustum finds. Thread-safe for concurrent queries.
//
// Custom frusta (relief mapping, relief.h): a caller may name frusta that are not solid
// frusta but something inside a grown box — frustum i is custom iff custom.shell_m is not
// empty and custom.shell_m[i] > 0; its box is that of the frustum with radii grown by
// shell_m[i], and every candidate ray goes to custom.intersector instead of
// intersect_frustum. Other frusta take exactly the path they take without custom frusta
// (one predictable branch per candidate more).
//
// Extra primitives (the blended crotches' balls, crotch_tracer.h): other shapes traced in
// the same Embree scene as the frusta, so that a ray walks one BVH, not two. Their hits
// are kept apart from the frusta's: nearest() reports the nearest frustum hit as always
// and, in *extra, the nearest extra crossing (each extra is asked only up to the nearer of
// the frusta's hit and the extras' so far: its own t_max), and the caller decides which to
// keep. The frusta's hit is exactly the one without extras (an extra never shortens the
// ray the frusta are culled with). A shadow ray (any()) is occluded by either.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include "core/cpu/bvh.h"
#include "core/geometry/ray_frustum.h"
#include "core/geometry/skin.h"

namespace sylva {

// What a custom intersector reports beyond the FrustumHit (relief.h's texture coordinates
// and perturbed shading normal); the accelerator only carries it to the caller.
struct CustomHitDetail {
  double u = 0;                        // turns
  double v_m = 0;                      // metres
  glm::dvec3 shading_normal{0, 0, 0};  // unit, outward
};

// Intersects custom frusta. Called concurrently from every querying thread.
class CustomFrustumIntersector {
 public:
  virtual ~CustomFrustumIntersector() = default;
  // The nearest hit of `ray` on frustum `index` with t_min < t < t_max; when `detail` is
  // non-null and there is a hit, *detail describes it (nullptr: shadow rays, only the
  // hit's existence matters).
  virtual FrustumHit intersect(uint32_t index, const Ray& ray, double t_min, double t_max,
                               CustomHitDetail* detail) const = 0;
};

// The custom frusta of an accelerator (see the header comment). Both must outlive it.
struct CustomFrusta {
  std::span<const double> shell_m;                      // per frustum; > 0: custom
  const CustomFrustumIntersector* intersector = nullptr;
};

// Extra primitives traced beside the frusta (see the header comment). Called concurrently
// from every querying thread.
class ExtraPrimitives {
 public:
  virtual ~ExtraPrimitives() = default;
  virtual uint32_t count() const = 0;
  // A box holding primitive `index` (world space).
  virtual Aabb bounds(uint32_t index) const = 0;
  // The first t in (t_min, t_max) where `ray` meets primitive `index`, if any.
  virtual std::optional<double> intersect(uint32_t index, const Ray& ray, double t_min, double t_max) const = 0;
  // Whether a shadow ray meets it in (t_min, t_max).
  virtual bool occludes(uint32_t index, const Ray& ray, double t_min, double t_max) const = 0;
};

// The nearest extra crossing of a query.
struct ExtraHit {
  static constexpr uint32_t kNone = 0xFFFFFFFFu;
  uint32_t index = kNone;
  double t = 0;
  bool hit() const { return index != kNone; }
};

class FrustumAccel {
 public:
  // Builds over `frusta`, which must outlive this object and stay unchanged, and the
  // `extra` primitives (null: none), which must outlive it too.
  explicit FrustumAccel(std::span<const Frustum> frusta, CustomFrusta custom = {},
                        const ExtraPrimitives* extra = nullptr);
  ~FrustumAccel();
  FrustumAccel(const FrustumAccel&) = delete;
  FrustumAccel& operator=(const FrustumAccel&) = delete;

  // The nearest hit with t_min < t < t_max (frustum index valid on a hit). When the hit is
  // on a custom frustum and `detail` is non-null, *detail is the intersector's detail.
  // With extra primitives and a non-null `extra`, *extra is their nearest crossing with
  // t_min < t < t_max that lies before the frustum hit (if any).
  BvhHit nearest(const Ray& ray, double t_min, double t_max, CustomHitDetail* detail = nullptr,
                 ExtraHit* extra = nullptr) const;
  // Whether anything is hit with t_min < t < t_max (shadow rays).
  bool any(const Ray& ray, double t_min, double t_max) const;
  // Bytes of the structure: Embree's allocations and each frustum's reach (not what the
  // extra primitives hold themselves).
  size_t memory_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sylva
