// bvh_test.cpp — the BVH finds exactly what testing every frustum finds.
#include "core/cpu/bvh.h"
#include "core/cpu/frustum_accel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <glm/geometric.hpp>
#include <limits>
#include <optional>
#include <random>

namespace sylva {
namespace {

// A random forest of bent chains with branches: realistic frusta (mitred joints, split
// joints with knuckles, caps, tips) for the BVH to sort.
Skeleton random_skeleton(uint32_t seed, int chains, int joints_per_chain, double offset) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Skeleton sk;
  for (int c = 0; c < chains; ++c) {
    Chain chain;
    chain.first_joint = static_cast<uint32_t>(sk.joints.size());
    chain.joint_count = static_cast<uint32_t>(joints_per_chain);
    glm::dvec3 p{offset + 5 * u(rng), offset + 5 * u(rng), offset + 5 * u(rng)};
    glm::dvec3 dir{u(rng), 1, u(rng)};
    double radius = 0.05 + 0.1 * (u(rng) + 1);
    for (int j = 0; j < joints_per_chain; ++j) {
      bool tip = j + 1 == joints_per_chain && (c % 3 == 0);
      sk.joints.push_back({{p.x, p.y, p.z}, tip ? 0.0 : radius, 0});
      dir = glm::normalize(dir + 0.8 * glm::dvec3(u(rng), u(rng), u(rng)));
      p += (0.3 + 0.3 * (u(rng) + 1)) * dir;
      radius *= 0.9;
    }
    if (c > 0 && c % 2 == 0) chain.parent = ChainParent{static_cast<uint32_t>(c - 1), 1};
    sk.chains.push_back(chain);
  }
  return sk;
}

// Nearest and any-hit queries of one acceleration structure over `frusta`.
struct Queries {
  std::function<BvhHit(const Ray&, double, double)> nearest;
  std::function<bool(const Ray&, double, double)> any;
};

void expect_matches_brute_force(std::span<const Frustum> frusta, const Queries& q, uint32_t seed, double offset) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const double inf = std::numeric_limits<double>::infinity();
  int hits = 0;
  for (int r = 0; r < 4000; ++r) {
    Ray ray;
    ray.origin = glm::dvec3(offset) + glm::dvec3(9 * u(rng), 9 * u(rng), 9 * u(rng));
    glm::dvec3 target = glm::dvec3(offset) + glm::dvec3(4 * u(rng), 4 * u(rng), 4 * u(rng));
    ray.direction = target - ray.origin;
    if (r % 7 == 0) ray.direction.y = 0;  // axis-parallel components: the zero-slab path
    if (r % 11 == 0) ray.direction = glm::dvec3(0, -1, 0);
    FrustumHit best;
    uint32_t best_index = 0;
    for (uint32_t f = 0; f < frusta.size(); ++f) {
      FrustumHit h = intersect_frustum(ray, frusta[f].shape, 0, inf);
      if (h.hit() && (!best.hit() || h.t < best.t)) best = h, best_index = f;
    }
    BvhHit got = q.nearest(ray, 0, inf);
    ASSERT_EQ(got.hit_any(), best.hit()) << "ray " << r;
    EXPECT_EQ(q.any(ray, 0, inf), best.hit()) << "ray " << r;
    if (!best.hit()) continue;
    ++hits;
    EXPECT_EQ(got.hit.t, best.t) << "ray " << r;
    EXPECT_EQ(got.frustum, best_index) << "ray " << r;
    // A shadow query that stops short of the nearest hit sees nothing.
    EXPECT_FALSE(q.any(ray, 0, best.t * 0.999)) << "ray " << r;
  }
  EXPECT_GT(hits, 400);  // the rays aim at the plants, so many hit
}

