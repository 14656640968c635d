// render_gl_instancing_test.cpp — plants that share a skeleton drawn as instances
// (docs/scatter.md "Instancing"; frusta_common.glsl GpuInstance): the skeleton's records
// uploaded once, one instanced draw per skeleton, and the same picture, AOVs and ids as
// every plant skinned in the world, in the G-buffer and the shadow map alike.
#include "core/gl/render_gl.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "tests/core/test_scenes.h"
#include "tests/gl/gl_test_util.h"

namespace sylva {
namespace {

RenderResult render(const Scene& s, bool instance) {
  RenderOptions o;
  o.aovs = kAovDepth | kAovNormal | kAovUv | kAovId;
  o.geometry.instance = instance;
  return render_gl(s, o);
}

TEST(RenderGlInstancing, AGroveOfSharedSkeletonsDrawsAsEveryPlantSkinnedInTheWorld) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::instanced_grove();
  const RenderResult flat = render(s, false), instanced = render(s, true);
  const RenderPass* skin = test::find_pass(instanced, "skin");
  ASSERT_NE(skin, nullptr);
  EXPECT_NE(skin->detail.find("12 plants as instances of 2 skeletons"), std::string::npos) << skin->detail;
  EXPECT_EQ(test::find_pass(flat, "skin")->detail.find("instances"), std::string::npos);
  EXPECT_EQ(instanced.frusta, flat.frusta);
  const RenderImage &a = flat.image, &b = instanced.image;
  const size_t pixels = static_cast<size_t>(s.width) * s.height;
  std::printf("[ instancing ] ids %zu, depth %zu, beauty %zu of %zu pixels differ\n", test::differing_pixels(a.id, b.id, 3, 0),
              test::differing_pixels(a.depth, b.depth, 1, 1e-5), test::differing_pixels(a.beauty, b.beauty, 4, 1e-4), pixels);
  // Float in another frame: a silhouette pixel may flip (none did on llvmpipe; allow 0.5 %),
  // depth and normals to float's rounding, the beauty to the shading's.
  EXPECT_LE(test::differing_pixels(a.id, b.id, 3, 0), pixels / 200);
  EXPECT_LE(test::differing_pixels(a.depth, b.depth, 1, 1e-5), pixels / 200);
  EXPECT_LE(test::differing_pixels(a.normal, b.normal, 3, 1e-4), pixels / 200);
  // v_m only: u starts at another angle around a turned plant's stems (the skin's
  // axis_frame does not turn with it; tests/cpu/instance_tracer_test.cpp says more).
  EXPECT_LE(test::differing_pixels(test::v_of_uv(a), test::v_of_uv(b), 1, 1e-4), pixels / 200);
  EXPECT_LE(test::differing_pixels(a.beauty, b.beauty, 4, 1e-4), pixels / 200);
}

TEST(RenderGlInstancing, EachInstancedPlantReportsItsOwnIdInTheIdAov) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::instanced_grove();
  const RenderResult r = render(s, true);
  const std::vector<int> seen = test::pixels_per_plant(r.image, s.plants.size());
  for (size_t p = 0; p < s.plants.size(); ++p) EXPECT_GT(seen[p], 0) << "plant " << p;
}

TEST(RenderGlInstancing, ASharedSkeletonIsUploadedOnce) {
  SYLVA_REQUIRE_GL();
  Scene s = test::instanced_grove();
  for (ScenePlant& p : s.plants) p.skeleton = test::cylinder(0.12, 0, 1.6);
  RenderOptions o;
  o.geometry.instance = false;
  const GlRenderer flat(s, o);
  o.geometry.instance = true;
  const GlRenderer instanced(s, o);
  EXPECT_EQ(flat.frusta(), 13u);
  EXPECT_EQ(instanced.frusta(), 13u);
  // One 64 B record and 16 B of ids, then 48 B per plant's transform, against 13 of each.
  EXPECT_EQ(flat.uploaded_bytes(), 13u * 80);
  EXPECT_EQ(instanced.uploaded_bytes(), 80u + 13 * 48);
}

TEST(RenderGlInstancing, AnInstancedGroveMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  Scene s = test::instanced_grove(192, 144);
  RenderOptions o;
  o.aovs = kAovDepth | kAovId;
  gl_test::expect_matches_cpu("instanced_grove", s, o);
}

}  // namespace
}  // namespace sylva
