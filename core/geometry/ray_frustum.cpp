// ray_frustum.cpp — ray casting conical frusta, Bhagvat et al. 2009 sec. 2.5 (eq. 9–10), robust.
//
// The cone's quadratic is eq. 9–10 in the apex-free form of cone_quadric.h (it never forms
// the apex height h', infinite for a cylinder), with the regrouped discriminant.
//
// What the paper's version lacks, and this one adds:
// - Re-centring. C ~ |E|² and B ~ |E|: with the eye 10⁶ away the textbook roots lose
//   every digit of the hit position to cancellation. The origin is first moved along the
//   ray to the point nearest the segment's midpoint (in compensated arithmetic, so the
//   moved origin is exact to an ulp of its own small size), the quadratic is solved there
//   and the shift is added back to t.
// - The stable root pair q = −(half_b + sign(half_b)·√D'), roots q/A and C/q: neither
//   root is a difference of nearly equal numbers. A → 0 (ray parallel to a generator line)
//   makes q/A run off to infinity while C/q stays the linear equation's root: the paper's
//   "a = 0 means a miss" is wrong, that ray crosses the cone once.
// - Wrong-nappe rejection (r(y) >= 0 at the hit) and the plane inside test of
//   frustum_shape.h, caps as the part of their plane inside the cone, an origin inside
//   the solid (its exit hit is the first hit).
// - Plane offsets made relative to the base by a compensated dot product, so a segment
//   10⁶ from the world origin keeps planes exact to an ulp of the segment's size.
#include "core/geometry/ray_frustum.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <initializer_list>
#include <limits>

#include "core/geometry/cone_quadric.h"
#include "core/geometry/recentre.h"

