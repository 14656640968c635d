// Tests for core/light/shadow_cones.h: shadow cones of Hougs and Day 2001 (sec. 3.2, 3.3.1, 6.2).
//
// ConeInterval.*: the stiff matrix — ray–cone intervals against a reference computed here
// in long double by a different route (an explicit orthonormal frame, the ray re-centred
// on the cone's midpoint in long double, textbook roots of the quadratic polished by
// Newton on the implicit function evaluated point by point), for Θ = 0, ±1e-9, ±the sun's radius and a
// wide cone, rays along the axis, parallel to it, from inside, head-on, oblique, grazing,
// from far away, with cones 1e-6 m to 1e4 m long and 10⁶ m from the world origin.
// Error measure: |Δt|·|d| over the scale S = max(cone radius at the crossing, distance
// from the ray origin to the cone's base); well-conditioned ends within kTolerance·S,
// grazing rays (conditioned as 1/sqrt(miss distance)) within kGrazingTolerance·S.
// ConeSet.*: merging, the hierarchy against brute force, containment.
// Clustering.*: synthetic shadow vectors of known occluders under a parallel sun and
// under the sun's disc.
#include "core/light/shadow_cones.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <glm/geometric.hpp>
#include <random>
#include <string>
#include <vector>

#include "core/geometry/skin.h"

