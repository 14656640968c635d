// skin.cpp — skinning a skeleton with conical frusta. Implements Bhagvat, Jeschke, Cline,
// Wonka, "GPU Rendering of Relief Mapped Conical Frusta" (2009): sec. 2.2 cutting planes
// (eq. 3–5, medial-plane construction; iterative minor-axis fit), sec. 2.3 (u, v; eq. 6–7
// in apex-free form), sec. 2.4 (eq. 8 normals), sec. 2.6 (bounding pyramid). Sharp bends,
// which the paper leaves open, are split into capped legs plus a knuckle ball (skin.h).
#include "core/geometry/skin.h"
#include "core/util/math.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <optional>

namespace sylva {

std::optional<SkinStyle> parse_skin_style(std::string_view text) {
  if (text == "smooth") return SkinStyle::smooth;
  if (text == "paper") return SkinStyle::paper;
  return std::nullopt;
}

namespace {

// Cancellation is checked, and progress reported, once per 1024 chains.
constexpr uint32_t kProgressChunkMask = 1023;
}  // namespace

namespace {

using glm::dvec2;
using glm::dvec3;


double deg_to_rad(double deg) { return deg * kPi / 180.0; }

// Wraps turns into [0, 1).
double wrap_turns(double turns) {
  double w = turns - std::floor(turns);
  return w >= 1.0 ? 0.0 : w;
}

double cross2(dvec2 a, dvec2 b) { return a.x * b.y - a.y * b.x; }

dvec3 joint_position(const Joint& j) { return {j.position_m[0], j.position_m[1], j.position_m[2]}; }

// A coordinate axis least aligned with `v`: the colinear fallback of eq. 3.
dvec3 least_aligned_axis(const dvec3& v) {
  dvec3 a = glm::abs(v);
  if (a.x <= a.y && a.x <= a.z) return {1, 0, 0};
  if (a.y <= a.z) return {0, 1, 0};
  return {0, 0, 1};
}

// Plane through `point` with unit normal `normal`.
Plane plane_through(const dvec3& point, const dvec3& normal) { return Plane{normal, glm::dot(normal, point)}; }

// Tilt allowance of one side of a joint: the plane tilt plus the cone's half angle must
// stay within max_tilt (so c − |k|·sin(tilt) >= cos(max_tilt), see G1).
double tilt_allowance_rad(double slope, double max_tilt_rad) {
  return std::max(0.0, max_tilt_rad - std::atan(std::abs(slope)));
}

// One side of a joint as the medial construction sees it.
struct JointSide {
  double radius_far;    // radius at the far end of the segment
  double radius_joint;  // radius of this segment at the joint
  double length;        // segment length (> 0)
  double slope() const { return (radius_joint - radius_far) / length; }  // toward the joint
};

// Result of the cutting-plane construction at one interior joint.
struct JointCut {
  Plane plane;
  bool split = false;    // bend too sharp for one plane within the tilt limits
  bool clamped = false;  // medial normal was limited to the tilt interval
  dvec3 medial_normal;   // Nm (fallback axis when the axes are colinear)
  dvec3 a_point, b_point;  // A and B of eq. 5 (valid when `regular`)
  bool regular = false;  // both boundary-line intersections were well conditioned
};

// Eq. 3–5 at joint `j` between segment 1 (direction m1, ending at j) and segment 2
// (direction m2, starting at j), computed in the medial plane with j as origin, x along
// m1 and y toward m2. Then the normal is clamped into the tilt interval (skin.h).
JointCut cutting_plane_at_joint(const dvec3& j, const dvec3& m1, const JointSide& s1,
                                const dvec3& m2, const JointSide& s2, double max_tilt_rad) {
  JointCut cut;
  dvec3 cross12 = glm::cross(m1, m2);
  double sin_a = glm::length(cross12);
  double cos_a = glm::dot(m1, m2);
  double alpha = std::atan2(sin_a, cos_a);  // bend angle in [0, pi], accurate near 0
  dvec3 nm = sin_a > 1e-300 ? cross12 / sin_a : dvec3(0);
  if (!(sin_a > 1e-12)) {  // colinear (or antiparallel): substitute a coordinate axis
    nm = glm::normalize(glm::cross(m1, least_aligned_axis(m1)));
  }
  cut.medial_normal = nm;
  dvec3 perp = glm::cross(nm, m1);  // in-plane, ⊥ m1, toward m2
  sin_a = std::sin(alpha);
  cos_a = std::cos(alpha);
  double one_minus_cos = 2.0 * std::sin(alpha / 2) * std::sin(alpha / 2);

  double k1 = s1.slope();  // radius grows toward the joint along segment 1
  double k2 = (s2.radius_far - s2.radius_joint) / s2.length;  // grows away from it
  double rj1 = s1.radius_joint;
  double rj2 = s2.radius_joint;

  // Left (inner, +y) and right boundary lines of both cones in the medial plane (eq. 4):
  // L2 = (0, rj1), line 1 direction (1, k1); L3 = rj2·(−sin a, cos a), direction
  // m2 + k2·(−s2) with s2 = m2 × Nm = (sin a, −cos a).
  dvec2 m2_2d{cos_a, sin_a};
  dvec2 left_side2{-sin_a, cos_a};
  auto boundary_point = [&](double sign) -> std::optional<dvec2> {
    dvec2 p{0, sign * rj1};
    dvec2 d{1, sign * k1};
    dvec2 e = m2_2d + sign * k2 * left_side2;
    // q − p without cancellation: rj2·cos a − rj1 = (rj2 − rj1) − rj2·(1 − cos a).
    dvec2 q_minus_p{-sign * rj2 * sin_a, sign * ((rj2 - rj1) - rj2 * one_minus_cos)};
    double den = cross2(d, e);
    if (!(std::abs(den) > 1e-12 * glm::length(d) * glm::length(e))) return std::nullopt;
    double t = cross2(q_minus_p, e) / den;
    return p + t * d;
  };
  std::optional<dvec2> a2 = boundary_point(+1);
  std::optional<dvec2> b2 = boundary_point(-1);
  double r_scale = std::max({rj1, rj2, 1e-300});

  // Normal angle phi in the bend plane, measured from m1 toward m2; miter is alpha/2.
  double phi = alpha / 2;
  dvec2 through{0, 0};  // plane point (2D), the joint unless the construction is regular
  if (a2 && b2) {
    dvec2 ab = *a2 - *b2;
    dvec2 mid = 0.5 * (*a2 + *b2);
    if (glm::length(ab) > 1e-9 * r_scale && glm::length(mid) <= 2.0 * r_scale) {
      dvec2 n2{ab.y, -ab.x};  // (A − B) × Nm
      if (n2.x * (1 + cos_a) + n2.y * sin_a < 0) n2 = -n2;  // along m1 + m2
      phi = std::atan2(n2.y, n2.x);
      through = mid;
      cut.regular = true;
      cut.a_point = j + a2->x * m1 + a2->y * perp;
      cut.b_point = j + b2->x * m1 + b2->y * perp;
    }
  }
  double t1 = tilt_allowance_rad(k1, max_tilt_rad);
  double t2 = tilt_allowance_rad(k2, max_tilt_rad);
  if (alpha > t1 + t2) {
    cut.split = true;
    return cut;
  }
  double lo = std::max(-t1, alpha - t2);
  double hi = std::min(t1, alpha + t2);
  if (phi < lo || phi > hi) {
    phi = std::clamp(phi, lo, hi);
    cut.clamped = true;
  }
  dvec3 normal = glm::normalize(std::cos(phi) * m1 + std::sin(phi) * perp);
  cut.plane = plane_through(j + through.x * m1 + through.y * perp, normal);
  return cut;
}

// Minor semi-axis (eq. 5 discussion) of the cut of a cone through the midpoint of A, B:
// the half-width of the ellipse along Nm, sqrt(r(y_M)² − d_M²).
double minor_semi_axis(const dvec3& base, const dvec3& axis, double r0, double slope,
                       const dvec3& mid) {
  dvec3 d = mid - base;
  double y = glm::dot(d, axis);
  dvec3 radial = d - y * axis;
  double r = r0 + slope * y;
  return std::sqrt(std::max(0.0, r * r - glm::dot(radial, radial)));
}

// Sec. 2.2's fit at a mitred joint between segment 1 (from base1 along m1, base radius
// r1_base, radius r1_joint at `joint`, length1) and segment 2 (from `joint` along m2, base
// radius r2_base, far radius r2_far, length2), given `plain`, the construction's cut with
// r2_base: the new cone's base radius r (within [0.5, 2] of r1_joint) whose cut's minor
// semi-axis matches the old cone's, so that both elliptical cuts share both axes and
// coincide; secant steps on f(r) = b2(r) − b1 from r2_base. `plain` and r2_base, not
// `matched`, where the construction is not regular, clamped, split, or does not settle
// within max_iterations to tolerance · r1_joint (the cuts then share at most their major
// axis: a crack between them, G3).
struct FittedCut {
  JointCut cut;
  double radius = 0;      // segment 2's base radius
  bool matched = false;   // the minor axes agree: the two cuts coincide
};
FittedCut fit_minor_axis(const JointCut& plain, const dvec3& joint, const dvec3& base1, const dvec3& m1,
                         double r1_base, double r1_joint, double length1, const dvec3& m2, double r2_base,
                         double r2_far, double length2, double max_tilt_rad, double tolerance, int max_iterations) {
  FittedCut out{plain, r2_base};
  // b2(r) − b1 on r's cut; none where that cut is no regular mitre.
  auto mismatch = [&](double r, const JointCut& c) -> std::optional<double> {
    if (c.split || !c.regular || c.clamped) return std::nullopt;
    const dvec3 mid = 0.5 * (c.a_point + c.b_point);
    const double k1 = (r1_joint - r1_base) / length1;
    const double k2 = (r2_far - r) / length2;
    return minor_semi_axis(joint, m2, r, k2, mid) - minor_semi_axis(base1, m1, r1_base, k1, mid);
  };
  auto cut_with = [&](double r) {
    return cutting_plane_at_joint(joint, m1, JointSide{r1_base, r1_joint, length1}, m2,
                                  JointSide{r2_far, r, length2}, max_tilt_rad);
  };
  if (!(r1_joint > 0) || !(r2_base > 0)) return out;
  double x0 = r2_base;
  std::optional<double> f0 = mismatch(x0, plain);
  if (!f0) return out;
  // Matched already (equal slopes; or collinear segments, where every radius gives a
  // perpendicular cut on which both circles agree, so the secant's second point would be
  // taken for a fit): the base radius stays.
  if (std::abs(*f0) <= tolerance * r1_joint) {
    out.matched = true;
    return out;
  }
  double x1 = r2_base * (1 + 1e-3);
  JointCut c1 = cut_with(x1);
  std::optional<double> f1 = mismatch(x1, c1);
  for (int it = 0; f1 && it < max_iterations; ++it) {
    if (std::abs(*f1) <= tolerance * r1_joint) {
      if (x1 >= 0.5 * r1_joint && x1 <= 2.0 * r1_joint) out = {c1, x1, true};
      break;
    }
    if (*f1 == *f0) break;
    const double x2 = x1 - *f1 * (x1 - x0) / (*f1 - *f0);
    if (!(x2 > 0.25 * r1_joint && x2 < 4.0 * r1_joint)) break;
    x0 = x1, f0 = f1;
    x1 = x2, c1 = cut_with(x1), f1 = mismatch(x1, c1);
  }
  return out;
}

// Rotates v about unit axis k by angle (Rodrigues).
dvec3 rotate(const dvec3& v, const dvec3& k, double angle) {
  double c = std::cos(angle), s = std::sin(angle);
  return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (1 - c);
}

// Raw u (turns in [0,1)) of a direction ⊥ axis.
double raw_u(const dvec3& axis, const dvec3& radial) {
  AxisFrame f = axis_frame(axis);
  return wrap_turns(std::atan2(glm::dot(radial, f.e1), glm::dot(radial, f.e0)) / (2 * kPi));
}

// Unit radial direction of `point` around the shape's axis (e0 on the axis).
dvec3 radial_direction(const FrustumShape& s, const dvec3& point) {
  dvec3 d = point - s.base;
  dvec3 radial = d - glm::dot(d, s.axis) * s.axis;
  double len = glm::length(radial);
  if (!(len > 1e-300)) return axis_frame(s.axis).e0;
  return radial / len;
}

// The straight polyline of one chain with zero-length segments removed.
struct ChainPath {
  std::vector<dvec3> points;
  std::vector<double> radii;
  std::vector<uint32_t> materials;
  std::vector<uint32_t> joint_index;  // index of each kept joint within the chain
};

}  // namespace

AxisFrame axis_frame(const dvec3& n) {
  double sign = std::copysign(1.0, n.z);
  double a = -1.0 / (sign + n.z);
  double b = n.x * n.y * a;
  AxisFrame f;
  f.e0 = dvec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
  f.e1 = dvec3(b, sign + n.y * n.y * a, -n.y);
  return f;
}

double generator_crossing_y(const FrustumShape& s, const Plane& plane, const dvec3& radial) {
  // dot(n, base + y·axis + (r0 + k·y)·ê) = offset, solved for y; the denominator is bounded
  // below by kMinCrossingDenominator for skinned frusta (G1).
  double k = s.slope();
  double nd = glm::dot(plane.normal, radial);
  double height = plane.offset - glm::dot(plane.normal, s.base);
  return (height - s.radius0 * nd) / (glm::dot(plane.normal, s.axis) + k * nd);
}

dvec3 cut_point(const FrustumShape& s, const Plane& plane, double u_raw) {
  AxisFrame f = axis_frame(s.axis);
  double angle = 2 * kPi * u_raw;
  dvec3 radial = std::cos(angle) * f.e0 + std::sin(angle) * f.e1;
  double y = generator_crossing_y(s, plane, radial);
  return s.base + y * s.axis + s.radius_at(y) * radial;
}

SurfaceUV surface_uv(const Frustum& fr, const dvec3& point) {
  const FrustumShape& s = fr.shape;
  dvec3 radial = radial_direction(s, point);
  double y = glm::dot(point - s.base, s.axis);
  double y_lower = generator_crossing_y(s, s.lower, radial);
  double y_upper = generator_crossing_y(s, s.upper, radial);
  SurfaceUV uv;
  uv.v = (y - y_lower) / (y_upper - y_lower);  // eq. 7 as a ratio of generator parameters
  uv.v_m = fr.v_lower_m + uv.v * (fr.v_upper_m - fr.v_lower_m);
  uv.u = wrap_turns(raw_u(s.axis, radial) - fr.u_offset +
                    fr.twist_rad_per_m * uv.v_m / (2 * kPi));
  return uv;
}

dvec3 surface_normal(const Frustum& fr, const dvec3& point, NormalMode mode) {
  const FrustumShape& s = fr.shape;
  dvec3 radial = radial_direction(s, point);
  dvec3 exact = glm::normalize(radial - s.slope() * s.axis);
  if (mode == NormalMode::exact || fr.kind == FrustumKind::knuckle) return exact;
  // Eq. 8: Nl = Pl − base, Nu = Pu − top, blended by v.
  double y_lower = generator_crossing_y(s, s.lower, radial);
  double y_upper = generator_crossing_y(s, s.upper, radial);
  dvec3 top = s.base + s.length * s.axis;
  dvec3 nl = s.base + y_lower * s.axis + s.radius_at(y_lower) * radial - s.base;
  dvec3 nu = s.base + y_upper * s.axis + s.radius_at(y_upper) * radial - top;
  double tiny = 1e-9 * (s.length + std::max(s.radius0, s.radius1));
  double ll = glm::length(nl), lu = glm::length(nu);
  nl = ll > tiny ? nl / ll : exact;  // a tip: Pl is the apex itself
  nu = lu > tiny ? nu / lu : exact;
  double v = (glm::dot(point - s.base, s.axis) - y_lower) / (y_upper - y_lower);
  v = std::clamp(v, 0.0, 1.0);
  dvec3 n = (1 - v) * nl + v * nu;
  double len = glm::length(n);
  return len > 1e-12 ? n / len : exact;
}

double seam_error(const Frustum& below, const Frustum& above, int samples) {
  assert(samples >= 3);
  auto curve_below = [&](double u) { return cut_point(below.shape, below.shape.upper, u); };
  auto curve_above = [&](double u) { return cut_point(above.shape, above.shape.lower, u); };
  // Distance from p to a closed curve: the nearest of `samples` points, then a golden-
  // section search on u around it (a polyline alone would report its own sagitta).
  auto distance_to = [&](const dvec3& p, auto&& curve) {
    double best_u = 0, best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < samples; ++i) {
      double d = glm::length(p - curve(double(i) / samples));
      if (d < best) best = d, best_u = double(i) / samples;
    }
    const double g = (std::sqrt(5.0) - 1) / 2;
    double a = best_u - 1.0 / samples, b = best_u + 1.0 / samples;
    double c = b - g * (b - a), d = a + g * (b - a);
    double fc = glm::length(p - curve(c)), fd = glm::length(p - curve(d));
    for (int it = 0; it < 80; ++it) {
      if (fc < fd) {
        b = d, d = c, fd = fc, c = b - g * (b - a), fc = glm::length(p - curve(c));
      } else {
        a = c, c = d, fc = fd, d = a + g * (b - a), fd = glm::length(p - curve(d));
      }
    }
    return std::min({best, fc, fd});
  };
  double worst = 0;
  for (int i = 0; i < samples; ++i) {
    double u = double(i) / samples;
    worst = std::max(worst, distance_to(curve_below(u), curve_above));
    worst = std::max(worst, distance_to(curve_above(u), curve_below));
  }
  return worst;
}

