// render_leaves_test.cpp — leaves (docs/spec/skeleton.md "Leaves", docs/leaves.md) in the CPU ray
// caster: a grammar's one known square leaf lands on the pixels its projection covers,
// with its material's colour, its id and its distance; it is two-sided, opaque, and it
// shadows the ground.
#include <gtest/gtest.h>

#include "core/cpu/render_cpu.h"
#include "core/light/shading.h"
#include "tests/support/leaf_checks.h"
#include "tests/support/test_scenes.h"

namespace sylva {
namespace {

RenderResult render_with_aovs(const Scene& s) {
  RenderOptions o;
  o.aovs = kAovDepth | kAovId | kAovNormal | kAovUv;
  return render_cpu(s, o);
}

TEST(RenderCpuLeaves, AGrammarsLeafCoversItsProjectionWithItsMaterialAndId) {
  // Seen from the front (+z), the sun behind the eye and above: the lit face.
  const Scene s = test::one_leaf_scene({-0.5, 1.5, 5}, {0.2, 0.5, 1});
  test::expect_the_leaf_where_projected(s, render_with_aovs(s), 1e-5, 1e-5, 1e-6);
}

TEST(RenderCpuLeaves, ALeafIsTwoSided) {
  // From behind (−z), with the sun behind the eye too: the back is lit the same way.
  const Scene s = test::one_leaf_scene({-0.5, 1.5, -5}, {0.2, 0.5, -1});
  test::expect_the_leaf_where_projected(s, render_with_aovs(s), 1e-5, 1e-5, 1e-6);
}

TEST(RenderCpuLeaves, ADoubleSidedLeafShowsEachSidesMaterial) {
  test::expect_each_side_in_its_material([](const Scene& s) { return render_cpu(s, {}).image; }, 1e-6);
}

TEST(RenderCpuLeaves, ALeafSeenAgainstTheSunShowsTheSkyAmbientOnly) {
  // The sun behind the leaf: its near side gets no sunlight (a leaf is opaque).
  const Scene s = test::one_leaf_scene({-0.5, 1.5, 5}, {0.2, 0.5, -1});
  const RenderResult r = render_cpu(s, {});
  const glm::dvec2 c = test::pixel_of(s, {-0.5, 1.5, 0});
  const glm::dvec3 ambient = shading::sky_ambient(test::kOneLeafAlbedo, {0, 0, 1}, s.sky);
  const glm::dvec3 got = test::beauty_at(r.image, static_cast<uint32_t>(c.x), static_cast<uint32_t>(c.y));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], ambient[k], 1e-6);
}

TEST(RenderCpuLeaves, ALeafShadowsTheGroundWhereTheSunProjectsIt) {
  const Scene s = test::leaf_shadow_scene();
  Scene bare = s;
  bare.plants[0].skeleton->leaves.clear();
  test::expect_the_leaf_shadow(s, render_cpu(s, {}).image, render_cpu(bare, {}).image, 1e-6);
}

TEST(RenderCpuLeaves, TheDefaultCameraFramesTheLeaves) {
  // skeleton_bounds holds the leaf (x down to −1, y up to 2), not only the stem.
  const SkeletonBounds b = skeleton_bounds(test::grown(test::kOneLeafGrammar));
  EXPECT_NEAR(b.lo.x, -1, 1e-12);
  EXPECT_NEAR(b.hi.y, 2, 1e-12);
}

TEST(RenderCpuLeaves, ACutOutsTransparentTexelsLetCameraAndShadowRaysThrough) {
  test::TempFolder dir;
  test::write_half_mask(dir.file("mask.png"));
  const Scene front = test::cut_out_leaf_scene(test::one_leaf_scene({-0.5, 1.5, 5}, {0.2, 0.5, 1}), dir.file("mask.png"));
  test::expect_the_cut_out(front, render_with_aovs(front));
  const Scene s = test::cut_out_leaf_scene(test::leaf_shadow_scene(), dir.file("mask.png"));
  Scene bare = s;
  bare.plants[0].skeleton->leaves.clear();
  test::expect_the_cut_out_shadow(s, render_cpu(s, {}).image, render_cpu(bare, {}).image, 1e-6);
}

TEST(RenderCpuLeaves, AOneSidedLeafIsThereFromItsFrontOnlyForEveryRay) {
  // The square's Newell normal is −z (its vertices turn clockwise seen from +z).
  Scene from_front = test::one_leaf_scene({-0.5, 1.5, -5}, {0.2, 0.5, -1});
  from_front.materials[test::kOneLeafMaterial].two_sided = false;
  test::expect_the_leaf_where_projected(from_front, render_with_aovs(from_front), 1e-5, 1e-5, 1e-6);
  Scene from_back = test::one_leaf_scene({-0.5, 1.5, 5}, {0.2, 0.5, 1});
  from_back.materials[test::kOneLeafMaterial].two_sided = false;
  const RenderResult back = render_with_aovs(from_back);
  for (size_t p = 0; p < back.image.depth.size(); ++p) ASSERT_NE(back.image.id[p * 3 + 1], kAovLeafChain) << p;
  // The sun on its back (leaf_shadow_scene's sun from +z): no shadow on the ground.
  Scene s = test::leaf_shadow_scene();
  s.materials[test::kOneLeafMaterial].two_sided = false;
  Scene bare = s;
  bare.plants[0].skeleton->leaves.clear();
  const RenderImage with = render_cpu(s, {}).image, without = render_cpu(bare, {}).image;
  const glm::dvec2 c = test::pixel_of(s, {-0.5, 0, -1.5});
  const glm::dvec3 a = test::beauty_at(with, static_cast<uint32_t>(c.x), static_cast<uint32_t>(c.y));
  const glm::dvec3 b = test::beauty_at(without, static_cast<uint32_t>(c.x), static_cast<uint32_t>(c.y));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 1e-6);
}

}  // namespace
}  // namespace sylva