namespace sylva {
namespace {

using LD = long double;

constexpr double kTolerance = 1e-13;         // × S, well-conditioned ends
constexpr double kGrazingTolerance = 1e-8;   // × S, tangent rays and chords 1e-6 of the radius deep
constexpr double kSunRadiusRad = 0.2679 * 3.14159265358979323846 / 180;  // 4.676 mrad
constexpr double kFar = 1e30;

// ---- Long double reference -------------------------------------------------------------

struct V3 {
  LD x = 0, y = 0, z = 0;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(LD s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
LD dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross3(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
V3 unit3(V3 a) { return (1.0L / std::sqrt(dot3(a, a))) * a; }
V3 ld(const glm::dvec3& v) { return {LD(v.x), LD(v.y), LD(v.z)}; }

struct RefInterval {
  bool hit = false;
  LD enter = 0, exit = 0;
};

// The cone's solid along the ray, in long double: 0 <= s <= end, r(s) >= 0, ρ <= r(s).
RefInterval reference_interval(const ShadowCone& cone, const Ray& ray, LD t_min, LD t_max) {
  const V3 Y = unit3(ld(cone.axis));
  const V3 helper = std::fabs(Y.x) < 0.6L ? V3{1, 0, 0} : V3{0, 0, 1};
  const V3 X = unit3(helper - dot3(helper, Y) * Y);
  const V3 Z = cross3(X, Y);
  const LD r0 = cone.radius_base_m, k = cone.tan_theta;
  LD end = cone.length_m;
  if (k < 0 && r0 < end * -k) end = r0 / -k;
  // Origin relative to the base (exact: a difference of doubles fits a long double's
  // mantissa at these magnitudes), re-centred on the point nearest the midpoint.
  const V3 d = ld(ray.direction);
  const V3 q = ld(ray.origin) - ld(cone.base);
  const V3 mid = (end / 2) * Y;
  const LD shift = dot3(mid - q, d) / dot3(d, d);
  const V3 o = q + shift * d;
  const V3 lo{dot3(o, X), dot3(o, Y), dot3(o, Z)}, ldir{dot3(d, X), dot3(d, Y), dot3(d, Z)};
  LD a = -INFINITY, b = INFINITY;  // local t bounds
  auto at_least = [&](LD coef, LD c) {  // coef·t >= c
    if (coef > 0) a = std::max(a, c / coef);
    else if (coef < 0) b = std::min(b, c / coef);
    else if (c > 0) b = -INFINITY;
  };
  at_least(ldir.y, -lo.y);             // s >= 0
  at_least(-ldir.y, lo.y - end);       // s <= end
  at_least(k * ldir.y, -(r0 + k * lo.y));  // r(s) >= 0
  const LD rho = r0 + k * lo.y;
  const LD A = ldir.x * ldir.x + ldir.z * ldir.z - k * k * ldir.y * ldir.y;
  const LD B = lo.x * ldir.x + lo.z * ldir.z - rho * k * ldir.y;
  const LD C = lo.x * lo.x + lo.z * lo.z - rho * rho;
  auto g = [&](LD t) {  // the implicit function at the point
    const LD x = lo.x + t * ldir.x, y = lo.y + t * ldir.y, z = lo.z + t * ldir.z;
    const LD r = r0 + k * y;
    return x * x + z * z - r * r;
  };
  auto polish = [&](LD t) {  // Newton steps kept only while they reduce |g| (a double
    for (int i = 0; i < 4; ++i) {  // root's flat slope would amplify g's rounding)
      const LD slope = 2 * (A * t + B);
      if (slope == 0) break;
      const LD next = t - g(t) / slope;
      if (!std::isfinite(next) || !(std::fabs(g(next)) < std::fabs(g(t)))) break;
      t = next;
    }
    return t;
  };
  // B² − A·C regrouped (the ρ²k²d_y² terms cancel algebraically): a ray through or near
  // the apex keeps its tiny discriminant, which B² − A·C loses even in long double.
  const LD radial_x = rho * ldir.x - k * ldir.y * lo.x, radial_z = rho * ldir.z - k * ldir.y * lo.z;
  const LD moment = lo.x * ldir.z - lo.z * ldir.x;
  const LD disc = radial_x * radial_x + radial_z * radial_z - moment * moment;
  if (A == 0) {
    at_least(-2 * B, C);
  } else if (disc < 0) {
    if (A > 0) return {};
  } else {
    LD t0 = (-B - std::sqrt(disc)) / A, t1 = (-B + std::sqrt(disc)) / A;
    if (t0 > t1) std::swap(t0, t1);
    t0 = polish(t0), t1 = polish(t1);
    if (A > 0) {
      a = std::max(a, t0);
      b = std::min(b, t1);
    } else {
      // Outside the roots; the nappe bound keeps one half-line.
      const LD a1 = a, b1 = std::min(b, t0), a2 = std::max(a, t1), b2 = b;
      if (a1 <= b1 && !(a2 <= b2)) b = b1;
      else if (a2 <= b2 && !(a1 <= b1)) a = a2;
      else if (a1 <= b1 && a2 <= b2) {
        if (b1 - a1 >= b2 - a2) b = b1;
        else a = a2;
      } else {
        return {};
      }
    }
  }
  RefInterval out;
  a = std::max(a + shift, t_min);
  b = std::min(b + shift, t_max);
  if (!(a <= b)) return {};
  out.hit = true;
  out.enter = a, out.exit = b;
  return out;
}

// ---- The stiff matrix ------------------------------------------------------------------

struct StiffRay {
  Ray ray;
  bool grazing = false;  // conditioned as 1/sqrt: kGrazingTolerance
  std::string what;
  LD scale = 1;          // S
};

ShadowCone make_cone(const glm::dvec3& base, const glm::dvec3& axis, double r0, double tan_theta, double length) {
  ShadowCone c;
  c.base = base;
  c.axis = glm::normalize(axis);
  c.radius_base_m = r0;
  c.tan_theta = tan_theta;
  c.length_m = length;
  return c;
}

std::vector<StiffRay> stiff_rays(const ShadowCone& c) {
  std::vector<StiffRay> rays;
  const AxisFrame f = axis_frame(c.axis);
  const double end = c.end_s();
  const double r_max = std::max(c.radius_base_m, c.radius_at(end));
  const double size = end + r_max;
  const double away = 3 * size;
  auto add = [&](glm::dvec3 o, glm::dvec3 d, std::string what, bool grazing, double r_scale) {
    StiffRay s;
    s.ray = {o, d};
    s.what = std::move(what);
    s.grazing = grazing;
    s.scale = std::max<LD>(r_scale, std::sqrt(dot3(ld(o) - ld(c.base), ld(o) - ld(c.base))));
    s.scale = std::max<LD>(s.scale, r_max);
    rays.push_back(std::move(s));
  };
  const double s_mid = 0.5 * end, r_mid = c.radius_at(s_mid);
  const glm::dvec3 p_mid = c.base + s_mid * c.axis;
  // Along the axis, both ways, and from inside.
  add(c.base - away * c.axis, c.axis, "along the axis", false, r_max);
  add(c.base + (end + away) * c.axis, -c.axis, "along the axis, antiparallel", false, r_max);
  add(p_mid, c.axis, "along the axis from inside", false, r_max);
  add(p_mid, -c.axis, "along the axis from inside, antiparallel", false, r_max);
  // Parallel to the axis, at half the smaller end radius.
  const double r_min = std::min(c.radius_base_m, c.radius_at(end));
  if (r_min > 0) add(c.base + 0.5 * r_min * f.e0 - away * c.axis, c.axis, "parallel to the axis", false, r_max);
  // Parallel to a generator line, a quarter radius inside the side.
  if (c.radius_base_m > 0) {
    const glm::dvec3 g = glm::normalize(c.axis + c.tan_theta * f.e1);
    add(c.base + 0.75 * c.radius_base_m * f.e1 - away * g, g, "parallel to a generator", false, r_max);
  }
  // Head-on through the axis at mid-length, and obliquely; from near and from 1e4 m.
  for (double distance : {away, 1e4}) {
    const std::string from = distance == away ? "" : " from 1e4 m";
    if (r_mid > 0) {
      add(p_mid + distance * f.e0, -f.e0, "head-on" + from, false, r_mid);
      const glm::dvec3 d = glm::normalize(-f.e0 + 0.7 * c.axis + 0.2 * f.e1);
      add(p_mid - distance * d, d, "oblique" + from, false, r_mid);
      // Grazing: a chord 1e-6 of the radius inside the side (width 2r·sqrt(2e-6)), and
      // exactly tangent.
      add(p_mid + (1 - 1e-6) * r_mid * f.e1 + distance * f.e0, -f.e0, "grazing chord" + from, true, r_mid);
      add(p_mid + r_mid * f.e1 + distance * f.e0, -f.e0, "tangent" + from, true, r_mid);
    }
  }
  // Through the base disc's rim region, crossing the base plane obliquely.
  if (c.radius_base_m > 0) {
    const glm::dvec3 d = glm::normalize(c.axis + 0.5 * f.e0);
    add(c.base + 0.5 * c.radius_base_m * f.e1 - away * d, d, "through the base plane", false, c.radius_base_m);
  }
  return rays;
}

struct ErrorStats {
  double worst = 0, worst_grazing = 0;
  int rays = 0, hits = 0;
};

void check_stiff(const ShadowCone& cone, const std::string& label, ErrorStats& stats) {
  const ConeSet set({cone});
  std::vector<ConeInterval> through_set;
  for (const StiffRay& s : stiff_rays(cone)) {
    ++stats.rays;
    const RefInterval ref = reference_interval(cone, s.ray, 0, kFar);
    const SolidInterval got = shadow_cone_interval(s.ray, cone, 0, kFar);
    const LD length = std::sqrt(dot3(ld(s.ray.direction), ld(s.ray.direction)));
    const double tol = (s.grazing ? kGrazingTolerance : kTolerance) * double(s.scale);
    // Hit or miss: a reference interval wider than the tolerance must be found, and a
    // found one must be within the tolerance of the reference.
    const LD ref_width = ref.hit ? (ref.exit - ref.enter) * length : -1;
    if (!got.hit) {
      EXPECT_FALSE(ref_width > tol) << label << ", " << s.what << ": missed an interval of width "
                                    << double(ref_width);
      continue;
    }
    ++stats.hits;
    if (!ref.hit) {
      EXPECT_LE((got.t_exit - got.t_enter) * double(length), tol) << label << ", " << s.what << ": spurious";
      continue;
    }
    const double e_enter = double(std::fabs(LD(got.t_enter) - ref.enter) * length / s.scale);
    const double e_exit = double(std::fabs(LD(got.t_exit) - ref.exit) * length / s.scale);
    const double e = std::max(e_enter, e_exit);
    (s.grazing ? stats.worst_grazing : stats.worst) = std::max(s.grazing ? stats.worst_grazing : stats.worst, e);
    EXPECT_LE(e, s.grazing ? kGrazingTolerance : kTolerance)
        << label << ", " << s.what << ": got [" << got.t_enter << ", " << got.t_exit << "], reference ["
        << double(ref.enter) << ", " << double(ref.exit) << "]";
    // The hierarchy gives the same interval (the box is conservative at every scale).
    set.intervals(s.ray, 0, kFar, &through_set);
    if (got.t_exit > got.t_enter) {
      ASSERT_EQ(through_set.size(), 1u) << label << ", " << s.what;
      EXPECT_EQ(through_set[0].t_enter, got.t_enter);
      EXPECT_EQ(through_set[0].t_exit, got.t_exit);
    }
  }
}

TEST(ConeInterval, StiffMatrixAgreesWithLongDoubleReference) {
  const double thetas[] = {0, 1e-9, -1e-9, kSunRadiusRad, -kSunRadiusRad, 0.3};
  const double radii[] = {1e-3, 1};
  const double lengths[] = {1e-6, 1, 1e4};
  const double offsets[] = {0, 1e6};
  const glm::dvec3 axes[] = {glm::normalize(glm::dvec3(0.3, -1, 0.2)), {0, -1, 0}};
  ErrorStats stats;
  for (double theta : thetas)
    for (double r : radii)
      for (double length : lengths)
        for (double offset : offsets)
          for (const glm::dvec3& axis : axes) {
            const glm::dvec3 base = offset * glm::normalize(glm::dvec3(0.57, 0.41, -0.71)) + glm::dvec3(0.1, 7, 0.3);
            const ShadowCone cone = make_cone(base, axis, r, std::tan(theta), length);
            char label[160];
            std::snprintf(label, sizeof label, "theta %g, r %g, length %g, offset %g, axis (%g, %g, %g)", theta, r,
                          length, offset, axis.x, axis.y, axis.z);
            check_stiff(cone, label, stats);
          }
  std::printf("stiff matrix: %d rays, %d hits, worst error %.3g (grazing %.3g) of S\n", stats.rays, stats.hits,
              stats.worst, stats.worst_grazing);
}

TEST(ConeInterval, AgreesWithTheGeneralFrustumSolidInterval) {
  // The specialised cone interval against frustum_solid_interval on the same solid
  // (cone_local_shape), random cones and rays: the same interval to rounding.
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(0, 1);
  auto unit = [&] {
    std::normal_distribution<double> n;
    return glm::normalize(glm::dvec3(n(rng), n(rng), n(rng)));
  };
  int hits = 0;
  double worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const double r = std::exp(std::log(1e-3) + u(rng) * std::log(1e3));
    const double tan_theta = (u(rng) - 0.5) * (u(rng) < 0.5 ? 0.02 : 1.0);
    const double length = std::exp(std::log(1e-2) + u(rng) * std::log(1e5));
    const glm::dvec3 base = (u(rng) < 0.3 ? 1e5 : 1.0) * unit();
    const ShadowCone c = make_cone(base, unit(), r, tan_theta, length);
    const glm::dvec3 target = c.base + u(rng) * c.end_s() * c.axis + 1.2 * r * unit();
    const Ray ray{target - (3 * (c.end_s() + r) * u(rng) + r) * unit(), glm::normalize(unit())};
    const Ray aimed{ray.origin, target - ray.origin};
    for (const Ray& q : {ray, aimed}) {
      const SolidInterval a = shadow_cone_interval(q, c, 0, kFar);
      const SolidInterval b = frustum_solid_interval({q.origin - c.base, q.direction}, cone_local_shape(c), 0, kFar);
      const double scale = std::max(glm::length(q.origin - c.base), c.end_s() + r) / glm::length(q.direction);
      const double width = std::max(a.hit ? a.t_exit - a.t_enter : 0, b.hit ? b.t_exit - b.t_enter : 0);
      if (a.hit != b.hit) {
        EXPECT_LT(width, 1e-6 * scale) << "hit/miss differ on a wide interval, cone " << i;
        continue;
      }
      if (!a.hit) continue;
      ++hits;
      const double e = std::max(std::abs(a.t_enter - b.t_enter), std::abs(a.t_exit - b.t_exit)) / scale;
      worst = std::max(worst, e);
      EXPECT_LT(e, 1e-12) << "cone " << i;
    }
  }
  EXPECT_GT(hits, 5000);
  std::printf("against frustum_solid_interval: %d hits, worst difference %.3g of the scale\n", hits, worst);
}

TEST(ConeInterval, CylinderCrossedHeadOnHasTheDiameterAsWidth) {
  const ShadowCone c = make_cone({0, 0, 0}, {0, -1, 0}, 0.5, 0, 10);
  const SolidInterval iv = shadow_cone_interval({{3, -4, 0}, {-1, 0, 0}}, c, 0, kFar);
  ASSERT_TRUE(iv.hit);
  EXPECT_DOUBLE_EQ(iv.t_enter, 2.5);
  EXPECT_DOUBLE_EQ(iv.t_exit, 3.5);
}

TEST(ConeInterval, ExpandingConeIsWiderDownstream) {
  // r(s) = 0.1 + 0.5·s: at s = 2 the radius is 1.1.
  const ShadowCone c = make_cone({0, 0, 0}, {0, -1, 0}, 0.1, 0.5, 4);
  const SolidInterval iv = shadow_cone_interval({{5, -2, 0}, {-1, 0, 0}}, c, 0, kFar);
  ASSERT_TRUE(iv.hit);
  EXPECT_NEAR(iv.t_enter, 5 - 1.1, 1e-14);
  EXPECT_NEAR(iv.t_exit, 5 + 1.1, 1e-14);
}

TEST(ConeInterval, ConvergingConeEndsAtItsApex) {
  // r(s) = 1 − 0.5·s reaches 0 at s = 2, before length 10.
  const ShadowCone c = make_cone({0, 0, 0}, {0, -1, 0}, 1, -0.5, 10);
  EXPECT_DOUBLE_EQ(c.end_s(), 2);
  const SolidInterval along = shadow_cone_interval({{0, 1, 0}, {0, -1, 0}}, c, 0, kFar);
  ASSERT_TRUE(along.hit);
  EXPECT_DOUBLE_EQ(along.t_enter, 1);
  EXPECT_NEAR(along.t_exit, 3, 1e-15);
  EXPECT_FALSE(shadow_cone_interval({{1, -2.5, 0}, {-1, 0, 0}}, c, 0, kFar).hit);  // beyond the apex
  EXPECT_FALSE(cone_contains(c, {0, -2.5, 0}));
  EXPECT_TRUE(cone_contains(c, {0.49, -1, 0}));
  EXPECT_FALSE(cone_contains(c, {0.51, -1, 0}));
}

TEST(ConeInterval, RangeClipsTheInterval) {
  const ShadowCone c = make_cone({0, 0, 0}, {0, -1, 0}, 0.5, 0, 10);
  const SolidInterval iv = shadow_cone_interval({{3, -4, 0}, {-1, 0, 0}}, c, 3, 10);
  ASSERT_TRUE(iv.hit);
  EXPECT_DOUBLE_EQ(iv.t_enter, 3);
  EXPECT_DOUBLE_EQ(iv.t_exit, 3.5);
  EXPECT_FALSE(shadow_cone_interval({{3, -4, 0}, {-1, 0, 0}}, c, 0, 2).hit);
}

// ---- ConeSet ---------------------------------------------------------------------------

TEST(ConeSet, SortAndMergeJoinsOverlapsAndTouches) {
  std::vector<ConeInterval> v = {{5, 6}, {1, 2}, {1.5, 3}, {3, 4}, {7, 9}, {8, 8.5}};
  sort_and_merge(v);
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v[0].t_enter, 1);
  EXPECT_EQ(v[0].t_exit, 4);  // [1,2] ∪ [1.5,3] ∪ [3,4] (touching at 3)
  EXPECT_EQ(v[1].t_enter, 5);
  EXPECT_EQ(v[1].t_exit, 6);
  EXPECT_EQ(v[2].t_enter, 7);
  EXPECT_EQ(v[2].t_exit, 9);  // [8, 8.5] inside [7, 9]
}

TEST(ConeSet, IntervalsClearsTheOutputAndMergesCones) {
  // Two overlapping parallel cylinders and a third apart, crossed head-on.
  const ConeSet set({make_cone({0, 0, 0}, {0, -1, 0}, 1, 0, 5), make_cone({1.5, 0, 0}, {0, -1, 0}, 1, 0, 5),
                     make_cone({6, 0, 0}, {0, -1, 0}, 0.5, 0, 5)});
  std::vector<ConeInterval> out = {{-1, -0.5}};
  set.intervals({{10, -1, 0}, {-1, 0, 0}}, 0, kFar, &out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[0].t_enter, 3.5, 1e-14);
  EXPECT_NEAR(out[0].t_exit, 4.5, 1e-14);
  EXPECT_NEAR(out[1].t_enter, 10 - 2.5, 1e-14);
  EXPECT_NEAR(out[1].t_exit, 11, 1e-14);
  EXPECT_EQ(set.size(), 3u);
  // A ray above the cones' bases sees none.
  set.intervals({{10, 0.5, 0}, {-1, 0, 0}}, 0, kFar, &out);
  EXPECT_TRUE(out.empty());
}

TEST(ConeSet, EmptySetHasNoIntervals) {
  const ConeSet set;
  std::vector<ConeInterval> out = {{0, 1}};
  set.intervals({{0, 0, 0}, {1, 0, 0}}, 0, kFar, &out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(set.size(), 0u);
  EXPECT_FALSE(set.contains({0, 0, 0}));
}

glm::dvec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  for (;;) {
    const glm::dvec3 v(n(rng), n(rng), n(rng));
    if (glm::length(v) > 1e-3) return glm::normalize(v);
  }
}

// Sunlit canopies: thousands of nearly parallel cones of all sizes in a crown, plus a few
// in random directions with Θ of both signs.
std::vector<ShadowCone> random_cones(std::mt19937_64& rng, int count, const glm::dvec3& centre) {
  std::uniform_real_distribution<double> u(0, 1);
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.4, -1, 0.25));
  std::vector<ShadowCone> cones;
  for (int i = 0; i < count; ++i) {
    const bool stray = u(rng) < 0.1;
    const glm::dvec3 axis = stray ? random_unit(rng) : glm::normalize(sun + 0.005 * random_unit(rng));
    const double r = std::exp(std::log(1e-3) + u(rng) * std::log(1e3));  // 1 mm .. 1 m
    const double tan_theta = stray ? (u(rng) - 0.5) * 0.6 : (u(rng) - 0.3) * 0.01;
    const double length = std::exp(std::log(1e-2) + u(rng) * std::log(1e4));  // 1 cm .. 100 m
    const glm::dvec3 base = centre + glm::dvec3(8 * (u(rng) - 0.5), 10 + 8 * u(rng), 8 * (u(rng) - 0.5));
    cones.push_back(make_cone(base, axis, r, tan_theta, length));
  }
  return cones;
}

TEST(ConeSet, HierarchyGivesExactlyTheBruteForceIntervals) {
  for (const glm::dvec3 centre : {glm::dvec3(0, 0, 0), glm::dvec3(1e6, 0, -1e6)}) {
    std::mt19937_64 rng(20250711);
    std::uniform_real_distribution<double> u(0, 1);
    const ConeSet set(random_cones(rng, 3000, centre));
    EXPECT_GT(set.depth(), 5u);
    std::vector<ConeInterval> fast, slow;
    size_t nonempty = 0, total = 0;
    for (int i = 0; i < 2000; ++i) {
      // Camera rays: from outside the crown toward it, from inside it, and toward the sun.
      Ray ray;
      const int kind = i % 3;
      if (kind == 0) {
        ray.origin = centre + glm::dvec3(0, 2, 0) + 40.0 * random_unit(rng);
        ray.direction = glm::normalize(centre + glm::dvec3(6 * (u(rng) - 0.5), 12 * u(rng), 6 * (u(rng) - 0.5)) - ray.origin);
      } else if (kind == 1) {
        ray.origin = centre + glm::dvec3(8 * (u(rng) - 0.5), 18 * u(rng), 8 * (u(rng) - 0.5));
        ray.direction = random_unit(rng) * (0.5 + u(rng));
      } else {
        ray.origin = centre + glm::dvec3(30 * (u(rng) - 0.5), 1.7, 30 * (u(rng) - 0.5));
        ray.direction = glm::normalize(-glm::dvec3(0.4, -1, 0.25) + 0.2 * random_unit(rng));
      }
      const double t_min = u(rng) < 0.3 ? u(rng) * 10 : 0;
      const double t_max = u(rng) < 0.3 ? t_min + u(rng) * 30 : kFar;
      set.intervals(ray, t_min, t_max, &fast);
      set.intervals_brute_force(ray, t_min, t_max, &slow);
      ASSERT_EQ(fast.size(), slow.size()) << "ray " << i;
      for (size_t k = 0; k < fast.size(); ++k) {
        ASSERT_EQ(fast[k].t_enter, slow[k].t_enter) << "ray " << i << " interval " << k;
        ASSERT_EQ(fast[k].t_exit, slow[k].t_exit) << "ray " << i << " interval " << k;
        EXPECT_LT(fast[k].t_enter, fast[k].t_exit);
        EXPECT_GE(fast[k].t_enter, t_min);
        EXPECT_LE(fast[k].t_exit, t_max);
        if (k > 0) {
          EXPECT_GT(fast[k].t_enter, fast[k - 1].t_exit);  // sorted, disjoint
        }
      }
      nonempty += !fast.empty();
      total += fast.size();
    }
    EXPECT_GT(nonempty, 1000u);  // most rays do meet cones
    std::printf("centre (%g, %g, %g): %zu of 2000 rays meet cones, %zu merged intervals, depth %u\n", centre.x,
                centre.y, centre.z, nonempty, total, set.depth());
  }
}

TEST(ConeSet, ContainsAgreesWithTestingEveryCone) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  const std::vector<ShadowCone> cones = random_cones(rng, 2000, {0, 0, 0});
  const ConeSet set(cones);
  int inside = 0;
  for (int i = 0; i < 20000; ++i) {
    const glm::dvec3 p(10 * (u(rng) - 0.5), 20 * u(rng), 10 * (u(rng) - 0.5));
    const bool brute = std::any_of(cones.begin(), cones.end(), [&](const ShadowCone& c) { return cone_contains(c, p); });
    ASSERT_EQ(set.contains(p), brute) << i;
    inside += brute;
  }
  EXPECT_GT(inside, 1000);
}

