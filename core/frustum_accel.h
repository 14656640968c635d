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
#pragma once

#include <cstddef>
#include <memory>
#include <span>

#include "core/bvh.h"
#include "core/ray_frustum.h"
#include "core/skin.h"

namespace sylva {

class FrustumAccel {
 public:
  // Builds over `frusta`, which must outlive this object and stay unchanged.
  explicit FrustumAccel(std::span<const Frustum> frusta);
  ~FrustumAccel();
  FrustumAccel(const FrustumAccel&) = delete;
  FrustumAccel& operator=(const FrustumAccel&) = delete;

  // The nearest hit with t_min < t < t_max (frustum index valid on a hit).
  BvhHit nearest(const Ray& ray, double t_min, double t_max) const;
  // Whether anything is hit with t_min < t < t_max (shadow rays).
  bool any(const Ray& ray, double t_min, double t_max) const;
  // Bytes Embree allocated for the structure.
  size_t memory_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sylva
