// leaf_checks.h — what both renderers' leaf tests (tests/cpu/render_leaves_test.cpp,
// tests/gl/render_gl_leaves_test.cpp) expect of test_scenes.h's one_leaf_scene.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>

#include "core/geometry/leaf_mesh.h"
#include "core/scene/render_types.h"
#include "core/light/shading.h"
#include "tests/support/test_scenes.h"
#include "tests/support/test_textures.h"

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
// one_leaf_scene's leaf's texture coordinates at point p of its plane z = 0: the affine
// map leaf_uvs gives its corners, carried to p through the square's edges from vertex 0.
inline glm::dvec2 one_leaf_uv(const Scene& s, const glm::dvec3& p) {
  const Skeleton placed = place_plant(s.plants[0]);
  const auto& c = placed.leaves.at(0).vertices_m;
  const std::vector<glm::dvec2> corner_uv = leaf_uvs(c, glm::normalize(polygon_newell_normal(c)));
  const glm::dvec3 v0(c[0][0], c[0][1], c[0][2]), e1 = glm::dvec3(c[1][0], c[1][1], c[1][2]) - v0,
      e3 = glm::dvec3(c[3][0], c[3][1], c[3][2]) - v0;
  const glm::dvec3 q = p - v0;
  const double a = glm::dot(q, e1) / glm::dot(e1, e1), b = glm::dot(q, e3) / glm::dot(e3, e3);
  return corner_uv[0] + a * (corner_uv[1] - corner_uv[0]) + b * (corner_uv[3] - corner_uv[0]);
}

// Where pixel (x, y)'s centre ray meets the plane z = 0.
inline glm::dvec3 on_leaf_plane(const Scene& s, uint32_t x, uint32_t y) {
  const Ray ray = camera_ray(s, x + 0.5, y + 0.5);
  return ray.origin + (-ray.origin.z / ray.direction.z) * ray.direction;
}

inline void expect_the_leaf_where_projected(const Scene& s, const RenderResult& r, double depth_rel,
                                            double radiance_abs, double uv_abs) {
  // Its petiole (vertex 0, (0, 1, 0)) is at v = 0 and the opposite corner, the farthest, at v = 1.
  EXPECT_NEAR(one_leaf_uv(s, {0, 1, 0}).y, 0, 1e-12);
  EXPECT_NEAR(one_leaf_uv(s, {-1, 2, 0}).y, 1, 1e-12);
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
        const glm::dvec2 uv = one_leaf_uv(s, on_leaf_plane(s, x, y));
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

// A double-sided leaf with two materials (docs/leaves.md "Two colours"): one_leaf_scene's
// square (its Newell normal −z) given back material 9, a blue of its own, is seen from −z
// (its front) as the square of material 2 alone, and from +z (its back) as the square drawn
// in material 9 alone — every pixel within radiance_abs — and there unlike material 2's.
// `render` draws a scene (the beauty).
template <class Render>
void expect_each_side_in_its_material(Render render, double radiance_abs) {
  constexpr uint32_t kBack = 9;
  for (const double side : {-5.0, 5.0}) {
    Scene two = one_leaf_scene({-0.5, 1.5, side}, {0.2, 0.5, side / 5});
    SceneMaterial blue = two.materials.at(kOneLeafMaterial);
    blue.albedo_rgb = {0.1, 0.2, 0.8};
    two.materials[kBack] = blue;
    Scene one = two, other = two;
    two.plants[0].skeleton->leaves.at(0).back_material = kBack;
    other.plants[0].skeleton->leaves.at(0).material = kBack;  // the back's material on both sides
    const RenderImage a = render(two), b = render(side < 0 ? one : other), c = render(side < 0 ? other : one);
    int leaf_pixels = 0, differing = 0;
    for (uint32_t y = 0; y < two.height; ++y)
      for (uint32_t x = 0; x < two.width; ++x) {
        if (!one_leaf_pixel(two, x, y)) continue;
        ++leaf_pixels;
        const glm::dvec3 got = beauty_at(a, x, y), want = beauty_at(b, x, y), unlike = beauty_at(c, x, y);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], radiance_abs) << x << "," << y << " side " << side;
        if (std::abs(got[2] - unlike[2]) > 10 * radiance_abs) ++differing;
      }
    EXPECT_GT(leaf_pixels, 200);
    EXPECT_EQ(differing, leaf_pixels) << "side " << side << ": the other side's material would look different";
  }
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