TEST(ConeSet, IntervalEndsLieOnTheConesBoundary) {
  // Every merged interval's interior is inside some cone and its ends are not (up to a
  // hair): checked by containment just inside and just outside each end.
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(0, 1);
  const ConeSet set(random_cones(rng, 500, {0, 0, 0}));
  std::vector<ConeInterval> out;
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const Ray ray{glm::dvec3(0, 2, 0) + 30.0 * random_unit(rng),
                  glm::normalize(glm::dvec3(6 * (u(rng) - 0.5), 12 * u(rng), 6 * (u(rng) - 0.5)))};
    set.intervals(ray, 0, kFar, &out);
    for (const ConeInterval& iv : out) {
      const double width = iv.t_exit - iv.t_enter;
      if (width < 1e-6) continue;
      EXPECT_TRUE(set.contains(ray.origin + (iv.t_enter + 0.5 * width) * ray.direction));
      const double hair = 1e-6 * std::max(1.0, iv.t_exit);
      if (iv.t_enter > 0) {  // (0: the origin is inside a cone)
        EXPECT_FALSE(set.contains(ray.origin + (iv.t_enter - hair) * ray.direction));
      }
      EXPECT_FALSE(set.contains(ray.origin + (iv.t_exit + hair) * ray.direction));
      ++checked;
    }
  }
  EXPECT_GT(checked, 200);
}

