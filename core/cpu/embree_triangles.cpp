// embree_triangles.cpp — see embree_triangles.h. Ray–triangle in double: Möller & Trumbore
// 1997, "Fast, minimum storage ray-triangle intersection".
#include "core/cpu/embree_triangles.h"

#include <glm/geometric.hpp>

namespace sylva {

TriangleCrossing cross_triangle(const Ray& ray, const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2) {
  // Edges from p0 and the origin relative to p0: differences of nearby doubles, exact
  // enough however far the scene is from the world's origin.
  const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, s = ray.origin - p0;
  const glm::dvec3 pvec = glm::cross(ray.direction, e2);
  TriangleCrossing c;
  c.det = glm::dot(e1, pvec);
  if (c.det == 0) return c;
  const double inv = 1 / c.det;
  const glm::dvec3 qvec = glm::cross(s, e1);
  c.b1 = glm::dot(s, pvec) * inv;
  c.b2 = glm::dot(ray.direction, qvec) * inv;
  c.t = glm::dot(e2, qvec) * inv;
  return c;
}

TriangleQuery start_triangle_query(const glm::dvec3* positions, const uint32_t* indices, const Ray& ray,
                                   double t_min, double t_max) {
  TriangleQuery q{};
  rtcInitIntersectContext(&q.embree);
  q.positions = positions;
  q.indices = indices;
  q.ray = ray;
  q.t_min = t_min;
  q.t_max = t_max;
  return q;
}

void triangle_range_filter(const RTCFilterFunctionNArguments* args) {
  const auto* q = reinterpret_cast<const TriangleQuery*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (!args->valid[i]) continue;
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    const uint32_t* tri = &q->indices[3 * static_cast<size_t>(prim)];
    const TriangleCrossing c = cross_triangle(q->ray, q->positions[tri[0]], q->positions[tri[1]], q->positions[tri[2]]);
    if (!in_query_range(c, *q)) args->valid[i] = 0;
  }
}

RTCGeometry new_filtered_triangles(RTCDevice device, const glm::dvec3* positions, size_t vertex_count,
                                   const uint32_t* indices, size_t triangle_count, const glm::dvec3& centre,
                                   RTCFilterFunctionN filter) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertex_count));
  for (size_t i = 0; i < vertex_count; ++i) {
    const glm::dvec3 p = positions[i] - centre;
    v[3 * i] = static_cast<float>(p.x), v[3 * i + 1] = static_cast<float>(p.y), v[3 * i + 2] = static_cast<float>(p.z);
  }
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices, 0, 3 * sizeof(uint32_t),
                             triangle_count);
  rtcSetGeometryIntersectFilterFunction(geom, filter);
  rtcSetGeometryOccludedFilterFunction(geom, filter);
  return geom;
}

}  // namespace sylva