// A 2 × 1 RGBA PNG for a cut-out: its left texel transparent, its right opaque, so the
// leaf is gone where u < 0.5 (leaf_images.h's bilinear alpha crosses 0.5 at u = 0.5).
inline void write_half_mask(const std::string& path) {
  write_rgba_png(path, 2, 1, [](uint32_t x, uint32_t) -> std::array<float, 4> {
    return {1, 1, 1, x == 0 ? 0.0f : 1.0f};
  });
}

// one_leaf_scene with its material's entry cut out by write_half_mask's image at `mask`.
inline Scene cut_out_leaf_scene(Scene s, const std::string& mask) {
  s.materials[kOneLeafMaterial].alpha_image = mask;
  return s;
}

// The cut-out leaf in `r` (id AOV): every leaf pixel (5 cm inside the square) with u more
// than 0.05 above 0.5 shows the leaf, every one 0.05 below shows no leaf; counts both.
inline void expect_the_cut_out(const Scene& s, const RenderResult& r) {
  int kept = 0, cut = 0;
  for (uint32_t y = 0; y < s.height; ++y)
    for (uint32_t x = 0; x < s.width; ++x) {
      if (!one_leaf_pixel(s, x, y)) continue;
      const double u = one_leaf_uv(s, on_leaf_plane(s, x, y)).x;
      const bool leaf = r.image.id[(static_cast<size_t>(y) * s.width + x) * 3 + 1] == kAovLeafChain;
      if (u > 0.55) {
        ++kept;
        EXPECT_TRUE(leaf) << x << "," << y << " u " << u;
      }
      if (u < 0.45) {
        ++cut;
        EXPECT_FALSE(leaf) << x << "," << y << " u " << u;
      }
    }
  EXPECT_GT(kept, 80);
  EXPECT_GT(cut, 80);
}

// leaf_shadow_scene cut out (cut_out_leaf_scene): the ground behind the kept half (leaf
// point (−0.8, 1.2, 0): u = 0.8) is in shadow, behind the cut half ((−0.2, 1.8, 0): u =
// 0.2) it is lit as without the leaf: shadow rays pass the transparent texels too.
inline void expect_the_cut_out_shadow(const Scene& s, const RenderImage& with, const RenderImage& without,
                                      double radiance_abs) {
  EXPECT_NEAR(one_leaf_uv(s, {-0.8, 1.2, 0}).x, 0.8, 1e-12);
  EXPECT_NEAR(one_leaf_uv(s, {-0.2, 1.8, 0}).x, 0.2, 1e-12);
  const glm::dvec3 ambient = shading::sky_ambient(s.ground.albedo, shading::kGroundNormal, s.sky);
  const glm::dvec2 behind_kept = pixel_of(s, {-0.8, 0, -1.2}), behind_cut = pixel_of(s, {-0.2, 0, -1.8});
  const glm::dvec3 shadowed = beauty_at(with, static_cast<uint32_t>(behind_kept.x), static_cast<uint32_t>(behind_kept.y));
  const glm::dvec3 lit = beauty_at(with, static_cast<uint32_t>(behind_cut.x), static_cast<uint32_t>(behind_cut.y));
  const glm::dvec3 bare = beauty_at(without, static_cast<uint32_t>(behind_cut.x), static_cast<uint32_t>(behind_cut.y));
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(shadowed[k], ambient[k], radiance_abs);
    EXPECT_NEAR(lit[k], bare[k], radiance_abs);
    EXPECT_GT(lit[k], 2 * ambient[k]);
  }
}

}  // namespace sylva::test