void expect_bvh_matches_brute_force(const Skeleton& sk, uint32_t seed, double offset) {
  SkinnedSkeleton skinned = skin_skeleton(sk);
  ASSERT_GT(skinned.frusta.size(), 50u);
  std::span<const Frustum> frusta(skinned.frusta);
  Bvh bvh = build_bvh(frusta);
  ASSERT_FALSE(bvh.nodes.empty());
  EXPECT_LT(bvh.depth, kBvhStackSize);
  expect_matches_brute_force(
      frusta,
      {[&](const Ray& r, double a, double b) { return intersect_nearest(bvh, frusta, r, a, b); },
       [&](const Ray& r, double a, double b) { return intersect_any(bvh, frusta, r, a, b); }},
      seed, offset);
}

void expect_accel_matches_brute_force(const Skeleton& sk, uint32_t seed, double offset) {
  SkinnedSkeleton skinned = skin_skeleton(sk);
  std::span<const Frustum> frusta(skinned.frusta);
  FrustumAccel accel(frusta);
  EXPECT_GT(accel.memory_bytes(), 0u);
  expect_matches_brute_force(
      frusta,
      {[&](const Ray& r, double a, double b) { return accel.nearest(r, a, b); },
       [&](const Ray& r, double a, double b) { return accel.any(r, a, b); }},
      seed, offset);
}

TEST(FrustumAccel, EmbreeFindsExactlyWhatTestingEveryFrustumFinds) {
  expect_accel_matches_brute_force(random_skeleton(7, 40, 6, 0), 11, 0);
}

TEST(FrustumAccel, EmbreeStaysExactFarFromTheOrigin) {
  expect_accel_matches_brute_force(random_skeleton(8, 40, 6, 1e6), 12, 1e6);
}

// Balls as extra primitives (frustum_accel.h): the blended crotches' role, a plain ray-sphere
// test here.
class Balls final : public ExtraPrimitives {
 public:
  std::vector<glm::dvec3> centres;
  std::vector<double> radii;
  uint32_t count() const override { return static_cast<uint32_t>(centres.size()); }
  Aabb bounds(uint32_t i) const override {
    return {centres[i] - glm::dvec3(radii[i]), centres[i] + glm::dvec3(radii[i])};
  }
  std::optional<double> intersect(uint32_t i, const Ray& ray, double t_min, double t_max) const override {
    const glm::dvec3 o = ray.origin - centres[i];
    const double a = glm::dot(ray.direction, ray.direction), b = glm::dot(o, ray.direction);
    const double disc = b * b - a * (glm::dot(o, o) - radii[i] * radii[i]);
    if (!(disc > 0)) return std::nullopt;
    for (double t : {(-b - std::sqrt(disc)) / a, (-b + std::sqrt(disc)) / a})
      if (t > t_min && t < t_max) return t;
    return std::nullopt;
  }
  bool occludes(uint32_t i, const Ray& ray, double t_min, double t_max) const override {
    return intersect(i, ray, t_min, t_max).has_value();
  }
};

