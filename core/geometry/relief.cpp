// relief.cpp — relief mapping of conical frusta, Bhagvat et al. 2009 sec. 3 (eq. 11–12); see relief.h.
//
// Numerics follow ray_frustum.cpp: the ray is re-centred on the point nearest the
// frustum's midpoint in compensated arithmetic (so an eye 10⁶ m away keeps the relief's
// millimetres), plane offsets are taken relative to the base in compensated arithmetic,
// the cone's quadratic is the apex-free one with the regrouped discriminant and the
// stable root pair. The re-centring and the compensated plane offsets are
// compensated.h's, the quadratic cone_quadric.h's: the very code ray_frustum.cpp uses.
#include "core/geometry/relief.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>

#include "core/geometry/recentre.h"
#include "core/geometry/solid_bounds.h"
#include "core/util/math.h"

namespace sylva {
namespace {

constexpr double kMaxNormalFootprint = 0.5;  // texture units: beyond, the normal is the base one

using compensated::plane_offset_from;

bool shape_rejected(const FrustumShape& shape) {
  return !(shape.length > 0) || !std::isfinite(shape.length) || !(shape.radius0 >= 0) ||
         !(shape.radius1 >= 0) || !std::isfinite(shape.radius0) || !std::isfinite(shape.radius1);
}

// The ray in the frustum's frame: origin relative to the base and moved along the ray to
// the point nearest the midpoint; t = shift + t_local. Exactly intersect_frustum's.
struct LocalRay {
  glm::dvec3 origin{0, 0, 0};
  glm::dvec3 dir{0, 0, 0};
  double shift = 0;
};

LocalRay local_ray(const Ray& ray, const FrustumShape& shape) {
  const compensated::RecentredRay recentred = compensated::recentre(ray, shape);
  return {recentred.origin, ray.direction, recentred.shift};
}

using solid_bounds::Bounds;

// The solid interval in local t (before clamping to the caller's range).
struct LocalInterval {
  bool hit = false;
  double lo = 0, hi = 0;
  SolidBoundary lo_by = SolidBoundary::range, hi_by = SolidBoundary::range;
};

LocalInterval local_solid_interval(const FrustumShape& s, const LocalRay& r, double lower_offset,
                                   double upper_offset) {
  LocalInterval out;
  const glm::dvec3& o = r.origin;
  const glm::dvec3& d = r.dir;
  Bounds b;
  // Slab: dot(nl, p) >= lower_offset, dot(nu, p) <= upper_offset.
  if (!b.linear_at_least(glm::dot(s.lower.normal, d), lower_offset - glm::dot(s.lower.normal, o),
                       SolidBoundary::lower))
    return out;
  if (!b.linear_at_least(-glm::dot(s.upper.normal, d), glm::dot(s.upper.normal, o) - upper_offset,
                       SolidBoundary::upper))
    return out;
  // Nappe: r(y) = ρ + k·dy·t >= 0.
  const double slope = s.slope();
  const double origin_y = glm::dot(o, s.axis);
  const double dir_y = glm::dot(d, s.axis);
  const double rho = s.radius0 + slope * origin_y;
  const double slope_dir_y = slope * dir_y;
  if (!b.linear_at_least(slope_dir_y, -rho, SolidBoundary::side)) return out;
  // Cone: f(t) = A t² + 2 half_b t + C <= 0, the quadric intersect_frustum solves.
  const glm::dvec3 origin_perp = o - origin_y * s.axis;
  const glm::dvec3 dir_perp = d - dir_y * s.axis;
  if (!b.inside_cone(origin_perp, dir_perp, rho, slope_dir_y, solid_bounds::SecondRoot::by_error_bounds)) return out;
  if (!std::isfinite(b.lo) || !std::isfinite(b.hi)) return out;  // degenerate (NaN, unbounded)
  out.hit = true;
  out.lo = b.lo, out.hi = b.hi;
  out.lo_by = b.lo_by, out.hi_by = b.hi_by;
  return out;
}

// The caller's [t_min, t_max] applied in global t (t = shift + t_local), as RayRange does.
SolidInterval clamp_interval(const LocalInterval& l, double shift, double t_min, double t_max) {
  SolidInterval out;
  if (!l.hit) return out;
  out.t_enter = shift + l.lo;
  out.t_exit = shift + l.hi;
  out.enter = l.lo_by;
  out.exit = l.hi_by;
  if (!(out.t_enter > t_min)) out.t_enter = t_min, out.enter = SolidBoundary::range;
  if (!(out.t_exit < t_max)) out.t_exit = t_max, out.exit = SolidBoundary::range;
  out.hit = out.t_enter <= out.t_exit && std::isfinite(out.t_enter) && std::isfinite(out.t_exit);
  return out;
}

double wrap_turns(double turns) {
  const double w = turns - std::floor(turns);
  return w >= 1.0 ? 0.0 : w;
}

// Everything the marcher needs about one frustum, in its local frame.
struct Marcher {
  const Frustum& frustum;
  const ReliefMap& map;
  const ReliefOptions& options;
  const ReliefFade* fade;  // null: none
  LocalRay ray;
  glm::dvec3 axis, e0, e1;
  double slope, radius0, length;
  double depth0, depth_slope;         // shell thickness d(y) = depth0 + depth_slope·y
  double lower_offset, upper_offset;  // relative to the base
  // v_m at the interval's ends (linear v).
  double t_enter = 0, t_exit = 0, v_enter = 0, v_exit = 0;

