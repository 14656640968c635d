// render_cpu_test.cpp — the CPU ray caster against geometry whose answer is known.
#include "core/cpu/render_cpu.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <string>
#include <vector>

#include "tests/support/test_scenes.h"
#include "tests/support/plants.h"

namespace sylva {
namespace {

// One vertical cylinder of radius 0.5 from y = 0 to 2 at the origin, seen from +Z.
Scene cylinder_scene() { return test::scene_around(test::cylinder(0.5, 0, 2), {0, 1, 5}, {0, 1, 0}, 64, 48, -10); }

TEST(RenderCpu, CylinderDepthEqualsTheAnalyticDistance) {
  Scene s = cylinder_scene();
  RenderOptions o;
  o.aovs = kAovDepth | kAovNormal | kAovUv | kAovId;
  RenderResult r = render_cpu(s, o);
  ASSERT_FALSE(r.cancelled);
  const uint32_t i = 32, j = 24;  // centre pixel, sampled at (32.5, 24.5)
  Ray ray = camera_ray(s, i + 0.5, j + 0.5);
  // x² + z² = 0.25 along origin + t·d: a quadratic in long double, the smaller root.
  long double ox = ray.origin.x, oz = ray.origin.z, dx = ray.direction.x, dz = ray.direction.z;
  long double a = dx * dx + dz * dz, b = 2 * (ox * dx + oz * dz), c = ox * ox + oz * oz - 0.25L;
  long double t = (-b - std::sqrt(b * b - 4 * a * c)) / (2 * a);
  long double distance = t * std::sqrt(static_cast<long double>(glm::dot(ray.direction, ray.direction)));
  const size_t pixel = static_cast<size_t>(j) * s.width + i;
  // The AOV is float; the double value behind it is checked to 1e-9 through the ray.
  EXPECT_NEAR(r.image.depth[pixel], static_cast<float>(distance), 1e-6 * static_cast<float>(distance));
  FrustumHit hit = intersect_frustum(ray, build_scene_geometry(s, {}).frusta[0].shape, 0, 1e30);
  ASSERT_TRUE(hit.hit());
  double exact_ray_distance = hit.t * glm::length(ray.direction);
  EXPECT_NEAR(exact_ray_distance, static_cast<double>(distance), 1e-9 * static_cast<double>(distance));

  // The id names plant 0, chain 0, segment 0; the normal faces the camera.
  EXPECT_EQ(r.image.id[pixel * 3 + 0], 0.0f);
  EXPECT_EQ(r.image.id[pixel * 3 + 1], 0.0f);
  EXPECT_EQ(r.image.id[pixel * 3 + 2], 0.0f);
  EXPECT_GT(r.image.normal[pixel * 3 + 2], 0.99f);

  // Every hit pixel's normal faces the camera; misses are +inf with id −1.
  int hits = 0, misses = 0;
  for (uint32_t y = 0; y < s.height; ++y)
    for (uint32_t x = 0; x < s.width; ++x) {
      const size_t p = static_cast<size_t>(y) * s.width + x;
      Ray pr = camera_ray(s, x + 0.5, y + 0.5);
      if (std::isinf(r.image.depth[p])) {
        ++misses;
        EXPECT_GT(r.image.depth[p], 0);
        EXPECT_EQ(r.image.id[p * 3 + 1], -1.0f);
        continue;
      }
      ++hits;
      glm::dvec3 n(r.image.normal[p * 3], r.image.normal[p * 3 + 1], r.image.normal[p * 3 + 2]);
      EXPECT_LT(glm::dot(n, pr.direction), 0) << x << "," << y;
      EXPECT_NEAR(glm::length(n), 1.0, 1e-6);
    }
  EXPECT_GT(hits, 200);
  EXPECT_GT(misses, 1000);
  EXPECT_TRUE(std::isinf(r.image.depth[0]));  // the corner sees only sky
}

TEST(RenderCpu, OnlyRequestedAovsAreAllocated) {
  Scene s = cylinder_scene();
  RenderOptions o;
  o.aovs = kAovDepth;
  RenderResult r = render_cpu(s, o);
  EXPECT_EQ(r.image.beauty.size(), 64u * 48u * 4u);
  EXPECT_EQ(r.image.depth.size(), 64u * 48u);
  EXPECT_TRUE(r.image.normal.empty());
  EXPECT_TRUE(r.image.uv.empty());
  EXPECT_TRUE(r.image.id.empty());
}

TEST(RenderCpu, IdenticalForEveryThreadCountAndSppAveragesStrata) {
  Scene s = cylinder_scene();
  s.sun.angular_radius_deg = 2;  // soft shadows: random numbers in play
  RenderOptions one, two;
  one.threads = 1;
  two.threads = 2;
  one.spp = two.spp = 4;
  one.aovs = two.aovs = kAovDepth;
  RenderResult a = render_cpu(s, one), b = render_cpu(s, two);
  EXPECT_EQ(a.image.beauty, b.image.beauty);
  EXPECT_EQ(a.image.depth, b.image.depth);
  EXPECT_EQ(a.primary_rays, 64u * 48u * 4u);
}

TEST(RenderCpu, CancelledRenderSaysSo) {
  Scene s = cylinder_scene();
  std::atomic<bool> cancel{true};
  RenderOptions o;
  o.progress = Progress(&cancel);
  EXPECT_TRUE(render_cpu(s, o).cancelled);
}

TEST(RenderCpu, ProgressRisesMonotonicallyToOneAndLeavesTheImageAlone) {
  Scene s = test::scene_around(test::cylinder(0.5, 0, 2), {0, 1, 5}, {0, 1, 0}, 256, 192, -10);  // 48 tiles
  std::vector<double> fractions;
  std::vector<std::string> stages;
  RenderOptions o;
  o.threads = 4;
  o.progress = Progress([&](double f, std::string_view stage) {
    fractions.push_back(f);
    stages.emplace_back(stage);
  });
  const RenderResult with = render_cpu(s, o);
  ASSERT_FALSE(with.cancelled);
  ASSERT_GE(fractions.size(), 10u);
  for (size_t i = 1; i < fractions.size(); ++i) EXPECT_LE(fractions[i - 1], fractions[i]);
  EXPECT_EQ(fractions.back(), 1.0);
  EXPECT_EQ(stages.front(), "geometry");
  EXPECT_EQ(stages.back(), "render");
  RenderOptions plain;
  plain.threads = 4;
  EXPECT_EQ(render_cpu(s, plain).image.beauty, with.image.beauty);
}

TEST(RenderCpu, CancellingMidRenderStopsBeforeTheLastTile) {
  Scene s = test::scene_around(test::cylinder(0.5, 0, 2), {0, 1, 5}, {0, 1, 0}, 512, 384, -10);  // 192 tiles
  std::atomic<bool> cancel{false};
  double last = 0;
  RenderOptions o;
  o.threads = 2;
  o.progress = Progress([&](double f, std::string_view stage) {
    last = f;
    if (stage == "render" && f > 0.3) cancel.store(true);
  }, &cancel);
  const RenderResult r = render_cpu(s, o);
  EXPECT_TRUE(r.cancelled);
  EXPECT_LT(last, 0.5);  // each worker finishes the tile it is on, then stops
  // The tiles left undone are still black (the image is incomplete, not garbage).
  EXPECT_EQ(r.image.beauty[r.image.beauty.size() - 4], 0.0f);
}

TEST(RenderCpu, PlacementRotatesScalesAndMoves) {
  ScenePlant plant;
  Skeleton sk;
  sk.joints = {{{1, 0, 0}, 0.1, 0}, {{1, 1, 0}, 0.1, 0}};
  sk.chains = {{0, 2, std::nullopt}};
  plant.skeleton = sk;
  plant.position = {10, 0, 0};
  plant.rotate_y_deg = 90;
  plant.scale = 2;
  Skeleton placed = place_plant(plant);
  // (1,0,0) scaled to (2,0,0), turned 90° about +Y to (0,0,−2), moved to (10,0,−2).
  EXPECT_NEAR(placed.joints[0].position_m[0], 10, 1e-12);
  EXPECT_NEAR(placed.joints[0].position_m[2], -2, 1e-12);
  EXPECT_NEAR(placed.joints[1].position_m[1], 2, 1e-12);
  EXPECT_EQ(placed.joints[0].radius_m, 0.2);
}

TEST(RenderCpu, SaguaroPresetIsLitAndShaded) {
  Scene scene = default_scene_for(test::grow_preset("saguaro"), 160, 120);
  RenderOptions o;
  o.aovs = kAovId;
  RenderResult r = render_cpu(scene, o);
  ASSERT_EQ(r.image.beauty.size(), 160u * 120u * 4u);
  float lo = 1e9f, hi = -1e9f;
  size_t plant_pixels = 0;
  for (size_t p = 0; p < 160u * 120u; ++p) {
    float luminance = 0.2126f * r.image.beauty[p * 4] + 0.7152f * r.image.beauty[p * 4 + 1] +
                      0.0722f * r.image.beauty[p * 4 + 2];
    lo = std::min(lo, luminance);
    hi = std::max(hi, luminance);
    if (r.image.id[p * 3] == 0.0f) ++plant_pixels;
  }
  EXPECT_GT(hi - lo, 0.1f);
  EXPECT_GT(plant_pixels, 500u);  // the cactus fills a good part of the frame
  EXPECT_GT(r.shadow_rays, 0u);
}

}  // namespace
}  // namespace sylva