BoundingPyramid bounding_pyramid(const FrustumShape& s, double shell_m) {
  BoundingPyramid pyr;
  double r0 = s.radius0 + shell_m;
  double k = s.slope();
  // Square aligned with the tilt direction of the more tilted plane: its edge lines then
  // meet that plane as the cone's extreme generators do (denominator c ± k·sin(tilt)).
  dvec3 tl = s.lower.normal - glm::dot(s.lower.normal, s.axis) * s.axis;
  dvec3 tu = s.upper.normal - glm::dot(s.upper.normal, s.axis) * s.axis;
  dvec3 t = glm::dot(tl, tl) >= glm::dot(tu, tu) ? tl : tu;
  dvec3 e0 = glm::length(t) > 1e-9 ? glm::normalize(t) : axis_frame(s.axis).e0;
  dvec3 e1 = glm::cross(s.axis, e0);
  const double signs[4][2] = {{1, 1}, {-1, 1}, {-1, -1}, {1, -1}};  // ccw about the axis
  bool proper = true;
  double lower_max = -std::numeric_limits<double>::infinity();
  double upper_min = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    dvec3 dir = signs[i][0] * e0 + signs[i][1] * e1;  // corner offset per unit radius
    for (int p = 0; p < 2; ++p) {
      const Plane& pl = p == 0 ? s.lower : s.upper;
      double nd = glm::dot(pl.normal, dir);
      double den = glm::dot(pl.normal, s.axis) + k * nd;
      double height = pl.offset - glm::dot(pl.normal, s.base);
      if (!(den >= kMinCrossingDenominator)) proper = false;
      double y = (height - r0 * nd) / std::max(den, kMinCrossingDenominator);
      pyr.vertices[p * 4 + i] = s.base + y * s.axis + (r0 + k * y) * dir;
      if (!(r0 + k * y >= -1e-9 * (r0 + std::abs(k) * s.length))) proper = false;
      if (p == 0) lower_max = std::max(lower_max, y);
      else upper_min = std::min(upper_min, y);
    }
  }
  double margin = 1e-9 * (s.length + r0);
  if (!(upper_min - lower_max > margin)) proper = false;
  pyr.proper = proper;
  pyr.planes[0] = Plane{-s.lower.normal, -s.lower.offset};
  pyr.planes[1] = s.upper;
  double inv = 1.0 / std::sqrt(1 + k * k);
  const dvec3 side_dirs[4] = {e0, e1, -e0, -e1};
  for (int i = 0; i < 4; ++i) {
    // Side plane: dot(side, p − base) − k·y <= r0, i.e. the square's half width r0 + k·y.
    dvec3 n = (side_dirs[i] - k * s.axis) * inv;
    pyr.planes[2 + i] = Plane{n, glm::dot(n, s.base) + r0 * inv};
  }
  const uint8_t tris[36] = {0, 2, 1, 0, 3, 2,   // lower face
                            4, 5, 6, 4, 6, 7,   // upper face
                            0, 1, 5, 0, 5, 4,  1, 2, 6, 1, 6, 5,
                            2, 3, 7, 2, 7, 6,  3, 0, 4, 3, 4, 7};
  std::copy(std::begin(tris), std::end(tris), pyr.triangles.begin());
  return pyr;
}

