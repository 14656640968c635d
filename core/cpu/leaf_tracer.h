// leaf_tracer.h — a scene's leaves (leaf_mesh.h) in the CPU ray caster: Embree 3 triangles
// (embree_triangles.h: float traversal, every hit decided again in double) beside the
// scene's other geometry (the frusta, or their mesh), one SceneTracer (surface.h) over
// both, so that primary rays, shadow rays, the fog's shadow rays and the sun's photons see
// leaves wherever they see wood.
//
// The leaves have an Embree scene of their own rather than sharing the frusta's: the
// frusta's user geometry keeps its nearest double t in the query context (frustum_accel.cpp)
// and a triangle found by Embree's float test would not lower it. A nearest query asks
// the other geometry first and the leaves only up to its hit (so a leaf behind wood costs
// one short traversal); `any` asks the leaves first (they are few and thin).
//
// What a leaf hit reports (SurfaceHit): t and position in double; geometric_normal =
// shading_normal = the leaf's unit Newell normal, whichever side was hit (a leaf is
// two-sided: the renderer turns it toward the viewer and the light, render_cpu.cpp);
// u, v_m = the leaf's texture coordinates (leaf_mesh.h leaf_uvs, both in [0, 1]) at the
// hit, interpolated over the triangle, and no tangents; plant, material, `leaf` (its index
// in the plant's Skeleton::leaves); chain, segment and frustum 0.
//
// Thread-safe for concurrent queries.
#pragma once

#include <memory>
#include <string>

#include "core/geometry/leaf_mesh.h"
#include "core/geometry/surface.h"

namespace sylva {

class LeafImages;  // leaf_images.h

class LeafTracer final : public SceneTracer {
 public:
  // `other`: the rest of the scene (may be null: leaves alone). `images`: the scene's leaf
  // materials (leaf_images.h; null: every leaf two-sided and whole) — every query, nearest
  // and any alike, passes through a cut-out's transparent texels and a one-sided leaf
  // where the light meets its back: a nearest ray (camera, photon) that arrives at its
  // back, an `any` ray (a shadow ray, cast from a surface toward the light) that leaves
  // through its back, so a one-sided leaf casts no shadow with the light behind it.
  LeafTracer(LeafMesh leaves, std::unique_ptr<SceneTracer> other, std::shared_ptr<const LeafImages> images = nullptr);
  ~LeafTracer() override;
  LeafTracer(const LeafTracer&) = delete;
  LeafTracer& operator=(const LeafTracer&) = delete;

  SurfaceHit nearest(const Ray& ray, double t_min, double t_max) const override;
  bool any(const Ray& ray, double t_min, double t_max) const override;
  Aabb bounds() const override;
  size_t memory_bytes() const override;
  // The other geometry's line, then ", N leaves (M Embree triangles)".
  std::string describe() const override;

  // The nearest leaf alone (the other geometry not asked).
  SurfaceHit nearest_leaf(const Ray& ray, double t_min, double t_max) const;
  const LeafMesh& leaves() const;
  const LeafImages* images() const;  // null when the leaves are plain
  const SceneTracer* other() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sylva
