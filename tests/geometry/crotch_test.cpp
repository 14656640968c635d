// Tests of core/geometry/crotch.h: the frusta's signed bound, where crotches are, the
// blended field against the exact union, and the march against a fine walk.
#include "core/geometry/crotch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <random>

#include "tests/support/limb_crotch.h"

namespace sylva {
namespace {

using glm::dvec3;

using test::LimbCrotch;
using test::random_unit;

bool inside(const FrustumShape& f, const dvec3& p) {
  const double y = glm::dot(p - f.base, f.axis);
  const double rho = glm::length(p - f.base - y * f.axis);
  const double r = f.radius_at(y);
  return glm::dot(f.lower.normal, p) >= f.lower.offset && glm::dot(f.upper.normal, p) <= f.upper.offset && r >= 0 &&
         rho <= r;
}

TEST(Crotch, TheFrustumBoundIsNegativeExactlyInsideAndOneLipschitz) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int insides = 0;
  for (int shape = 0; shape < 40; ++shape) {
    FrustumShape f;
    f.base = dvec3(u(rng), u(rng), u(rng));
    f.axis = random_unit(rng);
    f.length = 0.5 + 0.5 * (u(rng) + 1);
    f.radius0 = 0.05 + 0.2 * (u(rng) + 1);
    f.radius1 = shape % 5 == 0 ? 0.0 : 0.05 + 0.2 * (u(rng) + 1);  // some cones reach their apex
    // Planes tilted up to about 40° against the axis.
    auto tilted = [&](const dvec3& point) {
      dvec3 n = glm::normalize(f.axis + 0.8 * dvec3(u(rng), u(rng), u(rng)) * 0.6);
      if (glm::dot(n, f.axis) < 0.77) n = f.axis;
      return Plane{n, glm::dot(n, point)};
    };
    f.lower = tilted(f.base);
    f.upper = tilted(f.base + f.length * f.axis);
    for (int i = 0; i < 400; ++i) {
      const double box = i % 2 ? 1.5 : 0.4;  // half the points near the solid
      const dvec3 p = f.base + 0.5 * f.length * f.axis + box * dvec3(u(rng), u(rng), u(rng));
      const dvec3 q = p + 0.3 * dvec3(u(rng), u(rng), u(rng));
      const double fp = frustum_bound(f, p), fq = frustum_bound(f, q);
      EXPECT_LE(std::abs(fp - fq), glm::length(p - q) * (1 + 1e-12)) << "shape " << shape;
      if (std::abs(fp) > 1e-12) {
        EXPECT_EQ(fp < 0, inside(f, p)) << "shape " << shape << " bound " << fp;
      }
      insides += fp < 0;
    }
  }
  EXPECT_GT(insides, 500) << "the points probe the inside too";
  // Beside a cylinder's side the bound is the distance.
  FrustumShape c;
  c.length = 2;
  c.radius0 = c.radius1 = 0.3;
  c.upper.offset = 2;
  EXPECT_NEAR(frustum_bound(c, {0.4, 1, 0}), 0.1, 1e-15);
  EXPECT_NEAR(frustum_bound(c, {0, 2.25, 0.1}), 0.25, 1e-15);
}

TEST(Crotch, OneCrotchWhereTheLimbLeavesTheTrunkOnItsSurfaceAndNoneForTheTwig) {
  const Skeleton sk = test::limb_on_trunk();
  const SkinnedSkeleton skinned = skin_skeleton(sk);
  const std::vector<Crotch> crotches = find_crotches(sk, skinned.frusta);
  ASSERT_EQ(crotches.size(), 1u);
  const Crotch& c = crotches[0];
  EXPECT_EQ(c.lateral, 1u);
  EXPECT_NEAR(std::hypot(c.centre.x, c.centre.z), 0.3, 1e-9) << "on the trunk's surface";
  EXPECT_NEAR(c.k, 0.12, 1e-15);
  for (uint32_t i : c.parent_frusta) EXPECT_NE(skinned.frusta[i].chain, 1u) << "the trunk's and the twig's";
  for (uint32_t i : c.lateral_frusta) EXPECT_EQ(skinned.frusta[i].chain, 1u);
  EXPECT_FALSE(c.parent_frusta.empty());
  EXPECT_FALSE(c.lateral_frusta.empty());
  const CrotchSample at_centre = crotch_field(c, skinned.frusta, c.centre);
  EXPECT_NEAR(at_centre.parent, 0, 0.01) << "within the trunk's taper above the joint";
  EXPECT_LT(at_centre.lateral, -0.1) << "the limb's axis point is deep in the limb";
  // The paper's skin has the same crotch (the blend does not need a collar).
  EXPECT_EQ(find_crotches(sk, skin_skeleton(sk, SkinOptions::paper()).frusta).size(), 1u);
}

TEST(Crotch, AViewSeesAFilletOnlyWhereItsWidthSpansTwoPixels) {
  // k = 0.12 m: at 1000 pixels a radian it spans 2 pixels 60 m beyond the ball's surface.
  const Skeleton sk = test::limb_on_trunk();
  const Crotch c = find_crotches(sk, skin_skeleton(sk).frusta).at(0);
  const dvec3 away = glm::normalize(dvec3(1, 0.5, 2));
  auto eye_at = [&](double beyond_ball_m) { return c.centre + (c.radius + beyond_ball_m) * away; };
  EXPECT_TRUE(crotch_seen(c, eye_at(59.0), 1000));
  EXPECT_FALSE(crotch_seen(c, eye_at(61.0), 1000));
  EXPECT_TRUE(crotch_seen(c, eye_at(61.0), 2000));              // a finer view
  EXPECT_TRUE(crotch_seen(c, eye_at(61.0), 1000, 1.0));         // a lower bar
  EXPECT_TRUE(crotch_seen(c, c.centre + 0.5 * c.radius * away, 1e-6));  // the eye in the ball
}

TEST(Crotch, TheBlendOnlyFillsTheCreaseByAtMostAQuarterOfKAndNothingOutsideItsBall) {
  const LimbCrotch limb;
  const SkinnedSkeleton& skinned = limb.skinned;
  const Crotch& c = limb.crotch;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  int filled = 0, outside_ball = 0;
  double deepest_fill = 0;
  for (int i = 0; i < 200000; ++i) {
    const dvec3 p = c.centre + 1.3 * c.radius * dvec3(u(rng), u(rng), u(rng));
    const CrotchSample s = crotch_field(c, skinned.frusta, p);
    const double exact = std::min(s.parent, s.lateral);
    ASSERT_LE(s.value, exact) << "the blend never removes material";
    ASSERT_GE(s.value, exact - c.k / 4 - 1e-15);
    if (glm::length(p - c.centre) >= c.radius) {
      ++outside_ball;
      ASSERT_EQ(s.value, exact) << "outside the ball the union is exact";
    }
    if (s.value <= 0 && exact > 0) {
      ++filled;
      deepest_fill = std::max(deepest_fill, exact);
      // A filled point is near both surfaces: in the crease, not beside one surface alone.
      EXPECT_LT(std::abs(s.parent - s.lateral), c.k);
    }
    EXPECT_GE(s.h, 0);
    EXPECT_LE(s.h, 1);
  }
  EXPECT_GT(outside_ball, 1000);
  EXPECT_GT(filled, 20) << "the crease is filled";
  std::printf("filled %d of 200000 points, the deepest %.4f m outside the union (k/4 = %.4f)\n", filled,
              deepest_fill, c.k / 4);
  EXPECT_LE(deepest_fill, c.k / 4);
  EXPECT_GT(deepest_fill, c.k / 16) << "a fillet of a visible size";
}

// The first t in (lo, hi) where the field is <= 0, by a walk of steps `dt` and bisection;
// none where the ray starts inside (as march_crotch).
std::optional<double> fine_walk(const Crotch& c, std::span<const Frustum> frusta, const Ray& ray, double lo, double hi,
                                double dt) {
  auto f = [&](double t) { return crotch_field(c, frusta, ray.origin + t * ray.direction).value; };
  if (!(f(lo) > 0)) return std::nullopt;
  for (double t = lo; t < hi; t += dt) {
    const double t1 = std::min(t + dt, hi);
    if (f(t1) <= 0) {
      double a = t, b = t1;
      for (int k = 0; k < 60; ++k) (f(0.5 * (a + b)) > 0 ? a : b) = 0.5 * (a + b);
      return b;
    }
  }
  return std::nullopt;
}

TEST(Crotch, TheMarchFindsTheFirstCrossingThatAFineWalkFinds) {
  const LimbCrotch limb;
  const SkinnedSkeleton& skinned = limb.skinned;
  const Crotch& c = limb.crotch;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  int hits = 0, grazing = 0, max_steps = 0, fillet_hits = 0, fillet_only_gave_up = 0;
  for (int i = 0; i < 400; ++i) {
    const dvec3 target = c.centre + 0.9 * c.radius * std::abs(u(rng)) * random_unit(rng);
    const dvec3 origin = c.centre + 3 * c.radius * random_unit(rng);
    const double scale = i % 2 ? 1.0 : 2.5;  // t in units of a direction that is not unit
    Ray ray{origin, scale * (target - origin)};
    const std::optional<CrotchHit> got = march_crotch(c, skinned.frusta, ray, 0, 10);
    // The ball's span of t (the textbook roots: the ray starts well away from the ball).
    const dvec3 o = ray.origin - c.centre;
    const double a = glm::dot(ray.direction, ray.direction), b = glm::dot(o, ray.direction);
    const double root = std::sqrt(b * b - a * (glm::dot(o, o) - c.radius * c.radius));
    const double lo = (-b - root) / a, hi = (-b + root) / a;
    ASSERT_GE(lo, 0);
    const double speed = glm::length(ray.direction);
    const std::optional<double> want = fine_walk(c, skinned.frusta, ray, lo, hi, 1e-4 * c.radius / speed);
    ASSERT_EQ(got.has_value(), want.has_value()) << "ray " << i;
    // Asked for the fillet only (as the tracer does, with the exact hit as t_max), the march
    // finds every fillet crossing at the same t and gives up early on the others.
    const double t_max = got ? got->t + 1e-3 * c.radius / glm::length(ray.direction) : 10.0;
    const std::optional<CrotchHit> fillet = march_crotch(c, skinned.frusta, ray, 0, t_max, true);
    if (got) {
      const CrotchSample at = crotch_field(c, skinned.frusta, ray.origin + got->t * ray.direction);
      if (std::min(at.parent, at.lateral) > 1e-6 * c.radius) {
        ++fillet_hits;
        ASSERT_TRUE(fillet) << "ray " << i;
        EXPECT_NEAR(fillet->t, got->t, 1e-9) << "ray " << i;
      } else if (fillet) {  // the exact surface, reached before the test could rule it out
        EXPECT_NEAR(fillet->t, got->t, 1e-9) << "ray " << i;
      } else {
        ++fillet_only_gave_up;
      }
    } else {
      EXPECT_FALSE(fillet) << "ray " << i;
    }
    if (got) {
      ++hits;
      EXPECT_NEAR(got->t * speed, *want * speed, 2e-5 * c.radius) << "ray " << i;
      max_steps = std::max(max_steps, got->steps);
      grazing += got->steps > 100;
    }
  }
  EXPECT_GT(hits, 100);
  EXPECT_GT(fillet_hits, 20);
  EXPECT_GT(fillet_only_gave_up, (hits - fillet_hits) / 2);
  std::printf("march: %d hits of 400 rays (%d on the fillet), at most %d field evaluations, %d over 100; "
              "asked for the fillet only, %d of the exact surface's hits given up\n",
              hits, fillet_hits, max_steps, grazing, fillet_only_gave_up);
}

// Along a fan of rays across the crease, the shading normal of the blended surface turns
// smoothly, and where the fillet gives way to a surface alone (h = 0 or 1) it is that
// surface's own eq. 8 normal.
TEST(Crotch, TheShadingNormalTurnsSmoothlyAcrossTheFilletAndIsTheSurfacesOwnAtItsEdge) {
  const LimbCrotch limb;
  const SkinnedSkeleton& skinned = limb.skinned;
  const Crotch& c = limb.crotch;
  // Looking along −z at the acute side of the crotch (between the limb and the trunk above).
  const dvec3 eye = c.centre + dvec3(0.05, 0.15, 2.0);
  bool previous = false;
  dvec3 previous_point(0), previous_normal(0);
  int hits = 0, fillet = 0, alone = 0;
  double worst_turn_deg = 0;
  for (int i = 0; i <= 400; ++i) {
    const double x = -0.6 * c.radius + 1.2 * c.radius * i / 400;
    const dvec3 target = c.centre + dvec3(x, x * 0.4 + 0.1 * c.radius, 0);
    const Ray ray{eye, target - eye};
    const std::optional<CrotchHit> hit = march_crotch(c, skinned.frusta, ray, 0, 10);
    if (!hit) {
      previous = false;
      continue;
    }
    ++hits;
    const dvec3 p = ray.origin + hit->t * ray.direction;
    const CrotchShade s = crotch_shade(c, skinned.frusta, p);
    EXPECT_NEAR(glm::length(s.normal), 1, 1e-12);
    EXPECT_GT(glm::dot(s.normal, -ray.direction), 0) << "the surface faces the eye";
    fillet += s.h > 0.05 && s.h < 0.95;
    if (s.h == 0 || s.h == 1) {
      ++alone;
      const Frustum& f = skinned.frusta[s.h == 1 ? s.parent_frustum : s.lateral_frustum];
      EXPECT_LT(glm::length(s.normal - surface_normal(f, p, NormalMode::interpolated)), 1e-12);
    }
    if (previous && glm::length(p - previous_point) < 0.02 * c.radius) {
      const double turn = std::acos(std::clamp(glm::dot(s.normal, previous_normal), -1.0, 1.0)) * 180 / 3.14159265358979;
      worst_turn_deg = std::max(worst_turn_deg, turn);
    }
    previous = true;
    previous_normal = s.normal;
    previous_point = p;
  }
  EXPECT_GT(hits, 100);
  EXPECT_GT(fillet, 10) << "the fan crosses the fillet";
  EXPECT_GT(alone, 10) << "and the surfaces beside it";
  EXPECT_LT(worst_turn_deg, 5) << "no crease: neighbouring hits' normals differ by little";
  std::printf("fan: %d hits, %d on the fillet, worst turn %.2f deg\n", hits, fillet, worst_turn_deg);
}

}  // namespace
}  // namespace sylva