  // The sample at local t.
  struct Point {
    glm::dvec3 p, perp;
    double y, rho, r_inner, depth;
    // Eq. 11–12: the relief height of the point (its constant-w cone).
    double w() const { return depth > 0 ? (rho - r_inner) / depth : (rho <= r_inner ? 0.0 : 2.0); }
  };
  Point point(double t_local) const {
    Point q;
    q.p = ray.origin + t_local * ray.dir;
    q.y = glm::dot(q.p, axis);
    q.perp = q.p - q.y * axis;
    q.rho = std::sqrt(glm::dot(q.perp, q.perp));
    q.r_inner = radius0 + slope * q.y;
    q.depth = depth0 + depth_slope * q.y;
    return q;
  }

  glm::dvec3 radial(const Point& q) const { return q.rho > 0 ? q.perp / q.rho : e0; }

  // Eq. 7 on the concentric cone through q: the cone of constant w, radius
  // r(y) + w·d(y) (the paper's "new cone with P lying exactly on its surface").
  double exact_v_m(const Point& q) const {
    const glm::dvec3 e = radial(q);
    const double w = q.w();
    const double r0 = radius0 + w * depth0, k = slope + w * depth_slope;
    auto crossing = [&](const Plane& plane, double offset) {
      const double nd = glm::dot(plane.normal, e);
      return (offset - r0 * nd) / (glm::dot(plane.normal, axis) + k * nd);
    };
    const double y_lower = crossing(frustum.shape.lower, lower_offset);
    const double y_upper = crossing(frustum.shape.upper, upper_offset);
    const double v = (q.y - y_lower) / (y_upper - y_lower);
    return frustum.v_lower_m + v * (frustum.v_upper_m - frustum.v_lower_m);
  }

  double v_m_at(const Point& q, double t_local) const {
    if (options.exact_v) return exact_v_m(q);
    if (!(t_exit > t_enter)) return v_enter;
    return v_enter + (t_local - t_enter) / (t_exit - t_enter) * (v_exit - v_enter);
  }

  double u_at(const Point& q, double v_m) const {
    const double raw = std::atan2(glm::dot(q.perp, e1), glm::dot(q.perp, e0)) / (2 * kPi);
    return wrap_turns(raw - frustum.u_offset + frustum.twist_rad_per_m * v_m / (2 * kPi));
  }

  double height(double u, double v_m) const {
    const double h = map.field->height(u * map.u_repeat, v_m * map.v_per_metre);
    return std::clamp(h, 0.0, 1.0);
  }