namespace sylva {
namespace {

using compensated::plane_offset_from;

// ---- The intersector, shared by the double reference and the float twin -----------------
//
// Everything below is written once as a template over the scalar so that the double and
// float versions cannot drift; the GLSL mirrors these functions, same names, same order,
// using only dot, cross, sqrt, abs and comparisons.

template <class Real>
using Vec3 = glm::vec<3, Real, glm::defaultp>;

// The frame-relative shape: everything relative to the segment base.
template <class Real>
struct LocalShape {
  Vec3<Real> axis;
  Real length;
  Real radius0;
  Real slope;
  Vec3<Real> lower_normal;
  Real lower_offset;  // relative to the base
  Vec3<Real> upper_normal;
  Real upper_offset;  // relative to the base
  bool cap_lower;
  bool cap_upper;
};

// The caller's range, checked on the final t = shift + t_local (not on t_local against
// shifted bounds, whose rounding would move the ends of the range by an ulp of the shift).
template <class Real>
struct RayRange {
  Real shift;  // the re-centring: t = shift + t_local
  Real t_min;
  Real t_max;
  bool contains(Real t_local) const {
    const Real t = shift + t_local;
    return t > t_min && t < t_max;  // false for NaN and ±inf beyond the range
  }
};

template <class Real>
struct LocalHit {
  uint32_t kind = 0;
  Real t_local = 0;  // along the ray from the re-centred origin
  Vec3<Real> point{0, 0, 0};  // relative to the base
};

// True where p (relative to the base) is between the two cutting planes (frustum_shape.h).
template <class Real>
bool frustum_inside_planes(const LocalShape<Real>& s, const Vec3<Real>& p) {
  return dot(s.lower_normal, p) >= s.lower_offset && dot(s.upper_normal, p) <= s.upper_offset;
}

// Roots of A t² + 2 half_b t + C = 0 with D' = half_b² − A·C given, ascending, by the
// stable pair; returns how many.
// q = −(half_b + sign(half_b)·√D') never cancels; q/A is dropped when A == 0 (the linear
// case, whose one root C/q = −C/(2 half_b) remains) and C/q when q == 0 (then half_b == 0
// and D' == 0, so C == 0 and the double root is 0 = q/A). D' == 0 gives one root: a tangent
// hit counts once.
template <class Real>
int frustum_side_roots(Real A, Real half_b, Real C, Real discriminant, Real roots[2]) {
  if (!(discriminant >= Real(0))) return 0;  // miss (or NaN coefficients)
  const Real sign_b = half_b >= Real(0) ? Real(1) : Real(-1);  // not sign(): 0 at 0
  const Real q = -(half_b + sign_b * std::sqrt(discriminant));
  int count = 0;
  if (A != Real(0)) roots[count++] = q / A;
  if (q != Real(0) && (discriminant > Real(0) || count == 0)) roots[count++] = C / q;
  if (count == 2 && roots[1] < roots[0]) {
    const Real swap = roots[0];
    roots[0] = roots[1];
    roots[1] = swap;
  }
  return count;
}

// Side hit: the nearest root in range on the right nappe (r(y) >= 0) between the planes.
template <class Real>
void frustum_side_hit(const LocalShape<Real>& s, const Vec3<Real>& origin,
                      const Vec3<Real>& dir, const RayRange<Real>& range, LocalHit<Real>& best) {
  const Real origin_y = dot(origin, s.axis);
  const Vec3<Real> origin_perp = origin - origin_y * s.axis;
  const Real dir_y = dot(dir, s.axis);
  const Vec3<Real> dir_perp = dir - dir_y * s.axis;
  const Real rho = s.radius0 + s.slope * origin_y;  // radius at the origin's height
  const Real slope_dir_y = s.slope * dir_y;
  const ConeQuadric<Real> f = cone_quadric(origin_perp, dir_perp, rho, slope_dir_y);
  Real roots[2];
  const int count = frustum_side_roots(f.A, f.half_b, f.C, f.discriminant, roots);
  for (int i = 0; i < count; ++i) {
    const Real t = roots[i];
    if (!(t < best.t_local) || !range.contains(t)) continue;  // also drops ±inf
    const Vec3<Real> p = origin + t * dir;
    if (s.radius0 + s.slope * dot(p, s.axis) < Real(0)) continue;  // wrong nappe
    if (!frustum_inside_planes(s, p)) continue;
    best.kind = uint32_t(FrustumHitKind::side);
    best.t_local = t;
    best.point = p;
    return;
  }
}

// Cap hit: the part of the plane (normal, offset) inside the cone, on the right nappe, on
// the inner side of the other plane.
template <class Real>
void frustum_cap_hit(const LocalShape<Real>& s, const Vec3<Real>& origin,
                     const Vec3<Real>& dir, const Vec3<Real>& normal, Real offset,
                     uint32_t kind, const RayRange<Real>& range, LocalHit<Real>& best) {
  const Real denominator = dot(normal, dir);
  if (denominator == Real(0)) return;  // ray parallel to the cap
  const Real t = (offset - dot(normal, origin)) / denominator;
  if (!(t < best.t_local) || !range.contains(t)) return;
  const Vec3<Real> p = origin + t * dir;
  const Real y = dot(p, s.axis);
  const Vec3<Real> p_perp = p - y * s.axis;
  const Real radius = s.radius0 + s.slope * y;
  if (!(radius > Real(0)) || dot(p_perp, p_perp) > radius * radius) return;
  // The other plane: a cap is only the part of its disc between the planes.
  if (kind == uint32_t(FrustumHitKind::lower_cap) ? dot(s.upper_normal, p) > s.upper_offset
                                                  : dot(s.lower_normal, p) < s.lower_offset)
    return;
  best.kind = kind;
  best.t_local = t;
  best.point = p;
}

// The radial unit ê of p (⊥ axis); on the axis, a fixed perpendicular.
template <class Real>
Vec3<Real> frustum_radial(const Vec3<Real>& axis, const Vec3<Real>& p) {
  const Vec3<Real> p_perp = p - dot(p, axis) * axis;
  const Real length_sq = dot(p_perp, p_perp);
  if (length_sq > Real(0)) return p_perp / std::sqrt(length_sq);
  const Vec3<Real> helper = std::abs(axis.x) < Real(0.5) ? Vec3<Real>(1, 0, 0)
                                                        : Vec3<Real>(0, 1, 0);
  const Vec3<Real> perp = helper - dot(helper, axis) * axis;
  return perp / std::sqrt(dot(perp, perp));
}

// The core after the change of frame: origin relative to the base, re-centred already.
template <class Real>
LocalHit<Real> frustum_intersect_local(const LocalShape<Real>& s, const Vec3<Real>& origin,
                                       const Vec3<Real>& dir, const RayRange<Real>& range) {
  LocalHit<Real> best;
  best.t_local = std::numeric_limits<Real>::infinity();
  frustum_side_hit(s, origin, dir, range, best);
  if (s.cap_lower)
    frustum_cap_hit(s, origin, dir, -s.lower_normal, -s.lower_offset,
                    uint32_t(FrustumHitKind::lower_cap), range, best);
  if (s.cap_upper)
    frustum_cap_hit(s, origin, dir, s.upper_normal, s.upper_offset,
                    uint32_t(FrustumHitKind::upper_cap), range, best);
  return best;
}

// Outward normal at a hit of `kind` with radial ê.
template <class Real>
Vec3<Real> frustum_normal(const LocalShape<Real>& s, uint32_t kind, const Vec3<Real>& radial) {
  if (kind == uint32_t(FrustumHitKind::lower_cap)) return -s.lower_normal;
  if (kind == uint32_t(FrustumHitKind::upper_cap)) return s.upper_normal;
  const Vec3<Real> n = radial - s.slope * s.axis;  // ∝ ∇(|p⊥| − r(y))
  return n / std::sqrt(dot(n, n));
}

bool shape_rejected(const FrustumShape& shape) {
  // !(x > 0) and !(x >= 0) also catch NaN.
  return !(shape.length > 0) || !std::isfinite(shape.length) || !(shape.radius0 >= 0) ||
         !(shape.radius1 >= 0) || !std::isfinite(shape.radius0) ||
         !std::isfinite(shape.radius1);
}

}  // namespace

const char* frustum_shape_error(const FrustumShape& shape) {
  constexpr double kUnitTolerance = 1e-9;
  if (!(shape.length > 0) || !std::isfinite(shape.length))
    return "frustum length must be finite and > 0";
  if (!(shape.radius0 >= 0) || !(shape.radius1 >= 0) || !std::isfinite(shape.radius0) ||
      !std::isfinite(shape.radius1))
    return "frustum radii must be finite and >= 0";
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(shape.base[i])) return "frustum base must be finite";
  if (!(std::abs(glm::dot(shape.axis, shape.axis) - 1) <= kUnitTolerance))
    return "frustum axis must be a unit vector";
  for (const Plane* plane : {&shape.lower, &shape.upper}) {
    if (!(std::abs(glm::dot(plane->normal, plane->normal) - 1) <= kUnitTolerance))
      return "cutting plane normal must be a unit vector";
    if (!(glm::dot(plane->normal, shape.axis) > 0))
      return "cutting plane normal must point up the segment (dot(normal, axis) > 0)";
    if (!std::isfinite(plane->offset)) return "cutting plane offset must be finite";
  }
  if (shape.cap_lower && !(glm::dot(shape.lower.normal, shape.axis) >= 1 - kUnitTolerance))
    return "a lower cap needs a lower plane perpendicular to the axis";
  if (shape.cap_upper && !(glm::dot(shape.upper.normal, shape.axis) >= 1 - kUnitTolerance))
    return "an upper cap needs an upper plane perpendicular to the axis";
  return nullptr;
}