// ---- Clustering ------------------------------------------------------------------------

TEST(Clustering, ShadowVectorIsAtMost32Bytes) { EXPECT_LE(sizeof(ShadowVector), 32u); }

TEST(Clustering, ParamsAreChecked) {
  EXPECT_EQ(cone_params_error(ConeParams{}), nullptr);
  EXPECT_EQ(cone_params_error({100, 20, 16, 20, 2}), nullptr);  // the paper's p1..p4
  EXPECT_NE(cone_params_error({16, 8, 16, 4, 2}), nullptr);     // p1 < p3 + 1
  EXPECT_NE(cone_params_error({96, 1, 24, 4, 2}), nullptr);     // one sector
  EXPECT_NE(cone_params_error({96, 8, 0, 4, 2}), nullptr);
  EXPECT_NE(cone_params_error({96, 8, 24, 0, 2}), nullptr);
  EXPECT_NE(cone_params_error({96, 8, 24, 4, 0}), nullptr);
  EXPECT_NE(cone_params_error({96, 8, 24, 4, NAN}), nullptr);
}

// A flat occluder under the sun: photons from a disc perpendicular to the sun's direction
// `sun` (away from the sun), those that hit the occluder (the plane through `centre` with
// normal `normal`, where `inside` says) leave a shadow vector there. Directions uniform
// over a sun disc of angular radius `sun_radius` (0: parallel).
struct Occluder {
  glm::dvec3 centre{0, 5, 0};
  glm::dvec3 normal{0, 1, 0};
  std::function<bool(double, double)> inside;  // in the plane's frame (axis_frame(normal))
};

