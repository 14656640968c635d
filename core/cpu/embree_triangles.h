// embree_triangles.h — what the Embree triangle tracers (mesh_accel.cpp: the polygon
// baseline; leaf_tracer.cpp: the leaves) share: Embree finds the candidate triangle in
// float, and everything about a hit is decided again in double against the triangle's
// double vertices and the caller's double ray (Möller & Trumbore 1997). A filter callback
// keeps a candidate only where its double t lies in the query's (t_min, t_max), so a
// shadow ray leaving a surface never finds the triangle it left, however float rounds.
//
// Internal to core/cpu (includes Embree).
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <glm/vec3.hpp>

#include "core/geometry/ray_frustum.h"

namespace sylva {

// A ray against one triangle in double, without an inside test: t where the ray crosses
// the triangle's plane, and the barycentrics (b1, b2) of that point (b0 = 1 − b1 − b2).
// det == 0: the ray is parallel to the plane (t is then meaningless).
struct TriangleCrossing {
  double t = 0, b1 = 0, b2 = 0, det = 0;
};
TriangleCrossing cross_triangle(const Ray& ray, const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2);

// The intersect context Embree passes to the filter, extended with the double query
// (Embree 3 allows a context to be embedded first).
struct TriangleQuery {
  RTCIntersectContext embree;
  const glm::dvec3* positions;  // the triangles' double vertices
  const uint32_t* indices;      // 3 per triangle
  Ray ray;
  double t_min;
  double t_max;
};
TriangleQuery start_triangle_query(const glm::dvec3* positions, const uint32_t* indices, const Ray& ray,
                                   double t_min, double t_max);

// The filter (intersect and occluded alike): keeps a float candidate only if its double
// t lies in the query's (t_min, t_max).
void triangle_range_filter(const RTCFilterFunctionNArguments* args);

// Whether a candidate's double crossing `c` lies in the query's range (the range filter's test).
inline bool in_query_range(const TriangleCrossing& c, const TriangleQuery& q) {
  return c.det != 0 && c.t > q.t_min && c.t < q.t_max;
}

// Makes the Embree triangle geometry over `positions` (relative to `centre` in float) and
// `indices` (shared, not copied: they must outlive the geometry) with `filter` (intersect
// and occluded alike; the range filter, or one that applies it and more).
RTCGeometry new_filtered_triangles(RTCDevice device, const glm::dvec3* positions, size_t vertex_count,
                                   const uint32_t* indices, size_t triangle_count, const glm::dvec3& centre,
                                   RTCFilterFunctionN filter = triangle_range_filter);

}  // namespace sylva
