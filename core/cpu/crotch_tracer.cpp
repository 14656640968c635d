// crotch_tracer.cpp — see crotch_tracer.h.
#include "core/cpu/crotch_tracer.h"

#include <algorithm>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>

namespace sylva {

namespace {

// Around: a full turn is the circumference at the point's radius; along: the axis.
void set_tangents(SurfaceHit& s, const FrustumShape& f) {
  const glm::dvec3 w = s.position - f.base;
  const glm::dvec3 perp = w - glm::dot(w, f.axis) * f.axis;
  const double r = glm::length(perp);
  const glm::dvec3 radial = r > 0 ? perp / r : glm::dvec3(0);
  s.dp_du = (2 * std::numbers::pi * r) * glm::cross(f.axis, radial);
  s.dp_dv = glm::normalize(f.axis + f.slope() * radial);
}

}  // namespace

CrotchBalls::CrotchBalls(std::vector<Crotch> crotches, std::span<const Frustum> frusta)
    : crotches_(std::move(crotches)), frusta_(frusta) {}

Aabb CrotchBalls::bounds(uint32_t index) const {
  const Crotch& c = crotches_[index];
  return {c.centre - glm::dvec3(c.radius), c.centre + glm::dvec3(c.radius)};
}

std::optional<double> CrotchBalls::intersect(uint32_t index, const Ray& ray, double t_min, double t_max) const {
  const std::optional<CrotchHit> h = march_crotch(crotches_[index], frusta_, ray, t_min, t_max, /*fillet_only=*/true);
  return h ? std::optional<double>(h->t) : std::nullopt;
}

bool CrotchBalls::occludes(uint32_t index, const Ray& ray, double t_min, double t_max) const {
  const Crotch& c = crotches_[index];
  return march_crotch(c, frusta_, ray, t_min + 1e-3 * c.radius / glm::length(ray.direction), t_max, true)
      .has_value();
}

bool CrotchBalls::in_front(uint32_t index, const Ray& ray, double t, double t_exact) const {
  return t < t_exact - 1e-6 * crotches_[index].radius / glm::length(ray.direction);
}

SurfaceHit CrotchBalls::describe(uint32_t index, const Ray& ray, double t,
                                 std::span<const uint32_t> plant_of_frustum) const {
  const Crotch& c = crotches_[index];
  SurfaceHit s;
  s.t = t;
  s.position = ray.origin + s.t * ray.direction;
  const CrotchShade shade = crotch_shade(c, frusta_, s.position);
  const bool parent = shade.h >= 0.5;
  const Frustum& f = frusta_[parent ? shade.parent_frustum : shade.lateral_frustum];  // frustum_at's
  const Frustum& other = frusta_[parent ? shade.lateral_frustum : shade.parent_frustum];
  s.geometric_normal = s.shading_normal = shade.normal;
  s.u = parent ? shade.parent_uv.u : shade.lateral_uv.u;
  s.v_m = parent ? shade.parent_uv.v_m : shade.lateral_uv.v_m;
  s.u_other = parent ? shade.lateral_uv.u : shade.parent_uv.u;
  s.v_m_other = parent ? shade.lateral_uv.v_m : shade.parent_uv.v_m;
  s.blend = std::max(shade.h, 1 - shade.h);
  s.material_other = other.material;
  set_tangents(s, f.shape);
  s.frustum = parent ? shade.parent_frustum : shade.lateral_frustum;
  s.plant = plant_of_frustum[s.frustum];
  s.chain = f.chain;
  s.segment = f.segment;
  s.material = f.material;
  return s;
}

uint32_t CrotchBalls::frustum_at(uint32_t index, const glm::dvec3& p) const {
  const CrotchShade shade = crotch_shade(crotches_[index], frusta_, p);
  return shade.h >= 0.5 ? shade.parent_frustum : shade.lateral_frustum;
}

Aabb CrotchBalls::all_bounds() const {
  Aabb box = empty_box();
  for (uint32_t i = 0; i < count(); ++i) grow(box, bounds(i));
  return box;
}

size_t CrotchBalls::memory_bytes() const {
  size_t bytes = crotches_.capacity() * sizeof(Crotch);
  for (const Crotch& c : crotches_)
    bytes += (c.parent_frusta.capacity() + c.lateral_frusta.capacity()) * sizeof(uint32_t) +
             c.depth.capacity() * sizeof(double);
  return bytes;
}

}  // namespace sylva