ShadowVectors photons_on(const Occluder& occ, const glm::dvec3& sun, double sun_radius, double emitter_radius,
                         int photons, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const AxisFrame emitter = axis_frame(sun);
  const AxisFrame plane = axis_frame(occ.normal);
  ShadowVectors out;
  out.origin = occ.centre;
  const double one_minus_cos = 2 * std::pow(std::sin(sun_radius / 2), 2);
  for (int i = 0; i < photons; ++i) {
    const double rr = emitter_radius * std::sqrt(u(rng)), phi = 2 * 3.14159265358979 * u(rng);
    const glm::dvec3 start = occ.centre - 50.0 * sun + rr * (std::cos(phi) * emitter.e0 + std::sin(phi) * emitter.e1);
    const double h = u(rng) * one_minus_cos, psi = 2 * 3.14159265358979 * u(rng);
    const double sin_t = std::sqrt(h * (2 - h));
    const glm::dvec3 d = glm::normalize((1 - h) * sun + sin_t * (std::cos(psi) * emitter.e0 + std::sin(psi) * emitter.e1));
    const double denom = glm::dot(d, occ.normal);
    if (std::abs(denom) < 1e-9) continue;
    const double t = glm::dot(occ.centre - start, occ.normal) / denom;
    const glm::dvec3 hit = start + t * d;
    const glm::dvec3 q = hit - occ.centre;
    if (!occ.inside(glm::dot(q, plane.e0), glm::dot(q, plane.e1))) continue;
    out.vectors.push_back({glm::vec3(q), glm::vec3(d), 0});
  }
  return out;
}

