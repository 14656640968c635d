// frustum_tracer.cpp — see frustum_tracer.h.
#include "core/frustum_tracer.h"

#include <glm/geometric.hpp>
#include <numbers>

namespace sylva {

SurfaceHit describe_frustum_hit(const Ray& ray, const Frustum& f, const FrustumHit& hit) {
  SurfaceHit s;
  s.t = hit.t;
  s.position = ray.origin + hit.t * ray.direction;
  s.geometric_normal = hit.normal;
  s.shading_normal = hit.kind == FrustumHitKind::side
                         ? surface_normal(f, s.position, NormalMode::interpolated)
                         : hit.normal;
  const SurfaceUV uv = surface_uv(f, s.position);
  s.u = uv.u;
  s.v_m = uv.v_m;
  const FrustumShape& shape = f.shape;
  // Around: a full turn is the circumference at the hit's axial coordinate. Along: one
  // metre of arc length moves the point about one metre along the generator line.
  const double r = std::max(shape.radius_at(hit.y), 0.0);
  s.dp_du = (2 * std::numbers::pi * r) * glm::cross(shape.axis, hit.radial);
  s.dp_dv = glm::normalize(shape.axis + shape.slope() * hit.radial);
  s.chain = f.chain;
  s.segment = f.segment;
  s.material = f.material;
  return s;
}

FrustumTracer::FrustumTracer(std::span<const Frustum> frusta, std::span<const uint32_t> plant_of_frustum)
    : frusta_(frusta), plant_of_frustum_(plant_of_frustum), accel_(frusta) {}

SurfaceHit FrustumTracer::nearest(const Ray& ray, double t_min, double t_max) const {
  const BvhHit hit = accel_.nearest(ray, t_min, t_max);
  if (!hit.hit_any()) return {};
  SurfaceHit s = describe_frustum_hit(ray, frusta_[hit.frustum], hit.hit);
  s.plant = plant_of_frustum_[hit.frustum];
  s.frustum = hit.frustum;
  return s;
}

bool FrustumTracer::any(const Ray& ray, double t_min, double t_max) const {
  return accel_.any(ray, t_min, t_max);
}

size_t FrustumTracer::memory_bytes() const {
  return accel_.memory_bytes() + frusta_.size_bytes() + plant_of_frustum_.size_bytes();
}

std::string FrustumTracer::describe() const {
  return "Embree user geometry, " + std::to_string(frusta_.size()) + " analytic frusta";
}

}  // namespace sylva
