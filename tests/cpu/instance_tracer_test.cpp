// instance_tracer_test.cpp — plants that share a skeleton, traced as instances
// (instance_tracer.h, docs/scatter.md "Instancing"), give the picture and AOVs of every
// plant skinned where it stands, with each plant's own id.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <string>

#include "core/cpu/photons.h"
#include "core/cpu/render_cpu.h"
#include "tests/support/test_scenes.h"
#include "tests/support/test_textures.h"

namespace sylva {
namespace {

// The frusta through instances against the plants skinned in the world. Without the
// crotches' fillets: in a view, instances share the fillets any of them needs and a plant
// skinned in the world keeps its own (render_cpu.cpp; under 2 px, they move no surface by
// half a pixel), so the two pictures differ there by design; the fillets through instances
// are tested below with every fillet kept.
RenderResult render(const Scene& s, bool instance) {
  RenderOptions o;
  o.skin.blend_crotches = false;
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

// ---- Sun photons through instances (photons.h) ----------------------------------------

// The grove (its forks carry a leaf each) in the fog tests' fog (test_scenes.h), `mode`
// reading shadow cones, 8 steps, 40,000 photons, 48 × 36.
Scene foggy_grove(FogMode mode) {
  Scene s = test::instanced_grove(48, 36);
  s.fog = test::foggy_cylinder(mode, 8).fog;
  s.fog->photons = 40000;
  return s;
}

// The photons through instances against the same plants skinned in the world (with
// `skin`); on the grove the float positions come out bit-identical where `exact` (in
// general they may differ by the rounding of the transforms: a fillet's march runs in the
// prototype's frame, so its hits differ by that rounding).
void expect_instanced_photons_as_flat(const SkinOptions& skin, bool exact) {
  const Scene s = foggy_grove(FogMode::medium);
  GeometryOptions no_cull;
  no_cull.cull = false;
  const SceneGeometry flat = build_scene_geometry(s, skin, no_cull);
  const SceneGeometry instanced = build_instanced_geometry(s, skin, no_cull);
  if (skin.blend_crotches) {
    ASSERT_NE(flat.crotches, nullptr);
    ASSERT_TRUE(std::any_of(instanced.prototypes.begin(), instanced.prototypes.end(),
                            [](const SceneGeometry::Prototype& p) { return p.crotches != nullptr; }));
  }
  ASSERT_EQ(instanced.instanced_plants, 12u);
  ASSERT_FALSE(instanced.instances.empty());
  SunPhotonOptions o;
  o.photons = 60000;
  o.seed = 3;
  const SunPhotonTracer a(flat, s.sun), b(instanced, s.sun);
  EXPECT_NEAR(b.emitter().sphere_radius_m, a.emitter().sphere_radius_m, 1e-12);
  EXPECT_LT(glm::length(b.emitter().centre - a.emitter().centre), 1e-12);
  const SunPhotons pa = a.trace(o), pb = b.trace(o);
  ASSERT_EQ(pa.traced, pb.traced);
  ASSERT_GT(pa.vectors.vectors.size(), 1000u);
  ASSERT_EQ(pa.vectors.vectors.size(), pb.vectors.vectors.size());
  // Instance + frustum: the tracer's frustum space names every vector's plant, which is
  // the flat path's.
  ASSERT_EQ(b.plant_of_frustum().size(), flat.frusta.size());
  for (size_t i = 0; i < pa.vectors.vectors.size(); ++i) {
    const ShadowVector &va = pa.vectors.vectors[i], &vb = pb.vectors.vectors[i];
    ASSERT_EQ(flat.plant_of_frustum[va.frustum], b.plant_of_frustum()[vb.frustum]) << i;
    if (exact) {
      EXPECT_EQ(va.position, vb.position) << i;
    } else {
      EXPECT_LT(glm::length(glm::dvec3(va.position - vb.position)), 1e-5) << i;
    }
    EXPECT_EQ(va.direction, vb.direction) << i;
  }
  // The exact shadow test agrees too.
  for (int k = 0; k < 200; ++k) {
    const glm::dvec3 p(-6 + 0.06 * k, 0.05, -4 + 0.04 * k);
    EXPECT_EQ(a.toward_sun_blocked(p), b.toward_sun_blocked(p)) << k;
  }
}

TEST(InstanceTracer, SunPhotonsThroughInstancesLeaveTheVectorsOfEveryPlantSkinnedInTheWorld) {
  SkinOptions unblended;  // the frusta alone
  unblended.blend_crotches = false;
  expect_instanced_photons_as_flat(unblended, true);
}

TEST(InstanceTracer, SunPhotonsThroughInstancedFilletsLeaveTheVectorsOfEveryPlantSkinnedInTheWorld) {
  SkinOptions blended;
  blended.blend_crotches = true;
  expect_instanced_photons_as_flat(blended, false);
}

TEST(InstanceTracer, AFogRenderWithShadowConesIsTheSameThroughInstances) {
  for (FogMode mode : {FogMode::medium, FogMode::fast}) {
    const Scene s = foggy_grove(mode);
    RenderOptions o;
    o.aovs = kAovId | kAovFog;
    o.threads = 2;
    o.skin.blend_crotches = false;  // as render() above
    o.fog.cone_params = std::array<uint32_t, 4>{81, 8, 16, 16};
    o.geometry.instance = false;
    const RenderResult flat = render_cpu(s, o);
    o.geometry.instance = true;
    const RenderResult instanced = render_cpu(s, o);
    ASSERT_NE(test::find_pass(instanced, "instances"), nullptr) << fog_mode_name(mode);
    const RenderPass *ca = test::find_pass(flat, "cones"), *cb = test::find_pass(instanced, "cones");
    ASSERT_NE(ca, nullptr);
    ASSERT_NE(cb, nullptr);
    EXPECT_EQ(ca->detail, cb->detail) << fog_mode_name(mode);  // as many cones from as many vectors
    EXPECT_EQ(test::find_pass(flat, "photons")->detail, test::find_pass(instanced, "photons")->detail);
    EXPECT_EQ(test::differing_pixels(flat.image.id, instanced.image.id, 3, 0), 0u) << fog_mode_name(mode);
    EXPECT_EQ(test::differing_pixels(flat.image.fog, instanced.image.fog, 4, 0), 0u) << fog_mode_name(mode);
    EXPECT_EQ(test::differing_pixels(flat.image.beauty, instanced.image.beauty, 4, 0), 0u) << fog_mode_name(mode);
  }
}

}  // namespace
}  // namespace sylva