// Whether a point is in the occluder's shadow under a parallel sun along `sun`.
bool in_parallel_shadow(const Occluder& occ, const glm::dvec3& sun, const glm::dvec3& p) {
  const double denom = glm::dot(sun, occ.normal);
  const double t = glm::dot(occ.centre - p, occ.normal) / denom;  // back toward the sun
  if (!(t < 0)) return false;                                      // p is sunward of the plane
  const glm::dvec3 q = p + t * sun - occ.centre;
  const AxisFrame plane = axis_frame(occ.normal);
  return occ.inside(glm::dot(q, plane.e0), glm::dot(q, plane.e1));
}

const std::vector<uint32_t> kOnePlant = {0};

struct Coverage {
  double shadow_covered = 0;  // fraction of shadowed sample points inside a cone
  double lit_covered = 0;     // lit points inside a cone, per shadowed point
};

// Random points in the box around the occluder's shadow out to `depth` along the sun.
Coverage coverage(const ConeSet& set, const Occluder& occ, const glm::dvec3& sun, double extent, double depth,
                  uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const AxisFrame f = axis_frame(sun);
  int shadowed = 0, shadowed_in = 0, lit_in = 0;
  for (int i = 0; i < 200000; ++i) {
    const glm::dvec3 p = occ.centre + (depth * u(rng) - 0.5) * sun + extent * (2 * u(rng) - 1) * f.e0 +
                         extent * (2 * u(rng) - 1) * f.e1;
    const bool in_cone = set.contains(p);
    if (in_parallel_shadow(occ, sun, p)) {
      ++shadowed;
      shadowed_in += in_cone;
    } else {
      lit_in += in_cone;
    }
  }
  return {double(shadowed_in) / std::max(1, shadowed), double(lit_in) / std::max(1, shadowed)};
}

void expect_vectors_inside_their_cones(const ShadowVectors& v, const std::vector<ShadowCone>& cones,
                                       const std::vector<uint32_t>& cone_of, const ConeParams& params,
                                       const ClusterReport& report) {
  ASSERT_EQ(cone_of.size(), v.vectors.size());
  std::vector<uint32_t> count(cones.size(), 0);
  uint64_t covered = 0;
  for (size_t i = 0; i < v.vectors.size(); ++i) {
    if (cone_of[i] == kNoCone) continue;
    ASSERT_LT(cone_of[i], cones.size());
    ++count[cone_of[i]];
    ++covered;
    const glm::dvec3 p = v.origin + glm::dvec3(v.vectors[i].position);
    EXPECT_TRUE(cone_contains(cones[cone_of[i]], p)) << "vector " << i << " outside its cone " << cone_of[i];
  }
  for (size_t c = 0; c < cones.size(); ++c) {
    EXPECT_EQ(count[c], cones[c].vectors);
    EXPECT_GE(cones[c].vectors, params.p4);  // p4 honoured
  }
  EXPECT_EQ(report.covered, covered);
  EXPECT_EQ(report.covered + report.discarded, report.vectors);
  EXPECT_EQ(report.cones, cones.size());
}