  // Whether the sample at local t is inside the relief solid; on_shell: the sample is an
  // interval end on the outer shell, where w = 1 exactly.
  bool inside(double t_local, bool on_shell) const {
    const Point q = point(t_local);
    const double w = on_shell ? 1.0 : q.w();
    if (w < 0) return true;   // below the inner cone: H >= 0 >= w, no lookup
    if (w > 1) return false;  // above the shell (rounding): H <= 1 < w
    const double v_m = v_m_at(q, t_local);
    const double scale = fade ? std::clamp(fade->scale(frustum.shape.base + q.p), 0.0, 1.0) : 1.0;
    if (w > scale) return false;  // above the faded relief's top: no lookup
    return w <= scale * height(u_at(q, v_m), v_m);
  }
};

}  // namespace

ShellDepths relief_shell_depths(const FrustumShape& inner, double depth_m, double max_depth_per_radius) {
  const double f = std::max(0.0, max_depth_per_radius);
  return {std::min(depth_m, f * inner.radius0), std::min(depth_m, f * inner.radius1)};
}

FrustumShape relief_shell(const FrustumShape& inner, double depth_m, double max_depth_per_radius) {
  const ShellDepths d = relief_shell_depths(inner, depth_m, max_depth_per_radius);
  FrustumShape s = inner;
  s.radius0 += d.lower_m;
  s.radius1 += d.upper_m;
  return s;
}

SolidInterval frustum_solid_interval(const Ray& ray, const FrustumShape& shape, double t_min,
                                     double t_max) {
  if (shape_rejected(shape) || !(glm::dot(ray.direction, ray.direction) > 0)) return {};
  const LocalRay r = local_ray(ray, shape);
  const LocalInterval l = local_solid_interval(shape, r, plane_offset_from(shape.lower, shape.base),
                                               plane_offset_from(shape.upper, shape.base));
  return clamp_interval(l, r.shift, t_min, t_max);
}

ReliefHit intersect_relief(const Ray& ray, const Frustum& frustum, const ReliefMap& map,
                           const ReliefOptions& options, double t_min, double t_max,
                           bool describe, const ReliefFade* fade) {
  assert(map.field && map.depth_m > 0 && "intersect_relief needs a height field and a depth > 0");
  assert(options.max_depth_per_radius > 0 && "a zero shell has no relief");
  ReliefHit result;
  const ShellDepths depths = relief_shell_depths(frustum.shape, map.depth_m, options.max_depth_per_radius);
  const FrustumShape shell = relief_shell(frustum.shape, map.depth_m, options.max_depth_per_radius);
  if (shape_rejected(shell) || !(glm::dot(ray.direction, ray.direction) > 0)) return result;
  Marcher m{frustum,
            map,
            options,
            fade,
            local_ray(ray, shell),
            shell.axis,
            {},
            {},
            frustum.shape.slope(),
            frustum.shape.radius0,
            shell.length,
            depths.lower_m,
            (depths.upper_m - depths.lower_m) / shell.length,
            plane_offset_from(shell.lower, shell.base),
            plane_offset_from(shell.upper, shell.base)};
  const SolidInterval iv =
      clamp_interval(local_solid_interval(shell, m.ray, m.lower_offset, m.upper_offset), m.ray.shift,
                     t_min, t_max);
  if (!iv.hit) return result;
  const AxisFrame frame = axis_frame(shell.axis);
  m.e0 = frame.e0;
  m.e1 = frame.e1;
  // Local t of the ends (t − shift: exact for the ends that came from local roots up to
  // one rounding of the addition, which the caller's range check absorbs).
  m.t_enter = iv.t_enter - m.ray.shift;
  m.t_exit = iv.t_exit - m.ray.shift;
  if (!options.exact_v) {
    m.v_enter = m.exact_v_m(m.point(m.t_enter));
    m.v_exit = m.exact_v_m(m.point(m.t_exit));
  }

  const int steps = std::max(1, options.linear_steps);
  const bool enter_on_shell = iv.enter == SolidBoundary::side;
  const bool exit_on_shell = iv.exit == SolidBoundary::side;
  const bool start_inside = m.inside(m.t_enter, enter_on_shell);
  const bool from_inside = start_inside && iv.enter == SolidBoundary::range;

  double hit_local = 0;                           // local t of the hit
  SolidBoundary boundary = SolidBoundary::range;  // the interval end the hit is on; range:
                                                  // a crossing of the relief inside it
  bool found = false;
  if (start_inside && !from_inside) {
    // Entered through the shell or a plane straight into the solid: the boundary itself.
    hit_local = m.t_enter;
    boundary = iv.enter;
    found = true;
  } else {
    double previous = m.t_enter;
    for (int k = 1; k <= steps && !found; ++k) {
      const double t = k == steps ? m.t_exit : m.t_enter + (m.t_exit - m.t_enter) * k / steps;
      const bool in = m.inside(t, k == steps && exit_on_shell);
      if (in == start_inside) {
        previous = t;
        continue;
      }
      // Bracket [previous, t] with the crossing; bisect, keeping `outside` on the side
      // the ray comes from when entering.
      double outside = from_inside ? t : previous, inside = from_inside ? previous : t;
      for (int b = 0; b < options.bisection_steps; ++b) {
        const double mid = 0.5 * (outside + inside);
        if (m.inside(mid, false)) inside = mid;
        else outside = mid;
      }
      // Entering: the outside end (a shadow ray from there starts outside); leaving: the
      // inside end. Either way strictly inside the caller's range.
      hit_local = from_inside ? inside : outside;
      if (!(m.ray.shift + hit_local > t_min)) hit_local = inside;
      found = true;
    }
    if (!found && from_inside) {
      // Still inside at the interval's end: the way out is its exit boundary, a surface
      // where that is the outer shell (H = 1 there) or a capped plane.
      const bool capped = (iv.exit == SolidBoundary::lower && shell.cap_lower) ||
                          (iv.exit == SolidBoundary::upper && shell.cap_upper);
      if (iv.exit == SolidBoundary::side || capped) {
        hit_local = m.t_exit;
        boundary = iv.exit;
        found = true;
      }
    }
  }
  if (!found) return result;
  // A boundary hit keeps the interval's own t (no round trip through the local frame).
  const double t = boundary == SolidBoundary::range ? m.ray.shift + hit_local
                   : hit_local == m.t_enter         ? iv.t_enter
                                                    : iv.t_exit;
  if (!(t > t_min && t < t_max)) return result;

  result.hit.t = t;
  const bool on_cap = (boundary == SolidBoundary::lower && shell.cap_lower) ||
                      (boundary == SolidBoundary::upper && shell.cap_upper);
  result.hit.kind = on_cap ? (boundary == SolidBoundary::lower ? FrustumHitKind::lower_cap
                                                               : FrustumHitKind::upper_cap)
                           : FrustumHitKind::side;
  if (!describe) return result;

  const Marcher::Point q = m.point(hit_local);
  const glm::dvec3 e = m.radial(q);
  result.hit.y = q.y;
  result.hit.radial = e;
  result.v_m = m.v_m_at(q, hit_local);
  result.u = m.u_at(q, result.v_m);
  if (on_cap) {
    result.hit.normal = boundary == SolidBoundary::lower ? -shell.lower.normal : shell.upper.normal;
    result.shading_normal = result.hit.normal;
  } else {
    // Central differences of H over a texel or the footprint, then the bump-mapping
    // perturbation of relief.h.
    const double footprint_m = options.pixel_spread_rad * std::max(t, 0.0) * glm::length(ray.direction);
    const double around_per_metre = q.rho > 0 ? map.u_repeat / (2 * kPi * q.rho) : 0.0;
    const double ws = std::max(2 * map.field->gradient_step_s(), footprint_m * around_per_metre);
    const double wt = std::max(2 * map.field->gradient_step_t(), footprint_m * map.v_per_metre);
    const double s0 = result.u * map.u_repeat, t0 = result.v_m * map.v_per_metre;
    const bool filtered = ws > 2 * map.field->gradient_step_s() || wt > 2 * map.field->gradient_step_t();
    auto h_at = [&](double s1, double t1) {
      return filtered ? map.field->filtered_height(s1, t1, ws, wt) : map.field->height(s1, t1);
    };
    // A footprint over half a repeat averages the relief away: no perturbation (and no
    // lookups over most of the texture).
    const bool resolved = ws < kMaxNormalFootprint && wt < kMaxNormalFootprint;
    const double dh_ds = resolved ? (h_at(s0 + 0.5 * ws, t0) - h_at(s0 - 0.5 * ws, t0)) / ws : 0.0;
    const double dh_dt = resolved ? (h_at(s0, t0 + 0.5 * wt) - h_at(s0, t0 - 0.5 * wt)) / wt : 0.0;
    const double depth = std::max(q.depth, 0.0);
    const glm::dvec3 tangent_u = glm::cross(m.axis, e);
    // The constant-w cone through the hit (slope k + w·d'(y); k where d is constant).
    const double slope_w = m.slope + std::clamp(q.w(), 0.0, 1.0) * m.depth_slope;
    const glm::dvec3 tangent_v = glm::normalize(m.axis + slope_w * e);
    // The displacement is d·f·H: H's differences scaled by f, and H times f's gradient.
    double f = 1, df_da = 0, df_db = 0;
    if (fade) {
      const glm::dvec3 p = frustum.shape.base + q.p;
      const double step = fade->fade_step_m();
      auto scale_at = [&](const glm::dvec3& x) { return std::clamp(fade->scale(x), 0.0, 1.0); };
      f = scale_at(p);
      df_da = (scale_at(p + step * tangent_u) - scale_at(p - step * tangent_u)) / (2 * step);
      df_db = (scale_at(p + step * tangent_v) - scale_at(p - step * tangent_v)) / (2 * step);
    }
    const double h0 = fade ? h_at(s0, t0) : 0.0;  // where f changes, H lifts by f's slope
    const double around = depth * (f * (q.rho > 0 ? dh_ds * map.u_repeat / (2 * kPi * q.rho) : 0.0) + h0 * df_da);
    const double along = depth * (f * (dh_dt * map.v_per_metre +
                                       dh_ds * map.u_repeat * frustum.twist_rad_per_m / (2 * kPi)) +
                                  h0 * df_db);
    auto perturb = [&](const glm::dvec3& n0) {
      const glm::dvec3 n = n0 - around * tangent_u - along * tangent_v;
      const double length = glm::length(n);
      return length > 0 && std::isfinite(length) ? n / length : n0;
    };
    result.hit.normal = perturb(glm::normalize(e - slope_w * m.axis));
    const glm::dvec3 world = ray.origin + t * ray.direction;
    result.shading_normal = perturb(surface_normal(frustum, world, NormalMode::interpolated));
  }
  // From inside: the ray started in the solid (a boundary entry is from outside even where
  // its relief normal faces away from the ray).
  result.hit.from_inside = from_inside;
  return result;
}

}  // namespace sylva
