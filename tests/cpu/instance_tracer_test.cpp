// instance_tracer_test.cpp — plants that share a skeleton, traced as instances
// (instance_tracer.h, docs/scatter.md "Instancing"), give the picture and AOVs of every
// plant skinned where it stands, with each plant's own id.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/cpu/render_cpu.h"
#include "tests/core/test_scenes.h"
#include "tests/core/test_textures.h"

namespace sylva {
namespace {

RenderResult render(const Scene& s, bool instance) {
  RenderOptions o;
  o.aovs = kAovDepth | kAovNormal | kAovUv | kAovId;
  o.geometry.instance = instance;
  return render_cpu(s, o);
}

TEST(InstanceTracer, AGroveOfSharedSkeletonsRendersAsEveryPlantSkinnedInTheWorld) {
  const Scene s = test::instanced_grove();
  const RenderResult flat = render(s, false), instanced = render(s, true);
  ASSERT_EQ(test::find_pass(flat, "instances"), nullptr);
  const RenderPass* pass = test::find_pass(instanced, "instances");
  ASSERT_NE(pass, nullptr);
  // Twelve plants share two skeletons; the crooked one is skinned in the world.
  EXPECT_NE(pass->detail.find("12 plants as instances of 2 skeletons"), std::string::npos) << pass->detail;
  EXPECT_EQ(instanced.frusta, flat.frusta);
  const RenderImage &a = flat.image, &b = instanced.image;
  // Ids: every pixel names the same plant, chain and segment (leaf).
  EXPECT_EQ(test::differing_pixels(a.id, b.id, 3, 0), 0u);
  EXPECT_EQ(test::differing_pixels(a.depth, b.depth, 1, 1e-9), 0u);
  EXPECT_EQ(test::differing_pixels(a.normal, b.normal, 3, 1e-9), 0u);
  // v_m to rounding; u is not compared: the skin measures it from each frustum's
  // axis_frame (skin.h), which does not turn with the plant, so a turned plant's u starts
  // at another angle around its stems when skinned in the world, and turns with it as an
  // instance — another seam, the same surface.
  EXPECT_EQ(test::differing_pixels(test::v_of_uv(a), test::v_of_uv(b), 1, 1e-9), 0u);
  EXPECT_EQ(test::differing_pixels(a.beauty, b.beauty, 4, 1e-6), 0u);
}

TEST(InstanceTracer, EachInstancedPlantReportsItsOwnIdInTheIdAov) {
  const Scene s = test::instanced_grove();
  const RenderResult r = render(s, true);
  const std::vector<int> seen = test::pixels_per_plant(r.image, s.plants.size());
  // The camera sees every plant of the grove, each at its own pixels.
  for (size_t p = 0; p < s.plants.size(); ++p) EXPECT_GT(seen[p], 0) << "plant " << p;
}

TEST(InstanceTracer, PlantsOfOneSkeletonAreSkinnedOnce) {
  Scene s = test::instanced_grove();
  for (ScenePlant& p : s.plants) p.skeleton = test::cylinder(0.12, 0, 1.6);
  std::vector<RenderPass> passes;
  const SceneGeometry g = build_instanced_geometry(s, {}, {}, &passes);
  EXPECT_EQ(g.instanced_skeletons, 1u);
  EXPECT_EQ(g.instanced_plants, 13u);
  EXPECT_TRUE(g.frusta.empty());  // nothing skinned in the world
  EXPECT_EQ(g.instance_frusta, 13u);
}

TEST(InstanceTracer, AReliefPlantIsSkinnedInTheWorldAndTheRestStayInstances) {
  // A relief's shell is as deep in world metres wherever the plant stands: no prototype
  // holds it, so plant 0 is skinned in the world; the picture is still the flat path's.
  const test::TempFolder dir;
  test::write_gray_float(dir.file("height.exr"), 16, 16, [](uint32_t x, uint32_t y) { return ((x / 4 + y / 4) % 2) * 1.0f; });
  Scene s = test::instanced_grove();
  s.plants[0].bark.height_texture = dir.file("height.exr");
  s.plants[0].bark.relief_depth_m = 0.02;
  std::vector<RenderPass> passes;
  EXPECT_EQ(build_instanced_geometry(s, {}, {}, &passes).instanced_plants, 11u);
  GeometryOptions no_relief;
  no_relief.relief = false;
  EXPECT_EQ(build_instanced_geometry(s, {}, no_relief).instanced_plants, 12u);
  const RenderResult flat = render(s, false), instanced = render(s, true);
  EXPECT_EQ(test::differing_pixels(flat.image.id, instanced.image.id, 3, 0), 0u);
  EXPECT_EQ(test::differing_pixels(flat.image.beauty, instanced.image.beauty, 4, 1e-6), 0u);
}

}  // namespace
}  // namespace sylva