double frustum_radial_reach(const FrustumShape& s) {
  const BoundingPyramid pyr = bounding_pyramid(s);
  if (!pyr.proper) return std::numeric_limits<double>::infinity();
  double reach = std::max(s.radius0, 0.0);
  for (const dvec3& v : pyr.vertices) reach = std::max(reach, s.radius0 + s.slope() * glm::dot(v - s.base, s.axis));
  return reach * (1 + 1e-9);
}

double distance_outside(const BoundingPyramid& pyr, const dvec3& point) {
  double worst = -std::numeric_limits<double>::infinity();
  for (const Plane& p : pyr.planes) worst = std::max(worst, glm::dot(p.normal, point) - p.offset);
  return worst;
}

bool cuts_are_proper(const FrustumShape& s, double max_tilt_deg) {
  double min_cos = std::cos(deg_to_rad(max_tilt_deg)) * (1 - 1e-12);
  if (!(glm::dot(s.lower.normal, s.axis) >= min_cos)) return false;
  if (!(glm::dot(s.upper.normal, s.axis) >= min_cos)) return false;
  return bounding_pyramid(s).proper;
}

namespace {

ChainPath chain_path(const Skeleton& sk, const Chain& chain, uint64_t& skipped) {
  ChainPath path;
  for (uint32_t i = 0; i < chain.joint_count; ++i) {
    const Joint& j = sk.joints[chain.first_joint + i];
    dvec3 p = joint_position(j);
    if (!path.points.empty()) {
      dvec3 d = p - path.points.back();
      double scale = std::max({1.0, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
      if (!(glm::length(d) > 1e-13 * scale)) {  // coincident joints: no segment
        ++skipped;
        continue;
      }
    }
    path.points.push_back(p);
    path.radii.push_back(j.radius_m);
    path.materials.push_back(j.material);
    path.joint_index.push_back(i);
  }
  return path;
}

// One frustum of a ball or dome around a joint: perpendicular cuts, exact normals.
Frustum knuckle_piece(const dvec3& base, const dvec3& axis, double length, double r0, double r1,
                      uint32_t chain, uint32_t joint, uint32_t material, int64_t parent) {
  Frustum f;
  f.kind = FrustumKind::knuckle;
  f.chain = chain;
  f.segment = joint;
  f.material = material;
  f.parent = parent;
  f.shape.base = base;
  f.shape.axis = axis;
  f.shape.length = length;
  f.shape.radius0 = r0;
  f.shape.radius1 = r1;
  f.shape.lower = plane_through(base, axis);
  f.shape.upper = plane_through(base + length * axis, axis);
  f.v_lower_m = 0;
  f.v_upper_m = length;
  return f;
}

// Appends the knuckle ball of radius `radius` around `center`, axis `axis` (skin.h).
void add_knuckle(SkinnedSkeleton& out, const dvec3& center, const dvec3& axis, double radius,
                 int count, uint32_t chain, uint32_t joint, uint32_t material, int64_t parent) {
  double circum = radius / std::cos(kPi / (2.0 * count));  // profile circumscribes the ball
  for (int i = 0; i < count; ++i) {
    double a0 = kPi * i / count, a1 = kPi * (i + 1) / count;
    double y0 = -circum * std::cos(a0), y1 = -circum * std::cos(a1);
    out.frusta.push_back(knuckle_piece(center + y0 * axis, axis, y1 - y0,
                                       i == 0 ? 0.0 : circum * std::sin(a0),
                                       i + 1 == count ? 0.0 : circum * std::sin(a1), chain, joint,
                                       material, parent));
  }
}

// Appends the dome closing a chain end that carries children (docs/joints.md): frusta
// stacked along `axis` from the end joint, their profile inscribed in the ball of the end
// radius (vertices on it), so the first starts at exactly the chain's end radius (no step)
// and the last ends in a tip on the axis. The chain's flat cap lies under it.
// Its u and v go on from the chain's last frustum (u_offset, and v_m from v_end_m), so that
// where the dome shows (beside a continuation that keeps its flat cap) the bark does too.
void add_dome(SkinnedSkeleton& out, const dvec3& centre, const dvec3& axis, double radius,
              int count, uint32_t chain, uint32_t joint, uint32_t material, int64_t parent,
              double u_offset, double v_end_m) {
  for (int i = 0; i < count; ++i) {
    double b0 = 0.5 * kPi * i / count, b1 = 0.5 * kPi * (i + 1) / count;
    Frustum f = knuckle_piece(centre + radius * std::sin(b0) * axis, axis,
                              radius * (std::sin(b1) - std::sin(b0)), radius * std::cos(b0),
                              i + 1 == count ? 0.0 : radius * std::cos(b1), chain, joint, material, parent);
    f.u_offset = u_offset;
    f.v_lower_m = v_end_m + radius * std::sin(b0);
    f.v_upper_m = v_end_m + radius * std::sin(b1);
    out.frusta.push_back(f);
  }
}

// Sec. "Elbows" of docs/joints.md: every interior corner of the path that bends more
// than `over_rad` becomes a circular arc tangent to both legs, 0.45 of the shorter leg
// from the joint, of k >= 2 chords that each turn at most `piece_rad` (the chords turn
// alpha/k at their shared vertices and alpha/2k at the tangent points). An arc whose radius
// would be below the tube's radius (its inner side would fold) is not made: that bend
// stays a mitre, or a split joint with its knuckle. Radii follow the legs' taper; each
// piece keeps its original segment's lower joint and material, split at the arc's middle.
ChainPath round_bends(const ChainPath& path, double over_rad, double piece_rad) {
  const size_t m = path.points.size();
  if (m < 3) return path;
  ChainPath out;
  auto push = [&](const dvec3& p, double r, uint32_t material, uint32_t joint) {
    out.points.push_back(p);
    out.radii.push_back(r);
    out.materials.push_back(material);
    out.joint_index.push_back(joint);
  };
  push(path.points[0], path.radii[0], path.materials[0], path.joint_index[0]);
  for (size_t i = 1; i + 1 < m; ++i) {
    const dvec3& j = path.points[i];
    double len1 = glm::length(j - path.points[i - 1]);
    double len2 = glm::length(path.points[i + 1] - j);
    dvec3 m1 = (j - path.points[i - 1]) / len1;
    dvec3 m2 = (path.points[i + 1] - j) / len2;
    double alpha = std::atan2(glm::length(glm::cross(m1, m2)), glm::dot(m1, m2));
    double d = 0.45 * std::min(len1, len2);
    double rho = alpha > 0 ? d / std::tan(alpha / 2) : 0;
    if (!(alpha > over_rad) || alpha > kPi * 179.0 / 180.0 || !(rho >= path.radii[i])) {
      push(j, path.radii[i], path.materials[i], path.joint_index[i]);
      continue;
    }
    int k = std::max(2, int(std::ceil(alpha / piece_rad)));
    dvec3 toward = glm::normalize(m2 - glm::dot(m2, m1) * m1);  // in the bend plane, ⊥ m1
    dvec3 t1 = j - d * m1;
    dvec3 centre = t1 + rho * toward;
    double r_t1 = path.radii[i] + (path.radii[i - 1] - path.radii[i]) * d / len1;
    double r_t2 = path.radii[i] + (path.radii[i + 1] - path.radii[i]) * d / len2;
    auto first_half = [&](int piece) { return 2 * piece + 1 < k; };
    for (int q = 0; q <= k; ++q) {
      double phi = alpha * q / k;
      dvec3 p = q == 0 ? t1 : q == k ? j + d * m2
                                     : centre - rho * std::cos(phi) * toward + rho * std::sin(phi) * m1;
      uint32_t material = q == 0 || first_half(q - 1) ? path.materials[i] : path.materials[i + 1];
      uint32_t joint = q < k && first_half(q) ? path.joint_index[i - 1] : path.joint_index[i];
      push(p, r_t1 + (r_t2 - r_t1) * q / k, material, joint);
    }
  }
  push(path.points[m - 1], path.radii[m - 1], path.materials[m - 1], path.joint_index[m - 1]);
  return out;
}

// What a chain's attachment looks like from its parent (docs/joints.md).
struct Attachment {
  bool ends_with_children = false;  // a child chain attaches at this chain's last joint
  int64_t continuation = -1;        // the child there most in line with it (within 45°)
  double continuation_cos = 0;      // cos of that child's angle to this chain's end
};

}  // namespace

std::optional<dvec3> chain_direction_at(const Skeleton& sk, const Chain& ch, uint32_t k) {
  dvec3 p = joint_position(sk.joints[ch.first_joint + k]);
  dvec3 sum(0);
  for (uint32_t i = k; i-- > 0;) {
    dvec3 d = p - joint_position(sk.joints[ch.first_joint + i]);
    if (glm::length(d) > 0) { sum += glm::normalize(d); break; }
  }
  for (uint32_t i = k + 1; i < ch.joint_count; ++i) {
    dvec3 d = joint_position(sk.joints[ch.first_joint + i]) - p;
    if (glm::length(d) > 0) { sum += glm::normalize(d); break; }
  }
  if (!(glm::length(sum) > 1e-12)) return std::nullopt;
  return glm::normalize(sum);
}

namespace {

std::vector<Attachment> attachments(const Skeleton& sk) {
  std::vector<Attachment> at(sk.chains.size());
  const double cos_limit = std::cos(kPi / 4);
  for (uint32_t c = 0; c < sk.chains.size(); ++c) {
    const Chain& ch = sk.chains[c];
    if (!ch.parent) continue;
    const Chain& parent = sk.chains[ch.parent->chain];
    if (ch.parent->joint + 1 != parent.joint_count) continue;
    if (!(sk.joints[parent.first_joint + ch.parent->joint].radius_m > 0)) continue;
    Attachment& a = at[ch.parent->chain];
    a.ends_with_children = true;
    std::optional<dvec3> end = chain_direction_at(sk, parent, ch.parent->joint);
    std::optional<dvec3> start = chain_direction_at(sk, ch, 0);
    if (!end || !start) continue;
    double cos_angle = glm::dot(*end, *start);
    if (cos_angle > cos_limit && cos_angle > a.continuation_cos) {
      a.continuation = c;
      a.continuation_cos = cos_angle;
    }
  }
  return at;
}

// The collar of a lateral, or the continuation of its parent's axis (docs/joints.md):
// adjusts the radius at the chain's first point and may insert one point on its first
// segment. Only for a chain that starts at its parent's joint.
void shape_attachment(ChainPath& path, const Skeleton& sk, uint32_t c,
                      const std::vector<Attachment>& at, double flare) {
  const Chain& ch = sk.chains[c];
  if (!ch.parent || path.points.size() < 2) return;
  const Chain& parent = sk.chains[ch.parent->chain];
  const Joint& pj = sk.joints[parent.first_joint + ch.parent->joint];
  const double big_r = pj.radius_m;
  if (!(big_r > 0)) return;
  dvec3 start = path.points[0];
  if (!(glm::length(start - joint_position(pj)) <= 1e-9 * (1 + glm::length(start)))) return;
  const bool at_end = ch.parent->joint + 1 == parent.joint_count;
  if (at_end && at[ch.parent->chain].continuation == int64_t(c)) {
    path.radii[0] = big_r;  // the axis goes on: no radius step
    return;
  }
  std::optional<dvec3> parent_dir = chain_direction_at(sk, parent, ch.parent->joint);
  if (!parent_dir) return;
  double len0 = glm::length(path.points[1] - start);
  dvec3 a = (path.points[1] - start) / len0;
  double sin_t = glm::length(glm::cross(a, *parent_dir));
  // Where the lateral's axis leaves the parent: its tube of radius R, or the end's dome.
  double t_exit = at_end ? big_r : big_r / std::max(sin_t, 1e-6);
  double r_l = path.radii[0];
  // A lateral under a quarter of its parent's radius (a needle, a twig on a limb) makes a
  // crotch too small to see; its collar would double a needled plant's frusta.
  if (!(r_l >= 0.25 * big_r)) return;
  double t_q = std::min(t_exit + r_l, 0.5 * len0);
  if (!(t_q > t_exit + 0.25 * r_l)) return;  // the collar would stay inside the parent
  double r_q = r_l + (path.radii[1] - r_l) * t_q / len0;
  double r_max = (at_end ? 0.98 : 0.9) * big_r;  // the collar's cap stays inside the parent
  double r0 = std::min(r_q + (flare - 1) * r_l * t_q / (t_q - t_exit), r_max);
  if (!(r0 > r_q * 1.001)) return;
  path.points.insert(path.points.begin() + 1, start + t_q * a);
  path.radii.insert(path.radii.begin() + 1, r_q);
  path.materials.insert(path.materials.begin() + 1, path.materials[1]);
  path.joint_index.insert(path.joint_index.begin() + 1, path.joint_index[0]);
  path.radii[0] = r0;
}

// Index of the frustum, among those already emitted, that touches joint `joint` of
// chain `chain` (the segment ending there, else the one starting there).
int64_t frustum_at_joint(const std::vector<int64_t>& first_frustum_of_chain,
                         const std::vector<std::vector<uint32_t>>& segment_lower_joint,
                         uint32_t chain, uint32_t joint) {
  const std::vector<uint32_t>& lows = segment_lower_joint[chain];
  if (lows.empty() || first_frustum_of_chain[chain] < 0) return -1;
  // Segment i spans joints [lows[i], next kept joint]; pick the last one starting below.
  int64_t best = -1;
  for (size_t i = 0; i < lows.size(); ++i) {
    if (lows[i] < joint) best = int64_t(i);
  }
  if (best < 0) best = 0;
  return first_frustum_of_chain[chain] + best;
}

// The u = 0 direction of a frustum (⊥ its axis): raw angle u_offset in axis_frame.
dvec3 u_direction(const Frustum& f) {
  AxisFrame frame = axis_frame(f.shape.axis);
  double angle = 2 * kPi * f.u_offset;
  return std::cos(angle) * frame.e0 + std::sin(angle) * frame.e1;
}

// `radial` (⊥ `from`) carried onto `to` by the rotation that takes `from` to `to` (the
// parallel transport of the chain's u = 0 line across a bend); `fallback` is the rotation
// axis where the two are antiparallel.
dvec3 transport(const dvec3& radial, const dvec3& from, const dvec3& to, const dvec3& fallback = dvec3(0)) {
  dvec3 k = glm::cross(from, to);
  double sin_a = glm::length(k);
  double angle = std::atan2(sin_a, glm::dot(from, to));
  dvec3 out = rotate(radial, sin_a > 1e-12 ? k / sin_a : fallback, angle);
  return glm::normalize(out - glm::dot(out, to) * to);
}

// A chain's polyline as skin_skeleton skins it: zero-length segments dropped, bends
// rounded, its first segment shaped by its attachment.
ChainPath prepared_path(const Skeleton& sk, uint32_t c, const SkinOptions& options,
                        const std::vector<Attachment>& joins, uint64_t& skipped) {
  ChainPath path = chain_path(sk, sk.chains[c], skipped);
  if (options.round_bends_over_deg < 180) {
    path = round_bends(path, deg_to_rad(options.round_bends_over_deg), deg_to_rad(options.round_piece_deg));
  }
  if (options.collars) shape_attachment(path, sk, c, joins, options.collar_flare);
  return path;
}

// Where a continuation (its prepared `child` path) meets `last`, its parent's last
// frustum: the interior joint's construction (with sec. 2.2's fit of the child's base
// radius where options.fit_minor_axis, which must then make the cuts coincide), where it
// needs no split and keeps `last` proper and the child's first segment proper under it
// even with a perpendicular cut at its far end (which the child then falls back to); none
// otherwise.
struct ContinuationStart {
  Plane plane;
  double radius = 0;  // the child's base radius
};
std::optional<ContinuationStart> continuation_mitre(const FrustumShape& last, const ChainPath& child,
                                                    const SkinOptions& options) {
  if (child.points.size() < 2) return std::nullopt;
  const dvec3 end = last.base + last.length * last.axis;
  if (!(glm::length(child.points[0] - end) <= 1e-9 * (1 + glm::length(end)))) return std::nullopt;
  const dvec3 d = child.points[1] - child.points[0];
  const double length = glm::length(d);
  const dvec3 axis = d / length;
  const double max_tilt_rad = deg_to_rad(options.max_tilt_deg);
  ContinuationStart start;
  start.radius = child.radii[0];
  JointCut cut = cutting_plane_at_joint(child.points[0], last.axis, JointSide{last.radius0, last.radius1, last.length},
                                        axis, JointSide{child.radii[1], child.radii[0], length}, max_tilt_rad);
  if (options.fit_minor_axis && !cut.split) {
    const FittedCut fitted =
        fit_minor_axis(cut, child.points[0], last.base, last.axis, last.radius0, last.radius1, last.length, axis,
                       child.radii[0], child.radii[1], length, max_tilt_rad, options.fit_tolerance,
                       options.fit_max_iterations);
    // A mitre whose cuts would not coincide leaves a crack as wide as the mismatch: on the
    // elm up to 5 cm, where a twig tip goes on from its branch's end at the end's radius
    // and tapers to a third of it within 8 cm, the plane clamped to the tilt limit. There
    // the two keep their flat caps under the dome.
    if (!fitted.matched) return std::nullopt;
    cut = fitted.cut;
    start.radius = fitted.radius;
  }
  if (cut.split) return std::nullopt;
  FrustumShape parent = last;
  parent.upper = cut.plane;
  parent.cap_upper = false;
  FrustumShape first;
  first.base = child.points[0];
  first.axis = axis;
  first.length = length;
  first.radius0 = start.radius;
  first.radius1 = child.radii[1];
  first.lower = cut.plane;
  first.upper = plane_through(child.points[1], axis);
  if (!cuts_are_proper(parent, options.max_tilt_deg) || !cuts_are_proper(first, options.max_tilt_deg)) {
    return std::nullopt;
  }
  start.plane = cut.plane;
  return start;
}

// The frustum a continuation goes on from: its parent's last segment frustum, when chain
// `c` is the continuation of its parent (attachments) and starts at that frustum's end;
// else -1.
int64_t continued_from(const Skeleton& sk, uint32_t c, const std::vector<Attachment>& at,
                             const std::vector<int64_t>& first_frustum_of_chain,
                             const std::vector<std::vector<uint32_t>>& segment_lower_joint,
                             const SkinnedSkeleton& out, const dvec3& start) {
  const Chain& ch = sk.chains[c];
  if (!ch.parent || at[ch.parent->chain].continuation != int64_t(c)) return -1;
  int64_t f = frustum_at_joint(first_frustum_of_chain, segment_lower_joint, ch.parent->chain, ch.parent->joint);
  if (f < 0) return -1;
  const Frustum& pf = out.frusta[size_t(f)];
  if (pf.kind != FrustumKind::segment || pf.chain != ch.parent->chain) return -1;
  dvec3 end = pf.shape.base + pf.shape.length * pf.shape.axis;
  if (!(glm::length(end - start) <= 1e-9 * (1 + glm::length(start)))) return -1;
  return f;
}

}  // namespace

std::vector<int64_t> continuation_children(const Skeleton& sk) {
  std::vector<int64_t> out;
  out.reserve(sk.chains.size());
  for (const Attachment& a : attachments(sk)) out.push_back(a.continuation);
  return out;
}

SkinnedSkeleton skin_skeleton(const Skeleton& sk, const SkinOptions& options) {
  Expected<SkinnedSkeleton> skinned = skin_skeleton(sk, options, Progress{});
  return std::move(*skinned);  // never cancelled without a flag
}

Expected<SkinnedSkeleton> skin_skeleton(const Skeleton& sk, const SkinOptions& options, const Progress& progress) {
  assert(validate_skeleton(sk).ok() && "skin_skeleton: skeleton violates its invariants");
  assert(options.max_tilt_deg > 0 && options.max_tilt_deg <= 80);
  assert(options.knuckle_frusta >= 2);
  assert(options.collar_flare >= 1);
  assert(options.round_piece_deg > 0 && options.round_piece_deg <= options.round_bends_over_deg);
  const double max_tilt_rad = deg_to_rad(options.max_tilt_deg);
  SkinnedSkeleton out;
  std::vector<int64_t> first_frustum_of_chain(sk.chains.size(), -1);
  std::vector<std::vector<uint32_t>> segment_lower_joint(sk.chains.size());
  const std::vector<Attachment> joins = options.collars ? attachments(sk) : std::vector<Attachment>(sk.chains.size());
  std::vector<std::optional<ContinuationStart>> mitre_below(sk.chains.size());  // a continuation's start
  uint64_t lookahead_skipped = 0;  // counted again when the continuation is skinned

  for (uint32_t c = 0; c < sk.chains.size(); ++c) {
    if ((c & kProgressChunkMask) == 0 && c != 0) {  // between chunks of chains
      if (progress.cancelled()) return cancelled_diagnostic();
      progress.report(static_cast<double>(c) / static_cast<double>(sk.chains.size()), "skin");
    }
    const Chain& chain = sk.chains[c];
    const ChainPath path = prepared_path(sk, c, options, joins, out.zero_length_skipped);
    const size_t n = path.points.size() < 2 ? 0 : path.points.size() - 1;  // segments
    if (n == 0) continue;
    std::vector<dvec3> axis(n);
    std::vector<double> length(n);
    for (size_t s = 0; s < n; ++s) {
      dvec3 d = path.points[s + 1] - path.points[s];
      length[s] = glm::length(d);
      axis[s] = d / length[s];
    }
    // Cutting planes: planes[i] at kept joint i; split[i] for sharp interior joints.
    std::vector<Plane> planes(n + 1);
    std::vector<bool> split(n + 1, false);
    std::vector<double> radius_lower(n);  // radius0 per segment (minor-axis fit may move it)
    std::vector<bool> clamped(n + 1, false);
    std::vector<dvec3> bend_normal(n + 1, dvec3(0));
    // A continuation (docs/joints.md "Continuations") carries its parent's u and v on, and
    // meets the parent's last frustum in the mitred plane its parent chose (if it did).
    const int64_t continued = continued_from(sk, c, joins, first_frustum_of_chain,
                                             segment_lower_joint, out, path.points[0]);
    const std::optional<ContinuationStart> inherited_lower = continued >= 0 ? mitre_below[c] : std::nullopt;
    for (int pass = 0;; ++pass) {
      assert(pass <= int(n) + 1);
      for (size_t s = 0; s < n; ++s) radius_lower[s] = path.radii[s];
      if (inherited_lower) radius_lower[0] = inherited_lower->radius;
      planes[0] = inherited_lower ? inherited_lower->plane : plane_through(path.points[0], axis[0]);
      planes[n] = plane_through(path.points[n], axis[n - 1]);
      for (size_t i = 1; i < n; ++i) {
        clamped[i] = false;
        JointSide below{radius_lower[i - 1], path.radii[i], length[i - 1]};
        auto make_cut = [&](double r_joint_above) {
          JointSide above{path.radii[i + 1], r_joint_above, length[i]};
          return cutting_plane_at_joint(path.points[i], axis[i - 1], below, axis[i], above,
                                        max_tilt_rad);
        };
        JointCut cut = make_cut(path.radii[i]);
        bend_normal[i] = cut.medial_normal;
        if (!split[i] && cut.split) split[i] = true;
        if (split[i]) continue;
        if (options.fit_minor_axis) {
          const FittedCut fitted =
              fit_minor_axis(cut, path.points[i], path.points[i - 1], axis[i - 1], radius_lower[i - 1],
                             path.radii[i], length[i - 1], axis[i], path.radii[i], path.radii[i + 1], length[i],
                             max_tilt_rad, options.fit_tolerance, options.fit_max_iterations);
          cut = fitted.cut;
          radius_lower[i] = fitted.radius;
        }
        planes[i] = cut.plane;
        clamped[i] = cut.clamped;
      }
      // Split joints: perpendicular planes on both sides (resolved per segment below).
      auto lower_plane = [&](size_t s) {
        return split[s] ? plane_through(path.points[s], axis[s]) : planes[s];
      };
      auto upper_plane = [&](size_t s) {
        return split[s + 1] ? plane_through(path.points[s + 1], axis[s]) : planes[s + 1];
      };
      bool changed = false;
      for (size_t s = 0; s < n; ++s) {
        FrustumShape shape;
        shape.base = path.points[s];
        shape.axis = axis[s];
        shape.length = length[s];
        shape.radius0 = radius_lower[s];
        shape.radius1 = path.radii[s + 1];
        shape.lower = lower_plane(s);
        shape.upper = upper_plane(s);
        if (cuts_are_proper(shape, options.max_tilt_deg)) continue;
        // Split the more tilted interior end; a segment with both ends perpendicular is
        // always proper (parallel planes length apart), so this terminates.
        // A continuation's mitred start stays (its parent is already emitted): its next
        // joint is split instead, which its parent checked keeps it proper.
        double tilt_lower = s > 0 && !split[s] ? 1 - glm::dot(shape.lower.normal, shape.axis) : -1;
        double tilt_upper =
            s + 1 < n && !split[s + 1] ? 1 - glm::dot(shape.upper.normal, shape.axis) : -1;
        if (tilt_lower < 0 && tilt_upper < 0) continue;  // unreachable: both perpendicular
        split[tilt_lower >= tilt_upper ? s : s + 1] = true;
        changed = true;
        break;  // recompute planes (the fit of later joints depends on earlier ones)
      }
      if (!changed) {
        // Emit the chain.
        const int64_t chain_first = int64_t(out.frusta.size());
        first_frustum_of_chain[c] = chain_first;
        int64_t parent = -1;
        if (chain.parent) {
          parent = frustum_at_joint(first_frustum_of_chain, segment_lower_joint,
                                    chain.parent->chain, chain.parent->joint);
        }
        dvec3 transported = axis_frame(axis[0]).e0;  // u = 0 direction carried along
        double arc = 0;
        if (continued >= 0) {  // u and v go on from the parent's last frustum
          const Frustum& pf = out.frusta[size_t(continued)];
          transported = transport(u_direction(pf), pf.shape.axis, axis[0]);
          arc = pf.v_upper_m;
        }
        std::vector<size_t> segment_frustum(n);
        for (size_t s = 0; s < n; ++s) {
          if (s > 0) {
            transported = transport(transported, axis[s - 1], axis[s], bend_normal[s]);
          }
          Frustum f;
          f.chain = c;
          f.segment = path.joint_index[s];
          f.material = path.materials[s + 1];
          f.parent = s == 0 ? parent : int64_t(segment_frustum[s - 1]);
          f.shape.base = path.points[s];
          f.shape.axis = axis[s];
          f.shape.length = length[s];
          f.shape.radius0 = radius_lower[s];
          f.shape.radius1 = path.radii[s + 1];
          f.shape.lower = lower_plane(s);
          f.shape.upper = upper_plane(s);
          f.shape.cap_lower = ((s == 0 && !inherited_lower) || split[s]) && f.shape.radius0 > 0;
          f.shape.cap_upper = (s + 1 == n || split[s + 1]) && f.shape.radius1 > 0;
          f.u_offset = raw_u(axis[s], transported);
          f.twist_rad_per_m = options.twist_rad_per_m;
          f.v_lower_m = arc;
          arc += length[s];
          f.v_upper_m = arc;
          segment_frustum[s] = out.frusta.size();
          segment_lower_joint[c].push_back(path.joint_index[s]);
          out.frusta.push_back(f);
        }
        for (size_t i = 1; i < n; ++i) {
          if (split[i]) {
            ++out.split_joints;
            if (path.radii[i] > 0) {
              add_knuckle(out, path.points[i], bend_normal[i], path.radii[i],
                          options.knuckle_frusta, c, path.joint_index[i],
                          path.materials[i], int64_t(segment_frustum[i - 1]));
            }
          } else if (clamped[i]) {
            ++out.clamped_joints;
          }
        }
        // The continuation's start: mitred onto this chain's end where the plane keeps
        // both frusta proper, and then no dome (the two tubes hold the ball of the end
        // radius; a dome inscribed in it would stick out where the continuation tapers).
        bool mitred = false;
        if (joins[c].continuation >= 0) {
          Frustum& last = out.frusta[segment_frustum[n - 1]];
          std::optional<ContinuationStart> mitre = continuation_mitre(
              last.shape, prepared_path(sk, uint32_t(joins[c].continuation), options, joins, lookahead_skipped),
              options);
          if (mitre) {
            last.shape.upper = mitre->plane;
            last.shape.cap_upper = false;
            mitre_below[size_t(joins[c].continuation)] = mitre;
            mitred = true;
          }
        }
        if (joins[c].ends_with_children && path.radii[n] > 0 && !mitred) {
          const Frustum& last = out.frusta[segment_frustum[n - 1]];
          add_dome(out, path.points[n], axis[n - 1], path.radii[n], std::max(2, options.knuckle_frusta / 2), c,
                   path.joint_index[n], path.materials[n], int64_t(segment_frustum[n - 1]), last.u_offset,
                   last.v_upper_m);
        }
        break;
      }
    }
  }
  progress.report(1, "skin");
  return out;
}

// ---- GPU record ----------------------------------------------------------------------

namespace {

void put_bits(uint32_t (&words)[4], int first_bit, int count, uint32_t value) {
  for (int b = 0; b < count; ++b) {
    int bit = first_bit + b;
    if ((value >> b) & 1u) words[bit / 32] |= 1u << (bit % 32);
  }
}

uint32_t get_bits(const uint32_t (&words)[4], int first_bit, int count) {
  uint32_t v = 0;
  for (int b = 0; b < count; ++b) {
    int bit = first_bit + b;
    if ((words[bit / 32] >> (bit % 32)) & 1u) v |= 1u << b;
  }
  return v;
}

// snorm with `bits` bits: x in [-1,1] to two's complement.
uint32_t encode_snorm(double x, int bits) {
  double max = double((1u << (bits - 1)) - 1);
  auto q = int32_t(std::lround(std::clamp(x, -1.0, 1.0) * max));
  return uint32_t(q) & ((1u << bits) - 1);
}

double decode_snorm(uint32_t v, int bits) {
  double max = double((1u << (bits - 1)) - 1);
  int32_t q = int32_t(v << (32 - bits)) >> (32 - bits);  // sign-extend
  return std::max(-1.0, q / max);
}

// Residual scale of one origin component: >= one float ulp of it, so |res|/scale <= 0.5.
double residual_scale(float hi) { return std::max(std::abs(double(hi)), 1e-30) * std::ldexp(1.0, -23); }

}  // namespace

GpuSegment pack_gpu_segment(const Frustum& fr) {
  const FrustumShape& s = fr.shape;
  GpuSegment g{};
  for (int i = 0; i < 3; ++i) {
    g.origin_hi[i] = float(s.base[i]);
    g.axis_scaled[i] = float(s.axis[i] * s.length);
    double res = s.base[i] - double(g.origin_hi[i]);
    put_bits(g.bits, 16 * i, 16, encode_snorm(2.0 * res / residual_scale(g.origin_hi[i]), 16));
  }
  g.radius0 = float(s.radius0);
  g.radius1 = float(s.radius1);
  // Planes as (axis crossing, normal): relative to base, so no large offsets in float.
  g.lower_axis_y = float((s.lower.offset - glm::dot(s.lower.normal, s.base)) /
                         glm::dot(s.lower.normal, s.axis));
  g.upper_axis_y = float((s.upper.offset - glm::dot(s.upper.normal, s.base)) /
                         glm::dot(s.upper.normal, s.axis));
  g.v_lower_m = float(fr.v_lower_m);
  uint32_t u16 = uint32_t(std::lround(wrap_turns(fr.u_offset) * 65536.0)) & 0xFFFFu;
  uint32_t material = std::min<uint32_t>(fr.material, 255u);
  g.meta = u16 | (material << 16) | (uint32_t(s.cap_lower) << 24) |
           (uint32_t(s.cap_upper) << 25) | (uint32_t(fr.kind == FrustumKind::knuckle) << 26);
  AxisFrame f = axis_frame(s.axis);
  put_bits(g.bits, 48, 20, encode_snorm(glm::dot(s.lower.normal, f.e0), 20));
  put_bits(g.bits, 68, 20, encode_snorm(glm::dot(s.lower.normal, f.e1), 20));
  put_bits(g.bits, 88, 20, encode_snorm(glm::dot(s.upper.normal, f.e0), 20));
  put_bits(g.bits, 108, 20, encode_snorm(glm::dot(s.upper.normal, f.e1), 20));
  return g;
}

UnpackedGpuSegment unpack_gpu_segment(const GpuSegment& g) {
  UnpackedGpuSegment u;
  FrustumShape& s = u.shape;
  dvec3 axis_scaled;
  for (int i = 0; i < 3; ++i) {
    double res = 0.5 * decode_snorm(get_bits(g.bits, 16 * i, 16), 16) *
                 residual_scale(g.origin_hi[i]);
    s.base[i] = double(g.origin_hi[i]) + res;
    axis_scaled[i] = double(g.axis_scaled[i]);
  }
  s.length = glm::length(axis_scaled);
  s.axis = axis_scaled / s.length;
  s.radius0 = g.radius0;
  s.radius1 = g.radius1;
  AxisFrame f = axis_frame(s.axis);
  auto normal = [&](int first_bit) {
    double a = decode_snorm(get_bits(g.bits, first_bit, 20), 20);
    double b = decode_snorm(get_bits(g.bits, first_bit + 20, 20), 20);
    double c = std::sqrt(std::max(0.0, 1 - a * a - b * b));
    return glm::normalize(a * f.e0 + b * f.e1 + c * s.axis);
  };
  s.lower.normal = normal(48);
  s.upper.normal = normal(88);
  s.lower.offset = glm::dot(s.lower.normal, s.base + double(g.lower_axis_y) * s.axis);
  s.upper.offset = glm::dot(s.upper.normal, s.base + double(g.upper_axis_y) * s.axis);
  s.cap_lower = (g.meta >> 24) & 1u;
  s.cap_upper = (g.meta >> 25) & 1u;
  u.knuckle = (g.meta >> 26) & 1u;
  u.material = (g.meta >> 16) & 0xFFu;
  u.u_offset = (g.meta & 0xFFFFu) / 65536.0;
  u.v_lower_m = g.v_lower_m;
  return u;
}

}  // namespace sylva
