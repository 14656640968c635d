// crotch_tracer.cpp — see crotch_tracer.h.
#include "core/cpu/crotch_tracer.h"

#include <algorithm>
#include <cmath>
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
    : crotches_(std::move(crotches)), frusta_(frusta), of_frustum_(crotches_of_frusta(crotches_, frusta.size())) {}

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
  s.frustum = heavier_frustum(shade);
  const Frustum& f = frusta_[s.frustum];
  const Frustum& other = frusta_[parent ? shade.lateral_frustum : shade.parent_frustum];
  s.geometric_normal = s.shading_normal = shade.normal;
  s.u = parent ? shade.parent_uv.u : shade.lateral_uv.u;
  s.v_m = parent ? shade.parent_uv.v_m : shade.lateral_uv.v_m;
  s.u_other = parent ? shade.lateral_uv.u : shade.parent_uv.u;
  s.v_m_other = parent ? shade.lateral_uv.v_m : shade.parent_uv.v_m;
  s.blend = std::max(shade.h, 1 - shade.h);
  s.material_other = other.material;
  set_tangents(s, f.shape);
  s.plant = plant_of_frustum[s.frustum];
  s.chain = f.chain;
  s.segment = f.segment;
  s.material = f.material;
  return s;
}

uint32_t CrotchBalls::frustum_at(uint32_t index, const glm::dvec3& p) const {
  return heavier_frustum(crotch_shade(crotches_[index], frusta_, p));
}

bool CrotchBalls::fades(uint32_t frustum) const { return !of_frustum_.of(frustum).empty(); }

double CrotchBalls::relief_fade(uint32_t frustum, const glm::dvec3& p) const {
  return relief_fade_at(crotches_, of_frustum_.of(frustum), frusta_, p);
}

double CrotchBalls::fade_step_m(uint32_t frustum) const {
  double k = std::numeric_limits<double>::infinity();
  for (uint32_t i : of_frustum_.of(frustum)) k = std::min(k, crotches_[i].k);
  return std::isfinite(k) ? 1e-3 * k : 1e-6;
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
  return bytes + of_frustum_.bytes();
}

BvhHit nearest_wood(const FrustumAccel& accel, const CrotchBalls* crotches, const Ray& ray, double t_min,
                    double t_max) {
  ExtraHit fillet;
  BvhHit hit = accel.nearest(ray, t_min, t_max, nullptr, crotches ? &fillet : nullptr);
  const double t_exact = hit.hit_any() ? hit.hit.t : std::numeric_limits<double>::infinity();
  if (fillet.hit() && crotches->in_front(fillet.index, ray, fillet.t, t_exact)) {
    hit.hit.kind = FrustumHitKind::side;
    hit.hit.t = fillet.t;
    hit.frustum = crotches->frustum_at(fillet.index, ray.origin + fillet.t * ray.direction);
  }
  return hit;
}

}  // namespace sylva