FrustumHit intersect_frustum(const Ray& ray, const FrustumShape& shape, double t_min,
                             double t_max) {
  FrustumHit result;
  if (shape_rejected(shape)) return result;
  const glm::dvec3& d = ray.direction;
  const double dir_sq = glm::dot(d, d);
  if (!(dir_sq > 0)) return result;

  // Re-centre on the midpoint (compensated.h): t = shift + t_local.
  const compensated::RecentredRay recentred = compensated::recentre(ray, shape);
  const glm::dvec3& origin = recentred.origin;
  const double shift = recentred.shift;

  const LocalShape<double> local{shape.axis,
                                 shape.length,
                                 shape.radius0,
                                 shape.slope(),
                                 shape.lower.normal,
                                 plane_offset_from(shape.lower, shape.base),
                                 shape.upper.normal,
                                 plane_offset_from(shape.upper, shape.base),
                                 shape.cap_lower,
                                 shape.cap_upper};
  const LocalHit<double> hit =
      frustum_intersect_local(local, origin, d, RayRange<double>{shift, t_min, t_max});
  if (hit.kind == 0) return result;
  result.kind = FrustumHitKind(hit.kind);
  result.t = shift + hit.t_local;
  result.y = glm::dot(hit.point, shape.axis);
  result.radial = frustum_radial(shape.axis, hit.point);
  result.normal = frustum_normal(local, hit.kind, result.radial);
  result.from_inside = glm::dot(d, result.normal) > 0;
  return result;
}