TEST(Clustering, DiscUnderParallelSunGivesConesFillingItsShadowCylinder) {
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.2, -1, 0.1));
  Occluder disc;
  disc.normal = glm::normalize(glm::dvec3(0.3, 1, -0.2));  // tilted against the sun
  disc.inside = [](double x, double y) { return x * x + y * y <= 1; };
  const ShadowVectors v = photons_on(disc, sun, 0, 1.5, 40000, 1);
  ASSERT_GT(v.vectors.size(), 10000u);
  const ConeParams params;
  ClusterReport report;
  std::vector<uint32_t> cone_of;
  const std::vector<ShadowCone> cones = cluster_shadow_cones(v, kOnePlant, params, {20, false, 0}, &report, &cone_of);
  ASSERT_GT(cones.size(), 10u);
  expect_vectors_inside_their_cones(v, cones, cone_of, params, report);
  for (const ShadowCone& c : cones) {
    EXPECT_NEAR(glm::dot(c.axis, sun), 1, 1e-9);  // parallel sun: the axis is the sun's direction
    EXPECT_LT(c.tan_theta, 1e-6);                 // and the expansion is none
    EXPECT_EQ(c.plant, 0u);
  }
  const Coverage cov = coverage(ConeSet(cones), disc, sun, 1.6, 15, 2);
  std::printf("disc: %zu vectors, %zu cones, %llu covered; shadow covered %.3f, lit covered %.3f\n",
              v.vectors.size(), cones.size(), (unsigned long long)report.covered, cov.shadow_covered, cov.lit_covered);
  EXPECT_GT(cov.shadow_covered, 0.9);
  EXPECT_LT(cov.lit_covered, 0.1);  // a rim of spill: cones stop about one ring past the edge
}

TEST(Clustering, ConesDoNotBridgeTheGapBetweenTwoStrips) {
  const glm::dvec3 sun{0, -1, 0};
  Occluder strips;
  strips.inside = [](double x, double y) { return std::abs(y) <= 1 && std::abs(x) >= 0.15 && std::abs(x) <= 1; };
  const ShadowVectors v = photons_on(strips, sun, 0, 1.5, 40000, 3);
  ClusterReport report;
  std::vector<uint32_t> cone_of;
  const std::vector<ShadowCone> cones = cluster_shadow_cones(v, kOnePlant, ConeParams{}, {20, false, 0}, &report, &cone_of);
  ASSERT_GT(cones.size(), 4u);
  expect_vectors_inside_their_cones(v, cones, cone_of, ConeParams{}, report);
  const Coverage cov = coverage(ConeSet(cones), strips, sun, 1.2, 10, 4);
  // The 0.3 m gap is lit. Cones stop about one ring past an edge (the ring that crosses
  // it is the one that fails), so they spill a few centimetres into the gap, never
  // across its middle third.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  const ConeSet set(cones);
  const AxisFrame plane = axis_frame(strips.normal);
  int gap_in = 0, middle_in = 0;
  for (int i = 0; i < 20000; ++i) {
    const double x = 0.15 * (2 * u(rng) - 1);
    const glm::dvec3 p = strips.centre + x * plane.e0 + (2 * u(rng) - 1) * plane.e1 - 5 * u(rng) * glm::dvec3(0, 1, 0);
    const bool in = set.contains(p);
    gap_in += in;
    middle_in += in && std::abs(x) < 0.05;
  }
  std::printf("strips: %zu cones; shadow covered %.3f, lit covered %.3f, gap covered %.4f\n", cones.size(),
              cov.shadow_covered, cov.lit_covered, gap_in / 20000.0);
  EXPECT_GT(cov.shadow_covered, 0.9);
  EXPECT_LT(cov.lit_covered, 0.1);
  EXPECT_LT(gap_in, 20000 / 5);  // under 20% of the gap: 3 cm of each 15 cm half
  EXPECT_EQ(middle_in, 0);
}

TEST(Clustering, SunDiscGivesTheSunsAngularRadiusAsExpansion) {
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.2, -1, 0.1));
  Occluder disc;
  disc.inside = [](double x, double y) { return x * x + y * y <= 1; };
  const ShadowVectors v = photons_on(disc, sun, kSunRadiusRad, 1.5, 40000, 6);
  std::vector<uint32_t> cone_of;
  ClusterReport report;
  const std::vector<ShadowCone> cones = cluster_shadow_cones(v, kOnePlant, ConeParams{}, {20, false, 0}, &report, &cone_of);
  ASSERT_GT(cones.size(), 10u);
  expect_vectors_inside_their_cones(v, cones, cone_of, ConeParams{}, report);
  for (const ShadowCone& c : cones) {
    // The largest deviation from the mean of >= p4 directions uniform over the disc:
    // above half the sun's radius, below its diameter.
    EXPECT_GT(c.tan_theta, 0.5 * kSunRadiusRad);
    EXPECT_LT(c.tan_theta, 2 * kSunRadiusRad);
    EXPECT_LT(std::acos(std::min(1.0, glm::dot(c.axis, sun))), kSunRadiusRad);
  }
}

TEST(Clustering, MinimumVectorsPerConeIsHonoured) {
  const glm::dvec3 sun{0, -1, 0};
  Occluder disc;
  disc.inside = [](double x, double y) { return x * x + y * y <= 1; };
  const ShadowVectors v = photons_on(disc, sun, 0, 1.2, 20000, 7);
  size_t previous = SIZE_MAX;
  for (uint32_t p4 : {1u, 20u, 60u, 97u}) {
    ConeParams params;
    params.p4 = p4;
    ClusterReport report;
    std::vector<uint32_t> cone_of;
    const std::vector<ShadowCone> cones = cluster_shadow_cones(v, kOnePlant, params, {20, false, 0}, &report, &cone_of);
    expect_vectors_inside_their_cones(v, cones, cone_of, params, report);
    EXPECT_LE(cones.size(), previous);
    previous = cones.size();
    if (p4 > params.p1) {
      EXPECT_TRUE(cones.empty());  // a cone holds at most K's p1 vectors
    }
  }
}

