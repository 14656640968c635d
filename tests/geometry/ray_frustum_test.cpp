// Tests for core/geometry/ray_frustum.h: ray against one conical frustum (Bhagvat et al. 2009 sec. 2.5).
//
// RayFrustum.* are specifications on hand-made shapes with hand-computed answers.
// StiffCases.* is the stiff-case suite of docs/accuracy.md: a table of frusta and rays
// (r1/r0, angle to a generator line, origin inside/outside, offsets, radii, joint angles,
// antiparallel axes) plus thousands of random ones, each compared with a reference
// computed here in long double by a different algorithm: an exact re-centring by steps of
// 11 significant bits, an explicit local frame, textbook and vertex-form roots of eq. 10
// (no stable root pair), each polished by Newton on the implicit function x² + z² − r(y)²
// evaluated point by point along the ray. SYLVA_RAY_DEBUG=1 prints the inputs of any
// double disagreement in hex floats (to recheck them at high precision, e.g. mpmath).
//
// Error measures (one distance scale S per ray, metres):
//   S = max(|t_ref|·|d|, length + max(radius0, radius1))
// the larger of the distance the ray travels to the hit and the size of the frustum;
// t error = |t − t_ref|·|d| / S (double: ≤ 1e-9, float twin: ≤ 1e-4 where the ray meets
// the surface at |cos(incidence)| ≥ kFloatWellConditionedCos); normal error = angle
// between unit normals (double: ≤ 1e-6 rad).
// The grazing band, where hit/miss (or side/cap) may flip by rounding and t may disagree:
// the earlier of the two hits lies within kEdgeBand·S of an edge of its face (a cutting
// plane, a cap rim, the apex) or meets the surface at |cos(incidence)| ≤ kGrazingCos. Any
// hit, in or out of the band, must lie within kSurfaceTolerance·S of the face it claims.
// With SYLVA_ACCURACY_TABLE=path set, the suite writes the worst errors per case there as
// the markdown table of docs/accuracy.md.
#include "core/geometry/ray_frustum.h"
#include "core/geometry/skin.h"
#include "core/util/math.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <glm/geometric.hpp>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace sylva {
namespace {

using LD = long double;

// Double: the suite's bounds.
constexpr double kDoubleTTolerance = 1e-9;
constexpr double kDoubleNormalTolerance = 1e-6;  // radians
constexpr double kDoubleEdgeBand = 1e-9;         // × S
constexpr double kDoubleGrazingCos = 1e-6;
constexpr double kDoubleSurfaceTolerance = 1e-9;  // × S
// Float twin.
constexpr double kFloatTTolerance = 1e-4;
constexpr double kFloatWellConditionedCos = 0.02;  // below, t error grows as ε_f/|cos|
constexpr double kFloatEdgeBand = 1e-5;            // × S
constexpr double kFloatGrazingCos = 3e-3;
constexpr double kFloatSurfaceTolerance = 1e-4;  // × S


// ---- Long double reference -------------------------------------------------------------

struct V3 {
  LD x = 0, y = 0, z = 0;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(LD s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
LD dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross3(V3 a, V3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
V3 unit3(V3 a) { return (1.0L / std::sqrt(dot3(a, a))) * a; }
V3 ld(const glm::dvec3& v) { return {LD(v.x), LD(v.y), LD(v.z)}; }

// The shape in long double with an explicit orthonormal frame (X, Y = axis, Z).
struct RefShape {
  V3 base, X, Y, Z;
  LD length, radius0, slope;
  V3 lower_n, upper_n;
  LD lower_offset, upper_offset;  // relative to the base (error ~1e-19·|base|)
  bool cap_lower, cap_upper;
  explicit RefShape(const FrustumShape& s)
      : base(ld(s.base)),
        length(s.length),
        radius0(s.radius0),
        slope((LD(s.radius1) - LD(s.radius0)) / LD(s.length)),
        lower_n(ld(s.lower.normal)),
        upper_n(ld(s.upper.normal)),
        lower_offset(LD(s.lower.offset) - dot3(ld(s.lower.normal), ld(s.base))),
        upper_offset(LD(s.upper.offset) - dot3(ld(s.upper.normal), ld(s.base))),
        cap_lower(s.cap_lower),
        cap_upper(s.cap_upper) {
    Y = unit3(ld(s.axis));
    const V3 helper = std::fabs(Y.x) < 0.6L ? V3{1, 0, 0} : V3{0, 0, 1};
    X = unit3(helper - dot3(helper, Y) * Y);
    Z = cross3(X, Y);
  }
  // Points are relative to the base everywhere below.
  V3 local(V3 p) const { return {dot3(p, X), dot3(p, Y), dot3(p, Z)}; }
  V3 local_dir(V3 d) const { return {dot3(d, X), dot3(d, Y), dot3(d, Z)}; }
  LD radius(LD y) const { return radius0 + slope * y; }
  LD lower_side(V3 p) const { return dot3(lower_n, p) - lower_offset; }  // >= 0 inside
  LD upper_side(V3 p) const { return upper_offset - dot3(upper_n, p); }  // >= 0 inside
};

struct RefHit {
  FrustumHitKind kind = FrustumHitKind::none;
  LD t = 0;
  V3 point, normal;
};

// The implicit function along the ray, evaluated at the point (not from coefficients).
LD implicit_at(const RefShape& s, V3 lo, V3 ld_dir, LD t) {
  const V3 p = lo + t * ld_dir;
  const LD r = s.radius(p.y);
  return p.x * p.x + p.z * p.z - r * r;
}

LD polish_root(const RefShape& s, V3 lo, V3 ldir, LD t) {
  LD best = t, best_value = std::fabs(implicit_at(s, lo, ldir, t));
  for (int i = 0; i < 40 && best_value > 0; ++i) {
    const V3 p = lo + best * ldir;
    const LD r = s.radius(p.y);
    const LD derivative = 2 * (p.x * ldir.x + p.z * ldir.z - r * s.slope * ldir.y);
    if (derivative == 0) break;
    const LD next = best - implicit_at(s, lo, ldir, best) / derivative;
    const LD value = std::fabs(implicit_at(s, lo, ldir, next));
    if (!(value < best_value)) break;
    best = next;
    best_value = value;
  }
  return best;
}

V3 side_normal(const RefShape& s, V3 point) {
  const V3 p = s.local(point);
  const LD radial = std::sqrt(p.x * p.x + p.z * p.z);
  if (radial == 0) return {0, 0, 0};
  const V3 e = (1 / radial) * (p.x * s.X + p.z * s.Z);
  return unit3(e - s.slope * s.Y);
}

// The ray origin relative to the base, moved along the ray toward the segment's midpoint
// in steps of 11 significant bits: each step's s·d is exact in long double (11 + 53 ≤ 64
// bits) and so is each sum, so the moved origin is exact however far the eye is. Returns
// the total shift (t = shift + t_local).
LD exact_recentre(const RefShape& s, V3 relative, V3 d, V3& moved) {
  LD shift = 0;
  moved = relative;
  for (int step = 0; step < 12; ++step) {
    const V3 mid = (0.5L * s.length) * s.Y;
    LD t = dot3(mid - moved, d) / dot3(d, d);
    if (t == 0) break;
    int exponent = 0;
    std::frexp(t, &exponent);
    t = std::ldexp(std::round(std::ldexp(t, 11 - exponent)), exponent - 11);
    moved = moved + t * d;
    shift += t;
  }
  return shift;
}

RefHit reference_intersect(const FrustumShape& shape, const Ray& ray, double t_min,
                           double t_max) {
  const RefShape s(shape);
  const V3 o = ld(ray.origin), d = ld(ray.direction);
  V3 moved;
  const LD shift = exact_recentre(s, o - s.base, d, moved);
  const V3 lo = s.local(moved), ldir = s.local_dir(d);
  RefHit best;
  best.t = std::numeric_limits<LD>::infinity();
  // Candidates are in t_local; points relative to the base are moved + t_local·d.
  auto consider = [&](FrustumHitKind kind, LD t_local) {
    const LD t = shift + t_local;
    if (!(t > t_min && t < t_max && t < best.t)) return;
    best = {kind, t, moved + t_local * d, {}};
  };
  // Side: candidate roots from the textbook formula of eq. 10, from the vertex form
  // t = t_c ± √(−g(t_c)/a) with g(t_c) evaluated at the point (accurate near tangency, where
  // the textbook discriminant cancels even in long double), and from the linear equation;
  // each polished by Newton on the implicit function and kept if it is a root there.
  const LD rho = s.radius(lo.y);
  const LD a = ldir.x * ldir.x + ldir.z * ldir.z - s.slope * s.slope * ldir.y * ldir.y;
  const LD b = 2 * (lo.x * ldir.x + lo.z * ldir.z - s.slope * rho * ldir.y);
  const LD c = lo.x * lo.x + lo.z * lo.z - rho * rho;
  std::vector<LD> roots;
  if (b != 0) roots.push_back(-c / b);
  if (a != 0) {
    const LD disc = b * b - 4 * a * c;
    if (disc >= 0) {
      roots.push_back((-b - std::sqrt(disc)) / (2 * a));
      roots.push_back((-b + std::sqrt(disc)) / (2 * a));
    }
    const LD t_vertex = -b / (2 * a);
    const LD half_width_sq = -implicit_at(s, lo, ldir, t_vertex) / a;
    if (half_width_sq >= 0) {
      roots.push_back(t_vertex - std::sqrt(half_width_sq));
      roots.push_back(t_vertex + std::sqrt(half_width_sq));
    }
  }
  for (LD t : roots) {
    if (!std::isfinite(t)) continue;
    t = polish_root(s, lo, ldir, t);
    const V3 p = moved + t * d;
    const V3 q = s.local(p);
    // A root where |g| / (2R), the distance off the surface, is within 32 long double
    // ulps of the coordinates it was computed from (a near miss polished to the minimum
    // of g is not a root).
    const LD size = std::sqrt(q.x * q.x + q.z * q.z + s.radius(q.y) * s.radius(q.y));
    const LD magnitude = std::sqrt(dot3(lo, lo)) + std::fabs(t) * std::sqrt(dot3(ldir, ldir));
    constexpr LD kRootUlps = 32 * std::numeric_limits<LD>::epsilon();
    if (!(std::fabs(implicit_at(s, lo, ldir, t)) <= 2 * size * kRootUlps * (magnitude + size)))
      continue;  // not a root
    if (s.radius(q.y) < 0) continue;
    if (s.lower_side(p) < 0 || s.upper_side(p) < 0) continue;
    consider(FrustumHitKind::side, t);
  }
  // Caps: the plane, inside the cone, on the right nappe, inside the other plane.
  auto cap = [&](bool present, V3 n, LD offset, FrustumHitKind kind) {
    if (!present) return;
    const LD denominator = dot3(n, d);
    if (denominator == 0) return;
    const LD t = (offset - dot3(n, moved)) / denominator;
    const V3 p = moved + t * d;
    const V3 q = s.local(p);
    const LD r = s.radius(q.y);
    if (!(r > 0) || q.x * q.x + q.z * q.z > r * r) return;
    if (kind == FrustumHitKind::lower_cap ? s.upper_side(p) < 0 : s.lower_side(p) < 0) return;
    consider(kind, t);
  };
  cap(s.cap_lower, s.lower_n, s.lower_offset, FrustumHitKind::lower_cap);
  cap(s.cap_upper, s.upper_n, s.upper_offset, FrustumHitKind::upper_cap);
  if (best.kind == FrustumHitKind::side) best.normal = side_normal(s, best.point);
  if (best.kind == FrustumHitKind::lower_cap) best.normal = LD(-1) * s.lower_n;
  if (best.kind == FrustumHitKind::upper_cap) best.normal = s.upper_n;
  return best;
}

// Where a hit of `kind` at world point p lies relative to its face, in metres.
struct FaceDistances {
  LD to_surface;  // off the face's surface (cone or plane)
  LD to_edge;     // to the nearest edge of the face (planes, rim, apex)
  LD cos_incidence;
};

FaceDistances face_distances(const FrustumShape& shape, FrustumHitKind kind, V3 p, V3 d) {
  const RefShape s(shape);
  const V3 q = s.local(p);
  const LD radial = std::sqrt(q.x * q.x + q.z * q.z);
  const LD r = s.radius(q.y);
  const LD lower = s.lower_side(p), upper = s.upper_side(p);
  FaceDistances f{};
  V3 normal;
  if (kind == FrustumHitKind::side) {
    f.to_surface = std::fabs(radial - r) / std::sqrt(1 + s.slope * s.slope);
    f.to_edge = std::min({std::fabs(lower), std::fabs(upper), std::fabs(r)});
    normal = side_normal(s, p);
  } else {
    const bool is_lower = kind == FrustumHitKind::lower_cap;
    f.to_surface = std::fabs(is_lower ? lower : upper);
    f.to_edge = std::min(std::fabs(radial - r), std::fabs(is_lower ? upper : lower));
    normal = is_lower ? s.lower_n : s.upper_n;
  }
  f.cos_incidence = std::fabs(dot3(normal, d)) / std::sqrt(dot3(d, d));
  return f;
}

double angle_between(glm::dvec3 a, V3 b) {
  const LD c = std::clamp(dot3(unit3(ld(a)), unit3(b)), -1.0L, 1.0L);
  const LD s = std::sqrt(dot3(cross3(unit3(ld(a)), unit3(b)), cross3(unit3(ld(a)), unit3(b))));
  return double(std::atan2(s, c));
}

// ---- Accumulating the table ------------------------------------------------------------

struct Worst {
  long rays = 0;
  double double_t = 0, double_normal = 0, float_t = 0, float_t_well = 0, float_normal = 0;
  long double_flips_in_band = 0, double_flips_out = 0;
  long float_flips_in_band = 0, float_flips_out = 0;
  long float_ill_conditioned = 0;  // hits with |cos| < kFloatWellConditionedCos
};

struct Table {
  std::vector<std::string> order;
  std::map<std::string, Worst> rows;
  Worst& row(const std::string& name) {
    if (!rows.count(name)) order.push_back(name);
    return rows[name];
  }
};

Table& table() {
  static Table t;
  return t;
}

std::string sci(double v) {
  if (v == 0) return "0";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1e", v);
  return buffer;
}

void write_table_if_asked() {
  const char* path = std::getenv("SYLVA_ACCURACY_TABLE");
  if (!path) return;
  std::ofstream out(path);
  out << "| case | rays | double: max t err | double: max normal err (rad) | double: "
         "flips in band / outside | float: max t err (well-cond.) | float: max t err (all) "
         "| float: max normal err (rad) | float: ill-cond. hits | float: flips in band / "
         "outside |\n";
  out << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  // Rows grouped by table dimension, in the order of the list.
  const std::vector<std::string> groups = {"all", "r1/r0", "angle to generator", "crossing",
                                           "origin", "offset", "radius0", "joint", "axis",
                                           "antiparallel ray", "along", "parallel", "head-on",
                                           "tangent", "on a generator", "random"};
  auto rank = [&](const std::string& name) {
    for (size_t i = 0; i < groups.size(); ++i)
      if (name.rfind(groups[i], 0) == 0) return i;
    return groups.size();
  };
  std::vector<std::string> order = table().order;
  std::stable_sort(order.begin(), order.end(),
                   [&](const std::string& x, const std::string& y) { return rank(x) < rank(y); });
  for (const std::string& name : order) {
    const Worst& w = table().rows[name];
    out << "| " << name << " | " << w.rays << " | " << sci(w.double_t) << " | "
        << sci(w.double_normal) << " | " << w.double_flips_in_band << " / "
        << w.double_flips_out << " | " << sci(w.float_t_well) << " | " << sci(w.float_t)
        << " | " << sci(w.float_normal) << " | " << w.float_ill_conditioned << " | "
        << w.float_flips_in_band << " / " << w.float_flips_out << " |\n";
  }
}

// ---- Comparing one ray -----------------------------------------------------------------

struct Candidate {
  bool hit;
  FrustumHitKind kind;
  LD t;
  V3 point;
};

// True when the earlier of two disagreeing hits lies in the grazing band: within
// edge_band·scale of an edge of its face or of the start of the range (an origin on the
// surface), or meeting the surface at |cos| ≤ grazing_cos, or at |cos| ≤ √(2δ/r), the
// incidence of a chord of depth δ ≈ 64 long double ulps of the segment's size — below it
// the long double reference itself cannot tell a graze from a miss. own_depth: the same
// for the version under test (the float twin rounds at ε_f of the eye's distance).
bool in_band(const FrustumShape& shape, const Candidate& a, const Candidate& b, V3 d,
             LD scale, double edge_band, double grazing_cos, LD own_depth = 0) {
  const Candidate& earlier = !a.hit ? b : !b.hit ? a : (a.t <= b.t ? a : b);
  const FaceDistances f = face_distances(shape, earlier.kind, earlier.point, d);
  const LD dir_length = std::sqrt(dot3(d, d));
  // The reference re-centres exactly; what it still rounds is long double on the
  // segment's own size and on the plane offsets' |base|.
  const LD reference_depth =
      64 * std::numeric_limits<LD>::epsilon() *
      (LD(shape.length) + std::max(shape.radius0, shape.radius1) +
       std::sqrt(dot3(ld(shape.base), ld(shape.base))) * 1e-3L);
  const LD radius = std::max<LD>(std::max(shape.radius0, shape.radius1), 1e-300L);
  const LD reference_cos = std::sqrt(2 * std::max(reference_depth, own_depth) / radius);
  return f.to_edge <= edge_band * scale || std::fabs(earlier.t) * dir_length <= edge_band * scale ||
         f.cos_incidence <= std::max<LD>(grazing_cos, reference_cos);
}

struct RayCase {
  FrustumShape shape;
  Ray ray;
  std::vector<std::string> labels;
};

void check_ray(const RayCase& c) {
  const FrustumShape& shape = c.shape;
  const Ray& ray = c.ray;
  const double t_min = 0, t_max = std::numeric_limits<double>::infinity();
  const RefHit ref = reference_intersect(shape, ray, t_min, t_max);
  const FrustumHit hit = intersect_frustum(ray, shape, t_min, t_max);
  const FrustumHitF hit_f = intersect_frustum_f(to_float_ray(ray, shape.base),
                                                to_float_shape(shape, shape.base),
                                                float(t_min), float(t_max));
  const V3 o = ld(ray.origin), d = ld(ray.direction);
  const LD dir_length = std::sqrt(dot3(d, d));
  const LD extent = LD(shape.length) + std::max(shape.radius0, shape.radius1);
  std::string where;
  for (const std::string& l : c.labels) where += l + "; ";
  SCOPED_TRACE(where);

  const Candidate ref_c{ref.kind != FrustumHitKind::none, ref.kind, ref.t, ref.point};
  const V3 o_rel = o - ld(shape.base);  // exact for the suite's inputs
  const Candidate dbl_c{hit.hit(), hit.kind, LD(hit.t), o_rel + LD(hit.t) * d};
  // The float twin's hit point on its own (rounded) ray: what it claims is on the surface.
  const RayF ray_f = to_float_ray(ray, shape.base);
  const V3 o_f = ld(glm::dvec3(ray_f.origin));  // relative to the base
  const V3 d_f = ld(glm::dvec3(ray_f.direction));
  const Candidate flt_c{hit_f.kind != 0, FrustumHitKind(hit_f.kind), LD(hit_f.t),
                        o_f + LD(hit_f.t) * d_f};
  const LD t_scale = std::max({ref_c.hit ? std::fabs(ref.t) : 0.0L,
                               dbl_c.hit ? std::fabs(dbl_c.t) : 0.0L}) *
                     dir_length;
  const LD scale = std::max(t_scale, extent);
  // The float twin's scale also holds the eye's distance from the segment: its re-centring
  // rounds there (ε_f·|o − base|), as the GLSL will.
  const V3 eye_offset = o - ld(shape.base);
  const LD scale_f = std::max({scale, std::sqrt(dot3(eye_offset, eye_offset)),
                               flt_c.hit ? std::fabs(flt_c.t) * dir_length : 0.0L});

  Worst local;
  // Double.
  bool double_excused = false;
  if (dbl_c.hit) {
    ASSERT_TRUE(std::isfinite(hit.t) && std::isfinite(hit.y));
    ASSERT_NEAR(glm::length(hit.normal), 1.0, 1e-12);
    ASSERT_NEAR(glm::length(hit.radial), 1.0, 1e-12);
    const FaceDistances f = face_distances(shape, hit.kind, dbl_c.point, d);
    EXPECT_LE(double(f.to_surface / scale), kDoubleSurfaceTolerance) << "hit off the surface";
  }
  if (ref_c.hit != dbl_c.hit || (ref_c.hit && ref.kind != hit.kind)) {
    double_excused =
        in_band(shape, ref_c, dbl_c, d, scale, kDoubleEdgeBand, kDoubleGrazingCos);
    (double_excused ? local.double_flips_in_band : local.double_flips_out) +=
        ref_c.hit != dbl_c.hit;
    if (std::getenv("SYLVA_RAY_DEBUG") && !double_excused) {
      std::printf("DBG o %a %a %a d %a %a %a base %a %a %a axis %a %a %a L %a r0 %a r1 %a "
                  "ln %a %a %a lo %a un %a %a %a uo %a caps %d %d\n",
                  ray.origin.x, ray.origin.y, ray.origin.z, ray.direction.x, ray.direction.y,
                  ray.direction.z, shape.base.x, shape.base.y, shape.base.z, shape.axis.x,
                  shape.axis.y, shape.axis.z, shape.length, shape.radius0, shape.radius1,
                  shape.lower.normal.x, shape.lower.normal.y, shape.lower.normal.z,
                  shape.lower.offset, shape.upper.normal.x, shape.upper.normal.y,
                  shape.upper.normal.z, shape.upper.offset, int(shape.cap_lower),
                  int(shape.cap_upper));
    }
    EXPECT_TRUE(double_excused) << "double disagrees with the reference: ref kind "
                                << int(ref.kind) << " t " << double(ref.t) << ", double kind "
                                << int(hit.kind) << " t " << hit.t;
  }
  if (ref_c.hit && dbl_c.hit) {
    const double t_error = double(std::fabs(dbl_c.t - ref.t) * dir_length / scale);
    const bool excused =
        in_band(shape, ref_c, dbl_c, d, scale, kDoubleEdgeBand, kDoubleGrazingCos);
    if (!excused || t_error <= kDoubleTTolerance) {
      local.double_t = t_error;
      EXPECT_LE(t_error, kDoubleTTolerance) << "ref t " << double(ref.t) << " double t " << hit.t;
    }
    if (ref.kind == hit.kind && !excused) {
      const double normal_error = angle_between(hit.normal, ref.normal);
      local.double_normal = normal_error;
      EXPECT_LE(normal_error, kDoubleNormalTolerance);
    }
  }
  // Float twin.
  if (flt_c.hit) {
    ASSERT_TRUE(std::isfinite(hit_f.t) && std::isfinite(hit_f.normal.x) &&
                std::isfinite(hit_f.normal.y) && std::isfinite(hit_f.normal.z));
    const FaceDistances f = face_distances(shape, flt_c.kind, flt_c.point, d);
    EXPECT_LE(double(f.to_surface / scale_f), kFloatSurfaceTolerance) << "float hit off surface";
  }
  const LD float_depth = 16 * LD(std::numeric_limits<float>::epsilon()) * scale_f;
  if (ref_c.hit != flt_c.hit || (ref_c.hit && ref.kind != flt_c.kind)) {
    const bool excused = in_band(shape, ref_c, flt_c, d, scale_f, kFloatEdgeBand,
                                 kFloatGrazingCos, float_depth);
    (excused ? local.float_flips_in_band : local.float_flips_out) += ref_c.hit != flt_c.hit;
    EXPECT_TRUE(excused) << "float twin disagrees with the reference: ref kind "
                         << int(ref.kind) << " t " << double(ref.t) << ", float kind "
                         << hit_f.kind << " t " << hit_f.t;
  }
  if (ref_c.hit && flt_c.hit) {
    const double t_error = double(std::fabs(flt_c.t - ref.t) * dir_length / scale_f);
    const bool excused = in_band(shape, ref_c, flt_c, d, scale_f, kFloatEdgeBand,
                                 kFloatGrazingCos, float_depth);
    const FaceDistances f = face_distances(shape, ref.kind, ref.point, d);
    const bool well_conditioned = f.cos_incidence >= kFloatWellConditionedCos;
    if (!excused || t_error <= kFloatTTolerance) {
      local.float_t = t_error;
      if (well_conditioned) {
        local.float_t_well = t_error;
        EXPECT_LE(t_error, kFloatTTolerance) << "float t " << hit_f.t << " ref " << double(ref.t);
      }
    }
    if (!well_conditioned) local.float_ill_conditioned = 1;
    if (ref.kind == flt_c.kind && !excused)
      local.float_normal = angle_between(glm::dvec3(hit_f.normal), ref.normal);
  }
  std::vector<std::string> rows = c.labels;
  rows.push_back("all");
  for (const std::string& name : rows) {
    Worst& w = table().row(name);
    w.rays += 1;
    w.double_t = std::max(w.double_t, local.double_t);
    w.double_normal = std::max(w.double_normal, local.double_normal);
    w.float_t = std::max(w.float_t, local.float_t);
    w.float_t_well = std::max(w.float_t_well, local.float_t_well);
    w.float_normal = std::max(w.float_normal, local.float_normal);
    w.double_flips_in_band += local.double_flips_in_band;
    w.double_flips_out += local.double_flips_out;
    w.float_flips_in_band += local.float_flips_in_band;
    w.float_flips_out += local.float_flips_out;
    w.float_ill_conditioned += local.float_ill_conditioned;
  }
}

// ---- Building shapes -------------------------------------------------------------------

glm::dvec3 any_perpendicular(glm::dvec3 axis) {
  const glm::dvec3 helper = std::abs(axis.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 0, 1);
  return glm::normalize(helper - glm::dot(helper, axis) * axis);
}

// A plane through `point` tilted by tilt_rad from perpendicular, toward `toward` (⊥ axis).
Plane tilted_plane(glm::dvec3 point, glm::dvec3 axis, glm::dvec3 toward, double tilt_rad) {
  Plane p;
  p.normal = glm::normalize(std::cos(tilt_rad) * axis + std::sin(tilt_rad) * toward);
  p.offset = glm::dot(p.normal, point);
  return p;
}

FrustumShape make_shape(glm::dvec3 base, glm::dvec3 axis, double length, double r0, double r1,
                        double lower_tilt_rad, double upper_tilt_rad, bool caps) {
  FrustumShape s;
  s.base = base;
  s.axis = glm::normalize(axis);
  s.length = length;
  s.radius0 = r0;
  s.radius1 = r1;
  const glm::dvec3 u1 = any_perpendicular(s.axis);
  const glm::dvec3 u2 = glm::cross(s.axis, u1);
  s.lower = tilted_plane(base, s.axis, u1, lower_tilt_rad);
  s.upper = tilted_plane(base + length * s.axis, s.axis, glm::normalize(u1 + u2),
                         upper_tilt_rad);
  if (caps) {
    s.lower.normal = s.axis;
    s.lower.offset = glm::dot(s.axis, base);
    s.upper.normal = s.axis;
    s.upper.offset = glm::dot(s.axis, base + length * s.axis);
    s.cap_lower = r0 > 0;
    s.cap_upper = r1 > 0;
  }
  return s;
}

// ---- Specifications --------------------------------------------------------------------

FrustumShape unit_cylinder() {
  return make_shape({0, 0, 0}, {0, 1, 0}, 2, 1, 1, 0, 0, false);
}

TEST(RayFrustum, HeadOnRayHitsCylinderSideAtRadius) {
  const FrustumHit hit = intersect_frustum({{5, 1, 0}, {-1, 0, 0}}, unit_cylinder(), 0, 1e30);
  ASSERT_EQ(hit.kind, FrustumHitKind::side);
  EXPECT_DOUBLE_EQ(hit.t, 4);
  EXPECT_DOUBLE_EQ(hit.y, 1);
  EXPECT_NEAR(glm::length(hit.normal - glm::dvec3(1, 0, 0)), 0, 1e-15);
  EXPECT_NEAR(glm::length(hit.radial - glm::dvec3(1, 0, 0)), 0, 1e-15);
  EXPECT_FALSE(hit.from_inside);
}

TEST(RayFrustum, ConeNormalLeansAgainstTheSlope) {
  // r(y) = 1 − y/2: normal ∝ ê − slope·axis = (1, 0.5, 0).
  const FrustumShape cone = make_shape({0, 0, 0}, {0, 1, 0}, 2, 1, 0, 0, 0, false);
  const FrustumHit hit = intersect_frustum({{5, 1, 0}, {-1, 0, 0}}, cone, 0, 1e30);
  ASSERT_EQ(hit.kind, FrustumHitKind::side);
  EXPECT_NEAR(hit.t, 4.5, 1e-15);
  EXPECT_NEAR(glm::length(hit.normal - glm::normalize(glm::dvec3(1, 0.5, 0))), 0, 1e-15);
}

TEST(RayFrustum, OriginInsideGivesTheExitHitFromInside) {
  const FrustumHit hit = intersect_frustum({{0, 1, 0}, {0, 0, 2}}, unit_cylinder(), 0, 1e30);
  ASSERT_EQ(hit.kind, FrustumHitKind::side);
  EXPECT_DOUBLE_EQ(hit.t, 0.5);
  EXPECT_TRUE(hit.from_inside);
}

TEST(RayFrustum, RayAlongTheAxisHitsTheCapOrPassesThroughAnOpenEnd) {
  FrustumShape capped = make_shape({0, 0, 0}, {0, 1, 0}, 2, 1, 1, 0, 0, true);
  const FrustumHit cap = intersect_frustum({{0, -3, 0}, {0, 1, 0}}, capped, 0, 1e30);
  ASSERT_EQ(cap.kind, FrustumHitKind::lower_cap);
  EXPECT_DOUBLE_EQ(cap.t, 3);
  EXPECT_EQ(cap.normal, glm::dvec3(0, -1, 0));
  const FrustumHit down = intersect_frustum({{0, 5, 0}, {0, -1, 0}}, capped, 0, 1e30);
  ASSERT_EQ(down.kind, FrustumHitKind::upper_cap);
  EXPECT_DOUBLE_EQ(down.t, 3);
  // Open ends: a cylinder seen down its axis has no hit at all.
  EXPECT_FALSE(intersect_frustum({{0, -3, 0}, {0, 1, 0}}, unit_cylinder(), 0, 1e30).hit());
}

TEST(RayFrustum, RayParallelToAGeneratorCrossesOnce) {
  // Generator of r(y) = 1 − y/2 at ê = +x runs along (−0.5, 1, 0): A = 0 exactly.
  const FrustumShape cone = make_shape({0, 0, 0}, {0, 1, 0}, 2, 1, 0, 0, 0, false);
  const FrustumHit hit = intersect_frustum({{-0.5, 0, 0}, {-0.5, 1, 0}}, cone, 0, 1e30);
  ASSERT_EQ(hit.kind, FrustumHitKind::side);
  // Crosses x = −(1 − y/2) where −0.5 − t/2 = −1 + t/2: t = 0.5.
  EXPECT_DOUBLE_EQ(hit.t, 0.5);
}

TEST(RayFrustum, WrongNappeBeyondTheApexIsRejected) {
  // A tip (r1 = 0) cut by an upper plane tilted 60° through the apex: the mirrored cone
  // above the apex lies partly below that plane, and must not be hit.
  const FrustumShape tip = make_shape({0, 0, 0}, {0, 1, 0}, 1, 1, 0, 0, 60 * kPi / 180, false);
  const FrustumHit hit = intersect_frustum({{-3, 1.5, 0.0}, {1, 0, 0}}, tip, 0, 1e30);
  EXPECT_FALSE(hit.hit());
}

TEST(RayFrustum, ApexHitHasAFiniteNormal) {
  const FrustumShape tip = make_shape({0, 0, 0}, {0, 1, 0}, 1, 1, 0, 0, 0.3, false);
  const FrustumHit hit = intersect_frustum({{0, 3, 0}, {0, -1, 0}}, tip, 0, 1e30);
  if (hit.hit()) {
    EXPECT_TRUE(std::isfinite(hit.normal.x) && std::isfinite(hit.normal.y));
    EXPECT_NEAR(glm::length(hit.normal), 1, 1e-12);
  }
}

TEST(RayFrustum, RangeIsOpenAtBothEnds) {
  EXPECT_FALSE(intersect_frustum({{5, 1, 0}, {-1, 0, 0}}, unit_cylinder(), 4, 1e30).hit() &&
               intersect_frustum({{5, 1, 0}, {-1, 0, 0}}, unit_cylinder(), 4, 1e30).t == 4);
  const FrustumHit far = intersect_frustum({{5, 1, 0}, {-1, 0, 0}}, unit_cylinder(), 4, 1e30);
  ASSERT_TRUE(far.hit());
  EXPECT_DOUBLE_EQ(far.t, 6);  // the back face
  EXPECT_FALSE(intersect_frustum({{5, 1, 0}, {-1, 0, 0}}, unit_cylinder(), 0, 3.9).hit());
}

TEST(RayFrustum, OffsetByAMillionMetresLosesNothing) {
  // Dyadic coordinates and axis-aligned planes, so the translated inputs are exactly the
  // same shape and ray: the answers must agree to the last bits of t.
  const glm::dvec3 offset{1048576, -524288, 262144};
  auto shape_at = [](glm::dvec3 base) {
    FrustumShape s;
    s.base = base;
    s.length = 1.0 / 1024;
    s.radius0 = 1.0 / 4096;
    s.radius1 = 1.0 / 8192;
    s.lower = {{0, 1, 0}, base.y};
    s.upper = {{0, 1, 0}, base.y + s.length};
    return s;
  };
  const Ray near_ray{{1.0 / 512, 1.0 / 2048, -1.0 / 8192}, {-1, 0.125, 0.0625}};
  const FrustumHit a = intersect_frustum(near_ray, shape_at({0, 0, 0}), 0, 1e30);
  const FrustumHit b =
      intersect_frustum({near_ray.origin + offset, near_ray.direction}, shape_at(offset), 0, 1e30);
  ASSERT_TRUE(a.hit() && b.hit());
  EXPECT_NEAR(a.t, b.t, 1e-14 * a.t);
  EXPECT_NEAR(glm::length(a.normal - b.normal), 0, 1e-12);
  // And from an eye a million metres away, along the same line.
  const double back = 1048576;
  const FrustumHit c = intersect_frustum(
      {near_ray.origin - back * near_ray.direction, near_ray.direction}, shape_at({0, 0, 0}),
      0, 1e30);
  ASSERT_TRUE(c.hit());
  EXPECT_NEAR(c.t - back, a.t, 1e-9);
  EXPECT_NEAR(glm::length(a.normal - c.normal), 0, 1e-9);
}

TEST(RayFrustum, ZeroOrNegativeLengthIsRejectedWithoutNaN) {
  for (double length : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    FrustumShape s = unit_cylinder();
    s.length = length;
    EXPECT_NE(frustum_shape_error(s), nullptr) << length;
    const FrustumHit hit = intersect_frustum({{5, 1, 0}, {-1, 0, 0}}, s, 0, 1e30);
    EXPECT_FALSE(hit.hit()) << length;
    EXPECT_EQ(hit.t, 0);
    const FrustumHitF hit_f = intersect_frustum_f(to_float_ray({{5, 1, 0}, {-1, 0, 0}}, s.base),
                                                  to_float_shape(s, s.base), 0, 1e30f);
    EXPECT_EQ(hit_f.kind, 0u) << length;
  }
  FrustumShape negative_radius = unit_cylinder();
  negative_radius.radius1 = -0.1;
  EXPECT_NE(frustum_shape_error(negative_radius), nullptr);
  EXPECT_FALSE(intersect_frustum({{5, 1, 0}, {-1, 0, 0}}, negative_radius, 0, 1e30).hit());
  EXPECT_EQ(frustum_shape_error(unit_cylinder()), nullptr);
}

TEST(RayFrustum, FloatTwinAgreesOnASimpleHit) {
  const FrustumShape s = unit_cylinder();
  const FrustumHitF hit = intersect_frustum_f(to_float_ray({{5, 1, 0}, {-1, 0, 0}}, s.base),
                                              to_float_shape(s, s.base), 0, 1e30f);
  ASSERT_EQ(hit.kind, uint32_t(FrustumHitKind::side));
  EXPECT_FLOAT_EQ(hit.t, 4);
  EXPECT_FLOAT_EQ(hit.normal.x, 1);
}

// ---- The stiff-case suite --------------------------------------------------------------

std::string label(const char* name, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%s = %g", name, value);
  return buffer;
}

// The rays of one table configuration.
void stiff_rays(const FrustumShape& s, double offset, const std::vector<std::string>& labels,
                std::vector<RayCase>& out) {
  const double k = s.slope();
  const double extent = s.length + std::max(s.radius0, s.radius1);
  const glm::dvec3 u1 = any_perpendicular(s.axis);
  const glm::dvec3 u2 = glm::cross(s.axis, u1);
  const double eye = 3 * extent + offset;  // distance of an outside origin
  auto add = [&](glm::dvec3 o, glm::dvec3 d, std::vector<std::string> more) {
    RayCase c{s, {o, d}, labels};
    c.labels.insert(c.labels.end(), more.begin(), more.end());
    out.push_back(std::move(c));
  };
  for (double phi : {0.4, 2.5, 4.6}) {
    const glm::dvec3 e = std::cos(phi) * u1 + std::sin(phi) * u2;
    const double y_star = 0.45 * s.length;
    const double r_star = s.radius_at(y_star);
    const glm::dvec3 p = s.base + y_star * s.axis + r_star * e;  // on the side
    const glm::dvec3 n = glm::normalize(e - k * s.axis);         // outward normal at p
    const glm::dvec3 g = glm::normalize(s.axis + k * e);          // generator, upward
    const glm::dvec3 q = p - 0.25 * r_star * n;                   // just inside
    for (double theta : {0.0, 1e-6, 1e-3}) {
      const std::string angle = label("angle to generator (rad)", theta);
      const glm::dvec3 d = std::cos(theta) * g - std::sin(theta) * n;  // dives inward
      // Parallel-ish through an interior point: A ≈ 0, the linear case.
      add(q - eye * d, d, {angle, "origin outside"});
      add(q, d, {angle, "origin inside"});
      add(q + eye * d, -d, {angle, "origin outside", "antiparallel ray"});
      add(q, -d, {angle, "origin inside", "antiparallel ray"});
      if (theta > 0) {
        // Crossing the side at p at angle theta: ill-conditioned by 1/theta.
        add(p - eye * d, d, {angle, "origin outside", "crossing at angle"});
        add(p + 0.3 * s.length * d, -d, {angle, "origin inside", "crossing at angle"});
      }
    }
    // Head-on and from the axis.
    add(p + eye * n, -n, {"head-on", "origin outside"});
    add(s.base + y_star * s.axis, e, {"head-on", "origin inside"});
    // Grazing band: exactly tangent, and lying on a generator.
    const glm::dvec3 tangent = glm::cross(s.axis, e);
    add(p - eye * tangent, tangent, {"tangent (band)", "origin outside"});
    add(p - eye * g, g, {"on a generator (band)", "origin outside"});
  }
  // Along the axis, both ways, on it and off it.
  for (double off : {0.0, 0.5}) {
    const glm::dvec3 side = off * s.radius0 * u1;
    const std::string l = off == 0 ? "along the axis" : "parallel to the axis";
    add(s.base + side - eye * s.axis, s.axis, {l, "origin outside"});
    add(s.base + side + (s.length + eye) * s.axis, -s.axis,
        {l, "origin outside", "antiparallel ray"});
    add(s.base + side + 0.5 * s.length * s.axis, s.axis, {l, "origin inside"});
    add(s.base + side + 0.5 * s.length * s.axis, -s.axis,
        {l, "origin inside", "antiparallel ray"});
  }
}

std::vector<RayCase> stiff_table() {
  std::vector<RayCase> cases;
  const double ratios[] = {1, 1 + 1e-7, 1 - 1e-7, 1 + 1e-3, 1 - 1e-3, 0.5, 0};
  const double radii[] = {1e-4, 1e-2, 1, 1e2};
  const double offsets[] = {0, 1e4, 1e6};
  const double joints_deg[] = {0, 1e-6, 45, 90, 135, 179};
  const glm::dvec3 axes[] = {glm::normalize(glm::dvec3(0.3, 1, -0.2)), {0, -1, 0}};
  for (double ratio : ratios)
    for (double radius : radii)
      for (double offset : offsets)
        for (double joint : joints_deg)
          for (int a = 0; a < 2; ++a) {
            const double tilt = 0.5 * joint * kPi / 180;
            const glm::dvec3 base = offset * glm::normalize(glm::dvec3(0.57, 0.41, -0.71));
            const FrustumShape s = make_shape(base, axes[a], 6 * radius, radius, ratio * radius,
                                              tilt, tilt, joint == 0);
            EXPECT_EQ(frustum_shape_error(s), nullptr);
            std::vector<std::string> labels = {
                label("r1/r0", ratio), label("radius0 (m)", radius), label("offset (m)", offset),
                label("joint (deg)", joint), a == 0 ? "axis tilted" : "axis antiparallel to Y"};
            stiff_rays(s, offset, labels, cases);
          }
  return cases;
}

TEST(StiffCases, TableAgreesWithLongDoubleReference) {
  const std::vector<RayCase> cases = stiff_table();
  for (const RayCase& c : cases) check_ray(c);
  std::printf("stiff table: %zu rays\n", cases.size());
}

// Thousands of random frusta and rays, fixed seed: 3000 shapes, 8 rays each.
std::vector<RayCase> random_cases() {
  std::mt19937_64 rng(20240607);
  std::uniform_real_distribution<double> unit(0, 1);
  auto log_uniform = [&](double lo, double hi) {
    return std::exp(std::log(lo) + unit(rng) * (std::log(hi) - std::log(lo)));
  };
  auto random_unit = [&]() {
    std::normal_distribution<double> normal;
    return glm::normalize(glm::dvec3(normal(rng), normal(rng), normal(rng)));
  };
  std::vector<RayCase> cases;
  for (int shape_index = 0; shape_index < 3000; ++shape_index) {
    const double radius = log_uniform(1e-4, 1e2);
    const double r1 = unit(rng) < 0.2 ? 0 : radius * log_uniform(0.2, 5);
    const double length = radius * log_uniform(0.1, 1000);
    const double offset = unit(rng) < 0.3 ? 0 : log_uniform(1, 1e6);
    const bool caps = unit(rng) < 0.3;
    const double tilt_lower = caps ? 0 : unit(rng) * 1.4;  // up to 80°
    const double tilt_upper = caps ? 0 : unit(rng) * 1.4;
    const FrustumShape s = make_shape(offset * random_unit(), random_unit(), length, radius, r1,
                                      tilt_lower, tilt_upper, caps);
    const double extent = length + std::max(radius, r1);
    const glm::dvec3 middle = s.base + 0.5 * length * s.axis;
    for (int i = 0; i < 8; ++i) {
      // Toward a random point of the bounding cylinder, from near or far.
      const glm::dvec3 target = s.base + unit(rng) * length * s.axis +
                                std::max(radius, r1) * 1.2 * unit(rng) * random_unit();
      const double distance = unit(rng) < 0.5 ? extent * log_uniform(0.01, 3)
                                                : extent * log_uniform(3, 1e6);
      const glm::dvec3 origin = middle + distance * random_unit();
      const glm::dvec3 direction = (target - origin) * log_uniform(1e-3, 1e3);
      cases.push_back({s, {origin, direction}, {"random"}});
    }
  }
  return cases;
}

TEST(StiffCases, RandomFrustaAgreeWithLongDoubleReference) {
  const std::vector<RayCase> cases = random_cases();
  for (const RayCase& c : cases) check_ray(c);
  std::printf("random: %zu rays\n", cases.size());
}

// ---- The reach test accelerators run first (ray_beyond_reach) --------------------------

// Every ray of the stiff table and the random frusta that intersect_frustum hits anywhere
// on its line is kept by the reach test. (Those rays aim at the solid or just around it,
// and most tilted random shapes have no proper pyramid, so few are rejected: the next
// test measures the rejection itself.)
TEST(RayBeyondReach, NeverRejectsARayThatHitsOnTheStiffAndRandomCases) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (const bool random : {false, true}) {
    const std::vector<RayCase> cases = random ? random_cases() : stiff_table();
    size_t hits = 0, rejected = 0;
    for (const RayCase& c : cases) {
      const double reach = frustum_radial_reach(c.shape);
      const bool beyond = ray_beyond_reach(c.ray, c.shape, reach);
      rejected += beyond;
      const FrustumHit hit = intersect_frustum(c.ray, c.shape, -kInf, kInf);
      if (!hit.hit()) continue;
      ++hits;
      ASSERT_FALSE(beyond) << (random ? "random" : "stiff") << " case " << (&c - cases.data())
                           << ": a hit at t = " << hit.t << " rejected (reach " << reach << " m)";
    }
    std::printf("%s: %zu rays, %zu hit, %zu beyond reach\n", random ? "random" : "stiff", cases.size(), hits,
                rejected);
    EXPECT_GT(hits, cases.size() / 4);
    if (random) {
      EXPECT_GT(rejected, 0u);
    }
  }
}

// Rays that pass the axis at the reach's distance give or take a relative 1e-12 … 1e-2,
// crossing the random frusta at every height of their pyramids: those a little farther
// out are rejected (where the shape has a proper pyramid), and no rejected ray hits.
TEST(RayBeyondReach, RaysGrazingTheReachOfRandomFrustaAreRejectedOnlyWhenTheyMiss) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::mt19937_64 rng(20261204);
  std::uniform_real_distribution<double> unit(0, 1);
  auto log_uniform = [&](double lo, double hi) {
    return std::exp(std::log(lo) + unit(rng) * (std::log(hi) - std::log(lo)));
  };
  const std::vector<RayCase> cases = random_cases();
  size_t proper = 0, outside = 0, outside_rejected = 0, hits = 0;
  for (size_t i = 0; i < cases.size(); i += 8) {
    const FrustumShape& s = cases[i].shape;
    const double reach = frustum_radial_reach(s);
    if (!std::isfinite(reach)) continue;
    ++proper;
    const BoundingPyramid pyramid = bounding_pyramid(s);
    double y_lo = kInf, y_hi = -kInf;
    for (const glm::dvec3& v : pyramid.vertices) {
      y_lo = std::min(y_lo, glm::dot(v - s.base, s.axis));
      y_hi = std::max(y_hi, glm::dot(v - s.base, s.axis));
    }
    const glm::dvec3 u1 = any_perpendicular(s.axis), u2 = glm::cross(s.axis, u1);
    for (int k = 0; k < 16; ++k) {
      const double phi = 2 * kPi * unit(rng);
      const glm::dvec3 e = std::cos(phi) * u1 + std::sin(phi) * u2;   // radial
      const glm::dvec3 across = glm::cross(s.axis, e);                 // ⊥ axis and e
      const double delta = (k % 2 ? 1 : -1) * log_uniform(1e-12, 1e-2);
      const double y = y_lo + unit(rng) * (y_hi - y_lo);
      const double lean = (2 * unit(rng) - 1) * 1.5;                   // toward the axis, rad
      const glm::dvec3 point = s.base + y * s.axis + reach * (1 + delta) * e;
      const glm::dvec3 direction = (std::cos(lean) * across + std::sin(lean) * s.axis) * log_uniform(1e-3, 1e3);
      const Ray ray{point - 3 * (y_hi - y_lo + reach) * glm::normalize(direction), direction};
      const bool beyond = ray_beyond_reach(ray, s, reach);
      const bool hit = intersect_frustum(ray, s, -kInf, kInf).hit();
      hits += hit;
      ASSERT_FALSE(beyond && hit) << "shape " << i << ", delta " << delta << ", y " << y << ", lean " << lean;
      if (delta > 1e-8) {
        ++outside;
        outside_rejected += beyond;
      }
    }
  }
  std::printf("%zu proper shapes, %zu grazing hits, %zu of %zu rays beyond 1e-8 rejected\n", proper, hits,
              outside_rejected, outside);
  EXPECT_GT(proper, 500u);
  EXPECT_GT(hits, 0u);
  EXPECT_GE(outside_rejected, outside * 99 / 100);
}

// The reach is the largest radius of the solid: a cylinder's is its radius; a cone cut by
// tilted planes reaches r(y) at the plane's extreme point. Rays passing a millionth beyond
// it, at every offset, are rejected; rays a millionth inside are kept and hit.
TEST(RayBeyondReach, RejectsRaysJustBeyondTheSolidsLargestRadius) {
  const FrustumShape cylinder = unit_cylinder();  // radius 1 about +Y, y in [0, 2]
  EXPECT_NEAR(frustum_radial_reach(cylinder), 1, 1e-8);
  for (const double scale : {1 - 1e-6, 1 + 1e-6}) {
    const Ray ray{{scale, 1, -5}, {0, 0, 1}};
    EXPECT_EQ(ray_beyond_reach(ray, cylinder, frustum_radial_reach(cylinder)), scale > 1);
    EXPECT_EQ(intersect_frustum(ray, cylinder, 0, 100).hit(), scale < 1);
  }
  for (const double offset : {0.0, 1e3, 1e6}) {
    for (const double tilt_deg : {0.0, 20.0, 40.0}) {
      const glm::dvec3 base = offset * glm::normalize(glm::dvec3(0.57, 0.41, -0.71));
      const double tilt = tilt_deg * kPi / 180;
      const FrustumShape cone = make_shape(base, {0.2, 1, 0.1}, 2, 0.3, 0.1, tilt, tilt, false);
      const double reach = frustum_radial_reach(cone);
      // The widest point: on the lower plane, down its tilt (make_shape tilts it toward u1).
      const glm::dvec3 u1 = any_perpendicular(cone.axis);
      const double y_low = -cone.radius0 * std::tan(tilt) / (1 + cone.slope() * std::tan(tilt));
      EXPECT_NEAR(reach, cone.radius_at(y_low), 1e-8 * reach) << "tilt " << tilt_deg;
      const glm::dvec3 across = glm::cross(cone.axis, u1);  // ⊥ axis and u1
      for (const double scale : {1 - 1e-6, 1 + 1e-6}) {
        const glm::dvec3 point = cone.base + y_low * cone.axis + scale * reach * u1;
        const Ray ray{point - 5.0 * across, across};
        const bool beyond = ray_beyond_reach(ray, cone, reach);
        EXPECT_EQ(beyond, scale > 1) << "offset " << offset << ", tilt " << tilt_deg << ", scale " << scale;
      }
      EXPECT_FALSE(ray_beyond_reach({cone.base + 3.0 * u1, cone.axis}, cone, reach)) << "parallel to the axis";
      EXPECT_FALSE(ray_beyond_reach({cone.base + 3.0 * u1, across}, cone, std::numeric_limits<double>::infinity()));
    }
  }
}

// Writes the table once every test has run (SYLVA_ACCURACY_TABLE).
class AccuracyTableWriter : public ::testing::Environment {
 public:
  void TearDown() override { write_table_if_asked(); }
};
const ::testing::Environment* const kTableWriter =
    ::testing::AddGlobalTestEnvironment(new AccuracyTableWriter);

}  // namespace
}  // namespace sylva