TEST(FrustumAccel, ExtraPrimitivesLeaveTheFrustaHitAndFindTheNearestExtraInFrontOfIt) {
  const SkinnedSkeleton skinned = skin_skeleton(random_skeleton(9, 40, 6, 0));
  std::span<const Frustum> frusta(skinned.frusta);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1, 1);
  Balls balls;
  for (int i = 0; i < 60; ++i) {
    balls.centres.emplace_back(4 * u(rng), 4 * u(rng), 4 * u(rng));
    balls.radii.push_back(0.1 + 0.2 * (u(rng) + 1));
  }
  const FrustumAccel plain(frusta);
  const FrustumAccel with(frusta, {}, &balls);
  const double inf = std::numeric_limits<double>::infinity();
  int extra_hits = 0, frusta_hits = 0;
  for (int r = 0; r < 4000; ++r) {
    Ray ray;
    ray.origin = glm::dvec3(9 * u(rng), 9 * u(rng), 9 * u(rng));
    ray.direction = glm::dvec3(4 * u(rng), 4 * u(rng), 4 * u(rng)) - ray.origin;
    ExtraHit extra;
    const BvhHit want = plain.nearest(ray, 0, inf);
    const BvhHit got = with.nearest(ray, 0, inf, nullptr, &extra);
    ASSERT_EQ(got.hit_any(), want.hit_any()) << "ray " << r;
    if (want.hit_any()) {
      EXPECT_EQ(got.hit.t, want.hit.t) << "ray " << r;
      EXPECT_EQ(got.frustum, want.frustum) << "ray " << r;
      ++frusta_hits;
    }
    // The nearest ball crossing before the frusta's hit, by testing every ball.
    const double t_frusta = want.hit_any() ? want.hit.t : inf;
    std::optional<double> best;
    uint32_t best_index = 0;
    for (uint32_t b = 0; b < balls.count(); ++b) {
      const std::optional<double> t = balls.intersect(b, ray, 0, t_frusta);
      if (t && (!best || *t < *best)) best = t, best_index = b;
    }
    ASSERT_EQ(extra.hit(), best.has_value()) << "ray " << r;
    if (best) {
      EXPECT_EQ(extra.t, *best) << "ray " << r;
      EXPECT_EQ(extra.index, best_index) << "ray " << r;
      ++extra_hits;
    }
    EXPECT_EQ(with.any(ray, 0, inf), want.hit_any() || best.has_value()) << "ray " << r;
  }
  EXPECT_GT(extra_hits, 200);
  EXPECT_GT(frusta_hits, 400);
}

TEST(FrustumAccel, AnEmptySceneHitsNothing) {
  FrustumAccel accel(std::span<const Frustum>{});
  EXPECT_FALSE(accel.nearest(Ray{{0, 0, 0}, {0, 1, 0}}, 0, 1e9).hit_any());
  EXPECT_FALSE(accel.any(Ray{{0, 0, 0}, {0, 1, 0}}, 0, 1e9));
}

TEST(Bvh, NodesAreThirtyTwoBytes) { EXPECT_EQ(sizeof(BvhNode), 32u); }

TEST(Bvh, EmptyInputHasNoNodesAndNoHits) {
  std::vector<Frustum> none;
  Bvh bvh = build_bvh(none);
  EXPECT_TRUE(bvh.nodes.empty());
  Ray ray;
  EXPECT_FALSE(intersect_nearest(bvh, none, ray, 0, 1e9).hit_any());
  EXPECT_FALSE(intersect_any(bvh, none, ray, 0, 1e9));
}

TEST(Bvh, NearestHitEqualsBruteForceOnRandomRays) {
  expect_bvh_matches_brute_force(random_skeleton(1, 40, 8, 0), 2, 0);
}

TEST(Bvh, NearestHitEqualsBruteForceFarFromTheOrigin) {
  expect_bvh_matches_brute_force(random_skeleton(3, 30, 6, 1e6), 4, 1e6);
}

TEST(Bvh, BoundsContainSurfacePoints) {
  SkinnedSkeleton skinned = skin_skeleton(random_skeleton(5, 10, 6, 0));
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> unit(0, 1);
  for (const Frustum& f : skinned.frusta) {
    Aabb box = frustum_bounds(f.shape);
    // Rays from far outside toward the axis: their hits are surface points.
    for (int s = 0; s < 50; ++s) {
      glm::dvec3 on_axis = f.shape.base + unit(rng) * f.shape.length * f.shape.axis;
      glm::dvec3 from = on_axis + 100.0 * glm::dvec3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
      FrustumHit h = intersect_frustum({from, on_axis - from}, f.shape, 0, 2);
      if (!h.hit()) continue;
      glm::dvec3 p = from + h.t * (on_axis - from);
      for (int k = 0; k < 3; ++k) {
        EXPECT_GE(p[k], box.lo[k]);
        EXPECT_LE(p[k], box.hi[k]);
      }
    }
  }
}

}  // namespace
}  // namespace sylva
