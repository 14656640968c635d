// mesh_accel.h — the polygon baseline traced by the same CPU engine (Bhagvat et al. 2009 sec. 4): a
// TriangleMesh (tessellate.h: the paper's GS level m, or GS+R when displaced) in Embree 3
// triangle geometry, as a SceneTracer (surface.h), so the renderer shades, textures and
// measures it exactly as it does the analytic frusta.
//
// Precision. Embree traverses and tests the triangles in float, with vertices and rays
// relative to the mesh's centre (offsets of 10^6 m lose nothing) and
// RTC_SCENE_FLAG_ROBUST (its watertight test: no ray slips between triangles that share
// vertices). Which triangle a ray hits is Embree's float answer; everything reported
// about the hit is recomputed in double against the triangle's double vertices and the
// caller's double ray (Möller–Trumbore): t is the exact crossing of the triangle's plane,
// the barycentrics are clamped into the triangle where float and double disagree by
// rounding at an edge. So depth errors measured against the analytic frusta are those of
// the geometry (a chord instead of an arc: up to the sagitta r(1 − cos(π/columns))), not
// float noise (~10^-7 of the scene's size). A filter callback applies the same double t
// to the query's range: a candidate whose double t is not in (t_min, t_max) is rejected,
// so a shadow ray that leaves a surface (the renderer offsets it along the geometric
// normal) never finds the triangle it left, however float rounds.
//
// What a hit reports:
//   geometric_normal  the triangle's, unit, outward (triangles are counter-clockwise seen
//                     from outside);
//   shading_normal    the barycentric interpolation of the vertex normals, renormalised;
//   u, v_m            the barycentric interpolation of the vertex uvs; tessellate gives the
//                     seam column u = 1 on the triangles before it (and u = 0 after), so no
//                     triangle spans the wrap; u = 1 is reported as 0 ([0, 1) as skin.h). On a
//                     cap fan u interpolates toward the centre vertex's 0 and is not the
//                     angle (the analytic cap reports the angle);
//   dp_du, dp_dv      from the triangle's uv Jacobian (pbrt's triangle differentials),
//                     metres per turn and per metre; zero where the uvs are degenerate (a
//                     cap fan: every vertex at one v_m);
//   ids               plant, chain, segment, material and frustum of the triangle's frustum.
//
// Thread-safe for concurrent queries.
#pragma once

#include <memory>
#include <span>
#include <string>

#include "core/geometry/skin.h"
#include "core/geometry/surface.h"
#include "core/geometry/tessellate.h"

namespace sylva {

class MeshTracer final : public SceneTracer {
 public:
  // Builds Embree triangles over `mesh` (taken). Its triangle_frustum indexes `frusta`,
  // whose plant is `plant_of_frustum`; both must outlive the tracer unchanged. `level` and
  // `displaced` only label describe(): "GS m" or "GS+R m".
  MeshTracer(TriangleMesh mesh, std::span<const Frustum> frusta, std::span<const uint32_t> plant_of_frustum,
             int level, bool displaced = false);
  ~MeshTracer() override;
  MeshTracer(const MeshTracer&) = delete;
  MeshTracer& operator=(const MeshTracer&) = delete;

  SurfaceHit nearest(const Ray& ray, double t_min, double t_max) const override;
  bool any(const Ray& ray, double t_min, double t_max) const override;
  // The mesh's arrays (capacity) plus what Embree allocated (its memory monitor); the
  // frusta and plant table, shared with the scene, are not counted.
  Aabb bounds() const override;  // the vertices'
  size_t memory_bytes() const override;
  // "Embree triangles, N triangles (GS m)".
  std::string describe() const override;

  const TriangleMesh& mesh() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sylva