bool ray_beyond_reach(const Ray& ray, const FrustumShape& shape, double reach_m) {
  // The distance between the lines is |w·n| / |n| with w = origin − base, n = d × axis.
  const glm::dvec3 w = ray.origin - shape.base;
  const glm::dvec3 n = glm::cross(ray.direction, shape.axis);
  const double wn = std::abs(glm::dot(w, n));
  auto max_abs = [](const glm::dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); };
  // Rounding: w = origin − base is correctly rounded (ε/2 of |w|), n and the dot product
  // are off by a few ε of |w|·|d|; 1e-12 of those magnitudes (×3 for the max-abs norms)
  // covers both with a wide margin.
  const double slack = 3e-12 * (max_abs(w) + reach_m) * max_abs(ray.direction);
  const double beyond = wn - slack;
  return beyond > 0 && beyond * beyond > reach_m * reach_m * glm::dot(n, n) * (1 + 1e-12);
}

FrustumShapeF to_float_shape(const FrustumShape& shape, const glm::dvec3& segment_origin) {
  FrustumShapeF f;
  f.base = glm::vec3(shape.base - segment_origin);
  f.axis = glm::vec3(shape.axis);
  f.length = float(shape.length);
  f.radius0 = float(shape.radius0);
  f.slope = float(shape.slope());
  f.lower_normal = glm::vec3(shape.lower.normal);
  f.lower_offset = float(plane_offset_from(shape.lower, segment_origin));
  f.upper_normal = glm::vec3(shape.upper.normal);
  f.upper_offset = float(plane_offset_from(shape.upper, segment_origin));
  f.caps = (shape.cap_lower ? 1u : 0u) | (shape.cap_upper ? 2u : 0u);
  return f;
}

RayF to_float_ray(const Ray& ray, const glm::dvec3& segment_origin) {
  return {glm::vec3(ray.origin - segment_origin), glm::vec3(ray.direction)};
}

// The GLSL ray caster's function, line for line: plain float, no compensation (the record
// is already relative to the segment base, the ray to the segment origin).
FrustumHitF intersect_frustum_f(const RayF& ray, const FrustumShapeF& shape, float t_min,
                                float t_max) {
  FrustumHitF result;
  if (!(shape.length > 0.0f) || !(shape.radius0 >= 0.0f)) return result;
  const glm::vec3 d = ray.direction;
  const float dir_sq = dot(d, d);
  if (!(dir_sq > 0.0f)) return result;
  // Re-centre relative to the base, then to the point nearest the midpoint.
  const glm::vec3 relative = ray.origin - shape.base;
  const glm::vec3 midpoint = (0.5f * shape.length) * shape.axis;
  const float shift = dot(midpoint - relative, d) / dir_sq;
  const glm::vec3 origin = relative + shift * d;
  const LocalShape<float> local{shape.axis,
                                shape.length,
                                shape.radius0,
                                shape.slope,
                                shape.lower_normal,
                                shape.lower_offset - dot(shape.lower_normal, shape.base),
                                shape.upper_normal,
                                shape.upper_offset - dot(shape.upper_normal, shape.base),
                                (shape.caps & 1u) != 0u,
                                (shape.caps & 2u) != 0u};
  const LocalHit<float> hit =
      frustum_intersect_local(local, origin, d, RayRange<float>{shift, t_min, t_max});
  if (hit.kind == 0u) return result;
  result.kind = hit.kind;
  result.t = shift + hit.t_local;
  result.y = dot(hit.point, shape.axis);
  result.radial = frustum_radial(shape.axis, hit.point);
  result.normal = frustum_normal(local, hit.kind, result.radial);
  return result;
}

}  // namespace sylva
