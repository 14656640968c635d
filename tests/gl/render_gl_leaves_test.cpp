// render_gl_leaves_test.cpp — leaves (docs/leaves.md) in the GL renderer: the one known
// square leaf of test_scenes.h lands where its projection says with its material's colour,
// its id and its distance, from either side; it shadows the ground through the shadow
// map; and a leafy preset agrees with the CPU reference (render_gl_test.cpp's tolerances
// on hit/miss and depth; the beauty's, with the shadow map's resolution, below).
#include "core/gl/render_gl.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "tests/core/leaf_checks.h"
#include "tests/core/test_scenes.h"
#include "tests/gl/gl_test_util.h"

namespace sylva {
namespace {

RenderResult render_gl_with_aovs(const Scene& s) {
  RenderOptions o;
  o.aovs = kAovDepth | kAovId | kAovNormal | kAovUv;
  return render_gl(s, o);
}

// GL's float G-buffer and shading: depth to 1e-4, radiance to 1e-3 (linear).
constexpr double kDepthRel = 1e-4, kRadianceAbs = 1e-3;

TEST(RenderGlLeaves, AGrammarsLeafCoversItsProjectionWithItsMaterialAndId) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::one_leaf_scene({-0.5, 1.5, 5}, {0.2, 0.5, 1});
  test::expect_the_leaf_where_projected(s, render_gl_with_aovs(s), kDepthRel, kRadianceAbs, 2e-3);
}

TEST(RenderGlLeaves, ALeafIsTwoSided) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::one_leaf_scene({-0.5, 1.5, -5}, {0.2, 0.5, -1});
  test::expect_the_leaf_where_projected(s, render_gl_with_aovs(s), kDepthRel, kRadianceAbs, 2e-3);
}

TEST(RenderGlLeaves, ALeafShadowsTheGroundThroughTheShadowMap) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::leaf_shadow_scene();
  Scene bare = s;
  bare.plants[0].skeleton->leaves.clear();
  test::expect_the_leaf_shadow(s, render_gl(s, {}).image, render_gl(bare, {}).image, kRadianceAbs);
}

TEST(RenderGlLeaves, TheLeafyBushMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  const Skeleton bush = gl_test::grow_preset("abop_1_25_bush_leaves");
  ASSERT_GT(bush.leaves.size(), 1000u);
  const Scene scene = gl_test::scene_around(bush);
  RenderOptions options;
  options.aovs = kAovDepth | kAovId;
  const RenderResult gl = render_gl(scene, options), cpu = render_cpu(scene, options);
  const gl_test::Agreement a = gl_test::compare(gl.image, cpu.image);
  std::printf("[ agreement ] bush_leaves 256x192: %s\n", a.describe().c_str());
  // The geometry as the frusta's tolerances demand.
  EXPECT_GE(a.hit_miss, 0.995) << a.describe();
  EXPECT_LE(a.depth_median_rel, 1e-4) << a.describe();
  // The beauty to 1.5/255 instead of 1/255: 5 cm leaves throw shadows finer than the
  // 1024² shadow map's texels (about 4 mm here), which the CPU's shadow rays resolve, on
  // the ground and inside the crown (measured on llvmpipe: 1.10/255).
  EXPECT_LE(a.beauty_mad_srgb, 1.5 / 255) << a.describe() << "\n  images: "
                                          << gl_test::write_diff_images("bush_leaves", gl.image, cpu.image);
  // Leaves are drawn and named so on both: the same pixels carry a leaf id.
  size_t gl_leaf = 0, both_leaf = 0;
  for (size_t p = 0; p < gl.image.depth.size(); ++p) {
    const bool g = gl.image.id[p * 3 + 1] == kAovLeafChain, c = cpu.image.id[p * 3 + 1] == kAovLeafChain;
    gl_leaf += g;
    both_leaf += g && c;
  }
  EXPECT_GT(gl_leaf, a.hit_pixels / 8);
  EXPECT_GE(both_leaf, gl_leaf * 95 / 100);
}

TEST(RenderGlLeaves, ACutOutsTransparentTexelsLetCameraAndShadowRaysThrough) {
  SYLVA_REQUIRE_GL();
  test::TempFolder dir;
  test::write_half_mask(dir.file("mask.png"));
  const Scene front = test::cut_out_leaf_scene(test::one_leaf_scene({-0.5, 1.5, 5}, {0.2, 0.5, 1}), dir.file("mask.png"));
  test::expect_the_cut_out(front, render_gl_with_aovs(front));
  const Scene s = test::cut_out_leaf_scene(test::leaf_shadow_scene(), dir.file("mask.png"));
  Scene bare = s;
  bare.plants[0].skeleton->leaves.clear();
  test::expect_the_cut_out_shadow(s, render_gl(s, {}).image, render_gl(bare, {}).image, kRadianceAbs);
}

TEST(RenderGlLeaves, AOneSidedLeafIsThereFromItsFrontOnlyForEveryRay) {
  SYLVA_REQUIRE_GL();
  // The square's Newell normal is −z (its vertices turn clockwise seen from +z).
  Scene from_front = test::one_leaf_scene({-0.5, 1.5, -5}, {0.2, 0.5, -1});
  from_front.materials[test::kOneLeafMaterial].two_sided = false;
  test::expect_the_leaf_where_projected(from_front, render_gl_with_aovs(from_front), kDepthRel, kRadianceAbs, 2e-3);
  Scene from_back = test::one_leaf_scene({-0.5, 1.5, 5}, {0.2, 0.5, 1});
  from_back.materials[test::kOneLeafMaterial].two_sided = false;
  const RenderResult back = render_gl_with_aovs(from_back);
  for (size_t p = 0; p < back.image.depth.size(); ++p) ASSERT_NE(back.image.id[p * 3 + 1], kAovLeafChain) << p;
  // The sun on its back (leaf_shadow_scene's sun from +z): no shadow on the ground.
  Scene s = test::leaf_shadow_scene();
  s.materials[test::kOneLeafMaterial].two_sided = false;
  Scene bare = s;
  bare.plants[0].skeleton->leaves.clear();
  const RenderImage with = render_gl(s, {}).image, without = render_gl(bare, {}).image;
  const glm::dvec2 c = test::pixel_of(s, {-0.5, 0, -1.5});
  const glm::dvec3 a = test::beauty_at(with, static_cast<uint32_t>(c.x), static_cast<uint32_t>(c.y));
  const glm::dvec3 b = test::beauty_at(without, static_cast<uint32_t>(c.x), static_cast<uint32_t>(c.y));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], kRadianceAbs);
}

}  // namespace
}  // namespace sylva
