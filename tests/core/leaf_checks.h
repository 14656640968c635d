// leaf_checks.h — what both renderers' leaf tests (tests/cpu/render_leaves_test.cpp,
// tests/gl/render_gl_leaves_test.cpp) expect of test_scenes.h's one_leaf_scene.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>

#include "core/leaf_mesh.h"
#include "core/render_types.h"
#include "core/shading.h"
#include "tests/core/test_scenes.h"

namespace sylva::test {

inline glm::dvec3 beauty_at(const RenderImage& image, uint32_t x, uint32_t y) {
  const float* px = &image.beauty[(static_cast<size_t>(y) * image.width + x) * 4];
  return {px[0], px[1], px[2]};
}

// Every pixel whose centre ray meets the square (5 cm inside its edges) shows the leaf:
// id (plant 0, kAovLeafChain, leaf 0), the analytic distance (within depth_rel), the
// leaf's material shaded under the sun (within radiance_abs), a normal facing the eye;
// every pixel 5 cm clear of the square and of the stem shows no leaf; the uv AOV is the
// leaf's texture coordinates at the hit (within uv_abs): the affine map leaf_uvs gives its
// corners, carried to the hit through the square's edges. `r` rendered with the depth,
// normal, id and uv AOVs.
inline void expect_the_leaf_where_projected(const Scene& s, const RenderResult& r, double depth_rel,
                                            double radiance_abs, double uv_abs) {
  const Skeleton placed = place_plant(s.plants[0]);
  const auto& c = placed.leaves.at(0).vertices_m;
  const std::vector<glm::dvec2> corner_uv =
      leaf_uvs(c, glm::normalize(polygon_newell_normal(c)));
  const glm::dvec3 v0(c[0][0], c[0][1], c[0][2]), e1 = glm::dvec3(c[1][0], c[1][1], c[1][2]) - v0,
      e3 = glm::dvec3(c[3][0], c[3][1], c[3][2]) - v0;  // the square's two edges from vertex 0
  // Its petiole (vertex 0) is at v = 0 and the opposite corner, the farthest, at v = 1.
  EXPECT_NEAR(corner_uv[0].y, 0, 1e-12);
  EXPECT_NEAR(corner_uv[2].y, 1, 1e-12);
  int leaf_pixels = 0, clear_pixels = 0;
  for (uint32_t y = 0; y < s.height; ++y)
    for (uint32_t x = 0; x < s.width; ++x) {
      const size_t p = static_cast<size_t>(y) * s.width + x;
      const Ray ray = camera_ray(s, x + 0.5, y + 0.5);
      if (const auto leaf = one_leaf_pixel(s, x, y)) {
        ++leaf_pixels;
        EXPECT_EQ(r.image.id[p * 3 + 0], 0.0f) << x << "," << y;
        EXPECT_EQ(r.image.id[p * 3 + 1], kAovLeafChain) << x << "," << y;
        EXPECT_EQ(r.image.id[p * 3 + 2], 0.0f) << x << "," << y;
        EXPECT_NEAR(r.image.depth[p], leaf->distance, depth_rel * leaf->distance) << x << "," << y;
        const glm::dvec3 c = beauty_at(r.image, x, y);
        for (int k = 0; k < 3; ++k)
          EXPECT_NEAR(c[k], leaf->radiance[k], radiance_abs) << x << "," << y << " channel " << k;
        EXPECT_LT(ray.direction.z * r.image.normal[p * 3 + 2], 0) << x << "," << y;
        const glm::dvec3 q = ray.origin + (-ray.origin.z / ray.direction.z) * ray.direction - v0;
        const double a = glm::dot(q, e1) / glm::dot(e1, e1), b = glm::dot(q, e3) / glm::dot(e3, e3);
        const glm::dvec2 uv = corner_uv[0] + a * (corner_uv[1] - corner_uv[0]) + b * (corner_uv[3] - corner_uv[0]);
        EXPECT_NEAR(r.image.uv[p * 2 + 0], uv.x, uv_abs) << x << "," << y;
        EXPECT_NEAR(r.image.uv[p * 2 + 1], uv.y, uv_abs) << x << "," << y;
      } else if (!one_leaf_pixel(s, x, y, -0.05)) {
        const double t = -ray.origin.z / ray.direction.z;
        if (std::abs((ray.origin + t * ray.direction).x) < 0.1) continue;  // the stem's column
        ++clear_pixels;
        EXPECT_NE(r.image.id[p * 3 + 1], kAovLeafChain) << x << "," << y;
      }
    }
  EXPECT_GT(leaf_pixels, 200);
  EXPECT_GT(clear_pixels, 2000);
}

// leaf_shadow_scene (test_scenes.h): points well inside the leaf's shadow show the ground's sky
// ambient alone (within radiance_abs) where the same scene without the leaf is lit; a
// point beside it is the same with and without the leaf.
inline void expect_the_leaf_shadow(const Scene& s, const RenderImage& with, const RenderImage& without,
                                   double radiance_abs) {
  const glm::dvec3 ambient = shading::sky_ambient(s.ground.albedo, shading::kGroundNormal, s.sky);
  for (const glm::dvec3 ground : {glm::dvec3(-0.5, 0, -1.5), glm::dvec3(-0.3, 0, -1.2), glm::dvec3(-0.7, 0, -1.8)}) {
    const glm::dvec2 c = pixel_of(s, ground);
    const uint32_t x = static_cast<uint32_t>(c.x), y = static_cast<uint32_t>(c.y);
    const glm::dvec3 shadowed = beauty_at(with, x, y), lit = beauty_at(without, x, y);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(shadowed[k], ambient[k], radiance_abs) << ground.x << "," << ground.z;
      EXPECT_GT(lit[k], 2 * ambient[k]) << ground.x << "," << ground.z;
    }
  }
  // Beside the shadow (and not behind the leaf from the eye) the leaf changes nothing.
  const glm::dvec2 c = pixel_of(s, {0.5, 0, -1.5});
  const uint32_t x = static_cast<uint32_t>(c.x), y = static_cast<uint32_t>(c.y);
  const glm::dvec3 a = beauty_at(with, x, y), b = beauty_at(without, x, y);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], radiance_abs);
}

}  // namespace sylva::test
