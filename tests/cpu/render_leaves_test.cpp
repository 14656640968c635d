// render_leaves_test.cpp — leaves (skeleton.md "Leaves") in the CPU ray caster: a grammar's
// one known square leaf lands on the pixels its projection covers, with its material's
// colour, its id and its distance; it is two-sided and it shadows the ground.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>

#include "core/cpu/render_cpu.h"
#include "core/shading.h"
#include "tests/core/test_scenes.h"

namespace sylva {
namespace {

using test::one_leaf_pixel;
using test::one_leaf_scene;

glm::dvec3 beauty(const RenderResult& r, uint32_t x, uint32_t y) {
  const float* px = &r.image.beauty[(static_cast<size_t>(y) * r.image.width + x) * 4];
  return {px[0], px[1], px[2]};
}

// Every pixel whose centre ray meets the square (away from its edges) shows the leaf: id
// (plant 0, kAovLeafChain, leaf 0), the analytic distance, the leaf's material shaded
// under the sun; every pixel clear of the square and the stem shows no plant.
void expect_the_leaf_where_projected(const Scene& s) {
  RenderOptions o;
  o.aovs = kAovDepth | kAovId | kAovNormal;
  const RenderResult r = render_cpu(s, o);
  int leaf_pixels = 0, clear_pixels = 0;
  for (uint32_t y = 0; y < s.height; ++y)
    for (uint32_t x = 0; x < s.width; ++x) {
      const size_t p = static_cast<size_t>(y) * s.width + x;
      if (const auto leaf = one_leaf_pixel(s, x, y)) {
        ++leaf_pixels;
        EXPECT_EQ(r.image.id[p * 3 + 0], 0.0f) << x << "," << y;
        EXPECT_EQ(r.image.id[p * 3 + 1], kAovLeafChain) << x << "," << y;
        EXPECT_EQ(r.image.id[p * 3 + 2], 0.0f) << x << "," << y;
        EXPECT_NEAR(r.image.depth[p], leaf->distance, 1e-5 * leaf->distance) << x << "," << y;
        const glm::dvec3 c = beauty(r, x, y);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], leaf->radiance[k], 1e-5) << x << "," << y << " channel " << k;
        // The normal AOV faces the eye, whichever side is seen.
        const Ray ray = camera_ray(s, x + 0.5, y + 0.5);
        EXPECT_LT(ray.direction.z * r.image.normal[p * 3 + 2], 0) << x << "," << y;
      } else if (!one_leaf_pixel(s, x, y, -0.05)) {
        // Clear of the square by 5 cm: the stem (|x| < 0.02, y < 1) is the only other plant.
        const Ray ray = camera_ray(s, x + 0.5, y + 0.5);
        const double t = -ray.origin.z / ray.direction.z;
        const glm::dvec3 q = ray.origin + t * ray.direction;
        if (std::abs(q.x) < 0.1) continue;
        ++clear_pixels;
        EXPECT_NE(r.image.id[p * 3 + 1], kAovLeafChain) << x << "," << y;
      }
    }
  EXPECT_GT(leaf_pixels, 200);
  EXPECT_GT(clear_pixels, 2000);
}

TEST(RenderCpuLeaves, AGrammarsLeafCoversItsProjectionWithItsMaterialAndId) {
  // Seen from the front (+z), the sun behind the eye and above: the lit face.
  expect_the_leaf_where_projected(one_leaf_scene({-0.5, 1.5, 5}, {0.2, 0.5, 1}));
}

TEST(RenderCpuLeaves, ALeafIsTwoSided) {
  // From behind (−z), with the sun behind the eye too: the back is lit the same way.
  expect_the_leaf_where_projected(one_leaf_scene({-0.5, 1.5, -5}, {0.2, 0.5, -1}));
}

TEST(RenderCpuLeaves, ALeafSeenAgainstTheSunShowsTheSkyAmbientOnly) {
  // The sun behind the leaf: its near side gets no sunlight (a leaf is opaque).
  const Scene s = one_leaf_scene({-0.5, 1.5, 5}, {0.2, 0.5, -1});
  const RenderResult r = render_cpu(s, {});
  const glm::dvec2 c = test::pixel_of(s, {-0.5, 1.5, 0});
  const uint32_t x = static_cast<uint32_t>(c.x), y = static_cast<uint32_t>(c.y);
  const glm::dvec3 ambient = shading::sky_ambient(test::kOneLeafAlbedo, {0, 0, 1}, s.sky);
  const glm::dvec3 got = beauty(r, x, y);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], ambient[k], 1e-6);
}

TEST(RenderCpuLeaves, ALeafShadowsTheGroundWhereTheSunProjectsIt) {
  // The sun along (0, 1, 1): the square (z = 0, 1 <= y <= 2) throws its shadow onto the
  // ground at −2 <= z <= −1 (and −1 <= x <= 0); its centre (−0.5, 0, −1.5) is in shadow,
  // and the same ground without the leaf is lit.
  Scene s = one_leaf_scene({-0.5, 3, 4}, {0, 1, 1});
  s.sun.direction = glm::normalize(glm::dvec3(0, 1, 1));
  Scene bare = s;
  bare.plants[0].skeleton->leaves.clear();
  const RenderResult with = render_cpu(s, {}), without = render_cpu(bare, {});
  const glm::dvec3 ambient = shading::sky_ambient(s.ground.albedo, shading::kGroundNormal, s.sky);
  for (const glm::dvec3 ground : {glm::dvec3(-0.5, 0, -1.5), glm::dvec3(-0.3, 0, -1.2), glm::dvec3(-0.7, 0, -1.8)}) {
    const glm::dvec2 c = test::pixel_of(s, ground);
    const uint32_t x = static_cast<uint32_t>(c.x), y = static_cast<uint32_t>(c.y);
    const glm::dvec3 shadowed = beauty(with, x, y), lit = beauty(without, x, y);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(shadowed[k], ambient[k], 1e-6) << ground.x << "," << ground.z;
      EXPECT_GT(lit[k], 2 * ambient[k]) << ground.x << "," << ground.z;
    }
  }
  // Beside the shadow (and not behind the leaf from the eye) the leaf changes nothing.
  const glm::dvec2 c = test::pixel_of(s, {0.5, 0, -1.5});
  EXPECT_EQ(beauty(with, static_cast<uint32_t>(c.x), static_cast<uint32_t>(c.y)),
            beauty(without, static_cast<uint32_t>(c.x), static_cast<uint32_t>(c.y)));
}

TEST(RenderCpuLeaves, TheDefaultCameraFramesTheLeaves) {
  // skeleton_bounds holds the leaf (x down to −1, y up to 2), not only the stem.
  const SkeletonBounds b = skeleton_bounds(test::grown(test::kOneLeafGrammar));
  EXPECT_NEAR(b.lo.x, -1, 1e-12);
  EXPECT_NEAR(b.hi.y, 2, 1e-12);
}

}  // namespace
}  // namespace sylva
