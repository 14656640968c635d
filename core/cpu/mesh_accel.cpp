// mesh_accel.cpp — Embree 3 triangles with hits described in double (see mesh_accel.h).
// Ray–triangle in double: Möller & Trumbore 1997, "Fast, minimum storage ray-triangle
// intersection"; texture differentials as pbrt-v4's Triangle (Pharr, Jakob, Humphreys).
#include "core/cpu/mesh_accel.h"

#include "core/cpu/embree_scene.h"
#include "core/cpu/embree_triangles.h"


#include <algorithm>
#include <atomic>
#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <limits>
#include <stdexcept>

namespace sylva {

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

}  // namespace

struct MeshTracer::Impl {
  TriangleMesh mesh;
  std::span<const Frustum> frusta;
  std::span<const uint32_t> plant_of_frustum;
  int level = 0;
  bool displaced = false;
  glm::dvec3 centre{0, 0, 0};
  Aabb bounds = empty_box();
  EmbreeScene embree{/*need_filter_functions=*/true};

  TriangleQuery start_query(const Ray& ray, double t_min, double t_max) const {
    return start_triangle_query(mesh.positions.data(), mesh.indices.data(), ray, t_min, t_max);
  }

  RTCRay embree_ray(const Ray& ray, double t_min, double t_max) const {
    return EmbreeScene::embree_ray(ray, centre, t_min, t_max);
  }
};

MeshTracer::MeshTracer(TriangleMesh mesh, std::span<const Frustum> frusta, std::span<const uint32_t> plant_of_frustum,
                       int level, bool displaced)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.mesh = std::move(mesh);
  m.frusta = frusta;
  m.plant_of_frustum = plant_of_frustum;
  m.level = level;
  m.displaced = displaced;
  const TriangleMesh& tm = m.mesh;
  if (tm.indices.size() % 3 != 0 || tm.triangle_frustum.size() != tm.triangle_count() ||
      tm.uvs.size() != tm.positions.size() || tm.normals.size() != tm.positions.size())
    throw std::logic_error("MeshTracer: inconsistent TriangleMesh arrays");
  for (uint32_t f : tm.triangle_frustum)
    if (f >= frusta.size() || f >= plant_of_frustum.size())
      throw std::logic_error("MeshTracer: triangle_frustum past the frusta it indexes");

  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const glm::dvec3& p : tm.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  m.centre = tm.positions.empty() ? glm::dvec3(0) : 0.5 * (lo + hi);
  if (!tm.positions.empty()) m.bounds = {lo, hi};
  if (tm.triangle_count() > 0) {
    // The mesh's own index array, shared (not copied): it lives as long as the tracer.
    RTCGeometry geom = new_filtered_triangles(m.embree.device(), tm.positions.data(), tm.positions.size(),
                                              tm.indices.data(), tm.triangle_count(), m.centre);
    m.embree.attach(geom);
  }
  m.embree.commit();
}

MeshTracer::~MeshTracer() = default;

const TriangleMesh& MeshTracer::mesh() const { return impl_->mesh; }

SurfaceHit MeshTracer::nearest(const Ray& ray, double t_min, double t_max) const {
  const Impl& m = *impl_;
  TriangleQuery q = m.start_query(ray, t_min, t_max);
  RTCRayHit rh{};
  rh.ray = m.embree_ray(ray, t_min, t_max);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(m.embree.scene(), &q.embree, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};

  const TriangleMesh& tm = m.mesh;
  const uint32_t prim = rh.hit.primID;
  const uint32_t i0 = tm.indices[3 * size_t{prim}], i1 = tm.indices[3 * size_t{prim} + 1],
                 i2 = tm.indices[3 * size_t{prim} + 2];
  const glm::dvec3 &p0 = tm.positions[i0], &p1 = tm.positions[i1], &p2 = tm.positions[i2];
  const TriangleCrossing c = cross_triangle(ray, p0, p1, p2);  // det != 0: the filter kept it
  // Float said inside, double may say just outside an edge: clamp into the triangle.
  double b1 = std::max(c.b1, 0.0), b2 = std::max(c.b2, 0.0);
  if (b1 + b2 > 1) {
    const double sum = b1 + b2;
    b1 /= sum, b2 /= sum;
  }
  const double b0 = 1 - b1 - b2;

  SurfaceHit s;
  s.t = c.t;
  s.position = ray.origin + c.t * ray.direction;
  const glm::dvec3 ng = glm::cross(p1 - p0, p2 - p0);
  s.geometric_normal = ng / glm::length(ng);
  const glm::dvec3 ns = b0 * tm.normals[i0] + b1 * tm.normals[i1] + b2 * tm.normals[i2];
  const double ns_length = glm::length(ns);
  s.shading_normal = ns_length > 0 ? ns / ns_length : s.geometric_normal;
  const glm::dvec2 &uv0 = tm.uvs[i0], &uv1 = tm.uvs[i1], &uv2 = tm.uvs[i2];
  const glm::dvec2 uv = b0 * uv0 + b1 * uv1 + b2 * uv2;
  s.u = uv.x - std::floor(uv.x);
  s.v_m = uv.y;
  // dp = dp_du·du + dp_dv·dv across the triangle: solve the 2×2 system of its edges.
  const glm::dvec2 duv02 = uv0 - uv2, duv12 = uv1 - uv2;
  const glm::dvec3 dp02 = p0 - p2, dp12 = p1 - p2;
  const double det = duv02.x * duv12.y - duv02.y * duv12.x;
  if (std::abs(det) > 1e-12 * (glm::dot(duv02, duv02) + glm::dot(duv12, duv12))) {
    const double inv = 1 / det;
    s.dp_du = (duv12.y * dp02 - duv02.y * dp12) * inv;
    s.dp_dv = (duv02.x * dp12 - duv12.x * dp02) * inv;
  }
  const uint32_t f = tm.triangle_frustum[prim];
  const Frustum& fr = m.frusta[f];
  s.plant = m.plant_of_frustum[f];
  s.chain = fr.chain;
  s.segment = fr.segment;
  s.material = fr.material;
  s.frustum = f;
  return s;
}

bool MeshTracer::any(const Ray& ray, double t_min, double t_max) const {
  const Impl& m = *impl_;
  TriangleQuery q = m.start_query(ray, t_min, t_max);
  RTCRay r = m.embree_ray(ray, t_min, t_max);
  rtcOccluded1(m.embree.scene(), &q.embree, &r);
  return r.tfar == -kInfF;
}

Aabb MeshTracer::bounds() const { return impl_->bounds; }

size_t MeshTracer::memory_bytes() const {
  return impl_->mesh.memory_bytes() + impl_->embree.memory_bytes();
}

std::string MeshTracer::describe() const {
  return "Embree triangles, " + std::to_string(impl_->mesh.triangle_count()) + " triangles (GS" +
         (impl_->displaced ? "+R " : " ") + std::to_string(impl_->level) + ")";
}

}  // namespace sylva
