// render_gl_leaves_test.cpp — leaves (docs/leaves.md) in the GL renderer: the one known
// square leaf of test_scenes.h lands where its projection says with its material's colour,
// its id and its distance, from either side; it shadows the ground through the shadow
// map; and a leafy preset agrees with the CPU reference (render_gl_test.cpp's tolerances
// on hit/miss and depth; the beauty's, with the shadow map's resolution, below).
#include "core/gl/render_gl.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "tests/support/leaf_checks.h"
#include "tests/support/plants.h"
#include "tests/support/test_scenes.h"
#include "tests/support/gl_checks.h"

namespace sylva {
namespace {

RenderResult render_gl_with_aovs(const Scene& s) {
  RenderOptions o;
  o.aovs = kAovDepth | kAovId | kAovNormal | kAovUv;
  return gl_test::gl_render(s, o);
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

TEST(RenderGlLeaves, ADoubleSidedLeafShowsEachSidesMaterial) {
  SYLVA_REQUIRE_GL();
  test::expect_each_side_in_its_material([](const Scene& s) { return gl_test::gl_render(s, {}).image; }, kRadianceAbs);
}

TEST(RenderGlLeaves, ALeafShadowsTheGroundThroughTheShadowMap) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::leaf_shadow_scene();
  Scene bare = s;
  bare.plants[0].skeleton->leaves.clear();
  test::expect_the_leaf_shadow(s, gl_test::gl_render(s, {}).image, gl_test::gl_render(bare, {}).image, kRadianceAbs);
}

// The bush `scene` on both backends, within the geometry's and the beauty's tolerances
// (printed and named `name`); *gl and *cpu get the results.
void expect_bush_agrees(const Scene& scene, const std::string& name, RenderResult* gl, RenderResult* cpu) {
  RenderOptions options;
  options.aovs = kAovDepth | kAovId;
  *gl = gl_test::gl_render(scene, options);
  *cpu = gl_test::cpu_render(scene, options);
  const gl_test::Agreement a = gl_test::compare(gl->image, cpu->image);
  std::printf("[ agreement ] %s %ux%u: %s\n", name.c_str(), scene.width, scene.height, a.describe().c_str());
  // The geometry as the frusta's tolerances demand.
  EXPECT_GE(a.hit_miss, 0.995) << a.describe();
  EXPECT_LE(a.depth_median_rel, 1e-4) << a.describe();
  // The beauty to 1.5/255 instead of 1/255: 5 cm leaves throw shadows finer than the
  // 1024² shadow map's texels (about 4 mm here), which the CPU's shadow rays resolve, on
  // the ground and inside the crown (measured on llvmpipe: 1.10/255).
  EXPECT_LE(a.beauty_mad_srgb, 1.5 / 255) << a.describe() << "\n  images: "
                                          << gl_test::write_diff_images(name, gl->image, cpu->image);
}

// Pixels whose id names a leaf.
size_t leaf_pixels(const RenderImage& image) {
  size_t n = 0;
  for (size_t p = 0; 3 * p < image.id.size(); ++p) n += image.id[p * 3 + 1] == kAovLeafChain;
  return n;
}

TEST(RenderGlLeaves, TheLeafyBushMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  const Skeleton bush = test::grow_preset("abop_1_25_bush_leaves");
  ASSERT_GT(bush.leaves.size(), 1000u);
  RenderResult gl, cpu;
  expect_bush_agrees(gl_test::scene_around(bush), "bush_leaves", &gl, &cpu);
  const uint64_t hit_pixels = gl_test::compare(gl.image, cpu.image).hit_pixels;
  // Leaves are drawn and named so on both: the same pixels carry a leaf id.
  size_t gl_leaf = 0, both_leaf = 0;
  for (size_t p = 0; p < gl.image.depth.size(); ++p) {
    const bool g = gl.image.id[p * 3 + 1] == kAovLeafChain, c = cpu.image.id[p * 3 + 1] == kAovLeafChain;
    gl_leaf += g;
    both_leaf += g && c;
  }
  EXPECT_GT(gl_leaf, hit_pixels / 8);
  EXPECT_GE(both_leaf, gl_leaf * 95 / 100);
}

TEST(RenderGlLeaves, TheLeafyBushInTheBundledLeafImageMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  // The bush's leaves (material 3: ''' past the wood's 0) in the bundled elm leaf: its
  // albedo and its alpha cut-out (leaf_images.h), on both backends.
  const Skeleton bush = test::grow_preset("abop_1_25_bush_leaves");
  Scene scene = gl_test::scene_around(bush);
  SceneMaterial leaf;
  leaf.albedo_image = std::string(SYLVA_SOURCE_DIR) + "/presets/textures/elm_leaf.png";
  scene.materials[3] = leaf;
  RenderResult gl, cpu;
  expect_bush_agrees(scene, "bush_leaves_elm_leaf_image", &gl, &cpu);
  // The cut-out takes leaf pixels away (the image's leaf fills most of the bush's kite-shaped
  // leaf, so only a few here), the same on both.
  Scene plain = scene;
  plain.materials.erase(3);
  RenderOptions options;
  options.aovs = kAovId;
  const size_t cut = leaf_pixels(gl.image), whole = leaf_pixels(gl_test::gl_render(plain, options).image);
  std::printf("[ agreement ] leaf pixels: %zu GL cut out, %zu CPU cut out, %zu GL whole\n", cut, leaf_pixels(cpu.image),
              whole);
  EXPECT_GT(cut, 0u);
  EXPECT_LT(cut, whole);
  EXPECT_NEAR(static_cast<double>(cut), static_cast<double>(leaf_pixels(cpu.image)), 0.02 * cut);
}

TEST(RenderGlLeaves, MaterialsPastTheTableKeepTheDefaultLookNotTheLastEntrys) {
  SYLVA_REQUIRE_GL();
  // docs/materials.md: the table describes indices 0 to 15; a segment or leaf of index 20
  // has default_material_albedo's colour and specular 1 on both backends, whatever
  // entry 15 says (here: the elm leaf image with its cut-out, matte).
  Skeleton bush = test::grow_preset("abop_1_25_bush_leaves");
  for (Joint& j : bush.joints) j.material = 20;
  for (Leaf& l : bush.leaves) l.material = 20;
  Scene scene = gl_test::scene_around(bush);
  SceneMaterial last;
  last.albedo_image = std::string(SYLVA_SOURCE_DIR) + "/presets/textures/elm_leaf.png";
  last.specular = 0;
  scene.materials[15] = last;
  RenderResult gl, cpu;
  expect_bush_agrees(scene, "bush_material_20", &gl, &cpu);
  Scene untabled = scene;
  untabled.materials.clear();
  RenderOptions options;
  options.aovs = kAovId;
  EXPECT_EQ(leaf_pixels(gl.image), leaf_pixels(gl_test::gl_render(untabled, options).image)) << "no cut-out";
  EXPECT_EQ(gl.image.beauty, gl_test::gl_render(untabled, {}).image.beauty);
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
  test::expect_the_cut_out_shadow(s, gl_test::gl_render(s, {}).image, gl_test::gl_render(bare, {}).image, kRadianceAbs);
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
  const RenderImage with = gl_test::gl_render(s, {}).image, without = gl_test::gl_render(bare, {}).image;
  const glm::dvec2 c = test::pixel_of(s, {-0.5, 0, -1.5});
  const glm::dvec3 a = test::beauty_at(with, static_cast<uint32_t>(c.x), static_cast<uint32_t>(c.y));
  const glm::dvec3 b = test::beauty_at(without, static_cast<uint32_t>(c.x), static_cast<uint32_t>(c.y));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], kRadianceAbs);
}

}  // namespace
}  // namespace sylva
