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
#pragma once

#include <cstddef>
#include <memory>
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

class FrustumAccel {
 public:
  // Builds over `frusta`, which must outlive this object and stay unchanged.
  explicit FrustumAccel(std::span<const Frustum> frusta, CustomFrusta custom = {});
  ~FrustumAccel();
  FrustumAccel(const FrustumAccel&) = delete;
  FrustumAccel& operator=(const FrustumAccel&) = delete;

  // The nearest hit with t_min < t < t_max (frustum index valid on a hit). When the hit is
  // on a custom frustum and `detail` is non-null, *detail is the intersector's detail.
  BvhHit nearest(const Ray& ray, double t_min, double t_max, CustomHitDetail* detail = nullptr) const;
  // Whether anything is hit with t_min < t < t_max (shadow rays).
  bool any(const Ray& ray, double t_min, double t_max) const;
  // Bytes of the structure: Embree's allocations and each frustum's reach.
  size_t memory_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sylva