TEST(Clustering, ConesEndBelowTheGroundOrAtTheLengthLimit) {
  const glm::dvec3 sun = glm::normalize(glm::dvec3(1, -1, 0));  // 45° elevation
  Occluder disc;
  disc.inside = [](double x, double y) { return x * x + y * y <= 1; };
  const ShadowVectors v = photons_on(disc, sun, 0, 1.5, 20000, 8);  // disc at y = 5
  const std::vector<ShadowCone> grounded = cluster_shadow_cones(v, kOnePlant, ConeParams{}, {100, true, 0});
  ASSERT_FALSE(grounded.empty());
  const double horizontal = std::sqrt(0.5), descent = std::sqrt(0.5);
  for (const ShadowCone& c : grounded) {
    // Parallel sun: the highest point of the end disc is on the ground.
    const glm::dvec3 end = c.base + c.length_m * c.axis;
    EXPECT_NEAR(end.y + c.radius_base_m * horizontal, 0, 1e-9);
    EXPECT_NEAR(c.length_m, (c.base.y + c.radius_base_m * horizontal) / descent, 1e-9);
  }
  const std::vector<ShadowCone> limited = cluster_shadow_cones(v, kOnePlant, ConeParams{}, {2, true, 0});
  ASSERT_EQ(limited.size(), grounded.size());
  for (const ShadowCone& c : limited) EXPECT_EQ(c.length_m, 2);
}

TEST(Clustering, IsDeterministicAndSeparatesPlants) {
  const glm::dvec3 sun{0, -1, 0};
  Occluder disc;
  disc.inside = [](double x, double y) { return x * x + y * y <= 1; };
  ShadowVectors v = photons_on(disc, sun, kSunRadiusRad, 1.2, 20000, 9);
  // Frusta 0 and 1 belong to plants 3 and 1: the left half of the disc is plant 3's.
  for (ShadowVector& s : v.vectors) s.frustum = s.position.x < 0 ? 0 : 1;
  const std::vector<uint32_t> plant_of = {3, 1};
  ClusterReport a_report, b_report;
  const std::vector<ShadowCone> a = cluster_shadow_cones(v, plant_of, ConeParams{}, {20, false, 0}, &a_report);
  const std::vector<ShadowCone> b = cluster_shadow_cones(v, plant_of, ConeParams{}, {20, false, 0}, &b_report);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].base, b[i].base);
    EXPECT_EQ(a[i].axis, b[i].axis);
    EXPECT_EQ(a[i].radius_base_m, b[i].radius_base_m);
    EXPECT_EQ(a[i].tan_theta, b[i].tan_theta);
  }
  EXPECT_EQ(a_report.plants, 2u);
  // Plant 1's cones first (increasing plant index), each from one half only.
  bool seen_plant_3 = false;
  for (const ShadowCone& c : a) {
    if (c.plant == 3) seen_plant_3 = true;
    else EXPECT_FALSE(seen_plant_3) << "cones come out in plant order";
    EXPECT_TRUE(c.plant == 1 || c.plant == 3);
  }
  EXPECT_TRUE(seen_plant_3);
}

TEST(Clustering, IsTheSameOnEveryThreadCountAndWithSharedNeighbours) {
  // Blocks of seeds are proposed in parallel and accepted in order: the sequential
  // result, whatever the thread count; and a neighbour table shared by several
  // clusterings gives each one's own result.
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.2, -1, 0.1));
  Occluder ring;
  ring.inside = [](double x, double y) { return x * x + y * y <= 4 && x * x + y * y >= 0.25; };
  const ShadowVectors v = photons_on(ring, sun, kSunRadiusRad, 2.2, 60000, 11);
  ASSERT_GT(v.vectors.size(), 20000u);  // more than a few blocks of seeds
  const ConeParams params;
  const ConeLimits limits{20, false, 0};
  std::vector<uint32_t> one_of, many_of;
  const std::vector<ShadowCone> one = cluster_shadow_cones(v, kOnePlant, params, limits, nullptr, &one_of, 1);
  const std::vector<ShadowCone> many = cluster_shadow_cones(v, kOnePlant, params, limits, nullptr, &many_of, 3);
  const ShadowVectorIndex shared(v, kOnePlant, 2 * params.p1, 2);
  std::vector<uint32_t> shared_of;
  const std::vector<ShadowCone> from_table = shared.cluster(params, limits, nullptr, &shared_of, 2);
  ASSERT_GT(one.size(), 50u);
  for (const std::vector<ShadowCone>* other : {&many, &from_table}) {
    ASSERT_EQ(other->size(), one.size());
    for (size_t i = 0; i < one.size(); ++i) {
      EXPECT_EQ((*other)[i].base, one[i].base);
      EXPECT_EQ((*other)[i].radius_base_m, one[i].radius_base_m);
      EXPECT_EQ((*other)[i].tan_theta, one[i].tan_theta);
      EXPECT_EQ((*other)[i].vectors, one[i].vectors);
    }
  }
  EXPECT_EQ(many_of, one_of);
  EXPECT_EQ(shared_of, one_of);
}

TEST(Clustering, NoVectorsGiveNoCones) {
  ClusterReport report;
  EXPECT_TRUE(cluster_shadow_cones({}, kOnePlant, ConeParams{}, {20, false, 0}, &report).empty());
  EXPECT_EQ(report.vectors, 0u);
  EXPECT_EQ(report.cones, 0u);
}

}  // namespace
}  // namespace sylva
