// frustum_tracer.cpp — see frustum_tracer.h.
#include "core/cpu/frustum_tracer.h"

#include "core/cpu/bvh.h"  // frustum_bounds

#include <glm/geometric.hpp>
#include <limits>
#include <optional>
#include <numbers>
#include <utility>

namespace sylva {

namespace {

// Around: a full turn is the circumference at radius `r`. Along: one metre of arc length
// moves the point about one metre along the generator line.
void set_tangents(SurfaceHit& s, const FrustumShape& shape, const FrustumHit& hit, double r) {
  s.dp_du = (2 * std::numbers::pi * std::max(r, 0.0)) * glm::cross(shape.axis, hit.radial);
  s.dp_dv = glm::normalize(shape.axis + shape.slope() * hit.radial);
}

void set_ids(SurfaceHit& s, const Frustum& f) {
  s.chain = f.chain;
  s.segment = f.segment;
  s.material = f.material;
}

}  // namespace

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
  set_tangents(s, f.shape, hit, f.shape.radius_at(hit.y));
  set_ids(s, f);
  return s;
}

SurfaceHit describe_relief_hit(const Ray& ray, const Frustum& f, const FrustumHit& hit,
                               const CustomHitDetail& detail) {
  SurfaceHit s;
  s.t = hit.t;
  s.position = ray.origin + hit.t * ray.direction;
  s.geometric_normal = hit.normal;
  s.shading_normal = detail.shading_normal;
  s.u = detail.u;
  s.v_m = detail.v_m;
  const glm::dvec3 from_base = s.position - f.shape.base;
  const glm::dvec3 perp = from_base - glm::dot(from_base, f.shape.axis) * f.shape.axis;
  set_tangents(s, f.shape, hit, glm::length(perp));
  set_ids(s, f);
  return s;
}

FrustumHit FrustumTracer::ReliefIntersector::intersect(uint32_t index, const Ray& ray, double t_min,
                                                       double t_max, CustomHitDetail* detail) const {
  const Frustum& f = tracer_.frusta_[index];
  const ReliefMap& map = tracer_.relief_.plants[tracer_.plant_of_frustum_[index]];
  // On a crotch's frusta the relief fades into the fillet (crotch_tracer.h).
  const CrotchBalls* balls = tracer_.crotches_.get();
  const std::optional<CrotchReliefFade> fade =
      balls && balls->fades(index) ? std::optional<CrotchReliefFade>(std::in_place, *balls, index) : std::nullopt;
  const ReliefHit h = intersect_relief(ray, f, map, tracer_.relief_.options, t_min, t_max, detail != nullptr,
                                       fade ? &*fade : nullptr);
  if (detail && h.hit.hit()) *detail = {h.u, h.v_m, h.shading_normal};
  return h.hit;
}

namespace {

bool has_relief(const ReliefMap& map) { return map.field && map.depth_m > 0; }

}  // namespace

FrustumTracer::FrustumTracer(std::span<const Frustum> frusta, std::span<const uint32_t> plant_of_frustum,
                             SceneRelief relief, std::shared_ptr<const CrotchBalls> crotches)
    : frusta_(frusta),
      plant_of_frustum_(plant_of_frustum),
      relief_(std::move(relief)),
      shell_m_([&] {
        std::vector<double> shell;
        bool any_relief = false;
        for (const ReliefMap& map : relief_.plants) any_relief = any_relief || has_relief(map);
        if (!any_relief) return shell;  // no relief: no custom frusta, the exact path only
        shell.assign(frusta.size(), 0.0);
        for (size_t i = 0; i < frusta.size(); ++i) {
          const uint32_t plant = plant_of_frustum[i];
          if (plant >= relief_.plants.size() || !has_relief(relief_.plants[plant]) ||
              frusta[i].kind != FrustumKind::segment || frusta[i].material != 0)  // bark: wood only
            continue;
          // The accelerator grows the box by the thicker end's shell (0: a zero frustum).
          const ShellDepths d = relief_shell_depths(frusta[i].shape, relief_.plants[plant].depth_m,
                                                    relief_.options.max_depth_per_radius);
          shell[i] = std::max(d.lower_m, d.upper_m);
        }
        return shell;
      }()),
      intersector_(*this),
      crotches_(crotches && crotches->count() > 0 ? std::move(crotches) : nullptr),
      accel_(frusta, CustomFrusta{shell_m_, &intersector_}, crotches_.get()) {
  std::vector<char> plant_has_relief(relief_.plants.size(), 0);
  for (size_t i = 0; i < shell_m_.size(); ++i)
    if (shell_m_[i] > 0) ++relief_frusta_, plant_has_relief[plant_of_frustum_[i]] = 1;
  for (char c : plant_has_relief) relief_plants_ += c;
  for (size_t i = 0; i < frusta_.size(); ++i) {
    Aabb b = frustum_bounds(frusta_[i].shape);
    const double shell = i < shell_m_.size() ? shell_m_[i] : 0.0;
    b.lo -= glm::dvec3(shell), b.hi += glm::dvec3(shell);
    grow(bounds_, b);
  }
  if (crotches_) grow(bounds_, crotches_->all_bounds());
}

SurfaceHit FrustumTracer::nearest(const Ray& ray, double t_min, double t_max) const {
  CustomHitDetail detail;
  ExtraHit fillet;
  const BvhHit hit = accel_.nearest(ray, t_min, t_max, &detail, crotches_ ? &fillet : nullptr);
  const double t_exact = hit.hit_any() ? hit.hit.t : std::numeric_limits<double>::infinity();
  if (fillet.hit() && crotches_->in_front(fillet.index, ray, fillet.t, t_exact))
    return crotches_->describe(fillet.index, ray, fillet.t, plant_of_frustum_);
  if (!hit.hit_any()) return {};
  const Frustum& f = frusta_[hit.frustum];
  SurfaceHit s = !shell_m_.empty() && shell_m_[hit.frustum] > 0 ? describe_relief_hit(ray, f, hit.hit, detail)
                                                                 : describe_frustum_hit(ray, f, hit.hit);
  s.plant = plant_of_frustum_[hit.frustum];
  s.frustum = hit.frustum;
  return s;
}

bool FrustumTracer::any(const Ray& ray, double t_min, double t_max) const {
  return accel_.any(ray, t_min, t_max);
}

size_t FrustumTracer::memory_bytes() const {
  return accel_.memory_bytes() + frusta_.size_bytes() + plant_of_frustum_.size_bytes() +
         shell_m_.size() * sizeof(double) + (crotches_ ? crotches_->memory_bytes() : 0);
}

std::string FrustumTracer::describe() const {
  std::string d = "Embree user geometry, " + std::to_string(frusta_.size()) + " analytic frusta";
  if (relief_frusta_) d += " (" + std::to_string(relief_frusta_) + " relief-mapped)";
  if (crotches_) d += ", " + std::to_string(crotches_->count()) + " blended crotches";
  return d;
}

}  // namespace sylva
