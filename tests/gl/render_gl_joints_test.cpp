// render_gl_joints_test.cpp — branch joints and elbows (docs/joints.md) in the GL renderer:
// it draws the same skin as the CPU reference, so the close-ups of tests/core/
// joint_scenes.h agree with the CPU's (render_gl_test.cpp's hit/miss and depth
// tolerances) and show no convex crease either (render_joints_test.cpp's limit).
#include "core/gl/render_gl.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tests/support/joint_scenes.h"
#include "tests/support/gl_checks.h"
#include "tests/support/test_scenes.h"

namespace sylva {
namespace {

constexpr double kLargestSmoothTurnDeg = 50;  // as tests/cpu/render_joints_test.cpp

TEST(RenderGlJoints, CloseUpsOfJointsAndElbowsMatchTheCpuAndShowNoConvexCrease) {
  SYLVA_REQUIRE_GL();
  RenderOptions o;
  o.aovs = kAovDepth | kAovNormal;
  for (const test::JointCloseUp& c : test::joint_close_ups()) {
    const RenderResult gl = gl_test::gl_render(c.scene, o), cpu = gl_test::cpu_render(c.scene, o);
    const gl_test::Agreement a = gl_test::compare(gl.image, cpu.image);
    const test::SurfaceDefects d = test::surface_defects(c.scene, gl.image);
    std::printf("[ joints ] %-12s GL vs CPU %s; GL %s\n", c.name.c_str(), a.describe().c_str(),
                d.describe().c_str());
    EXPECT_GE(a.hit_miss, 0.995) << c.name << ": " << a.describe();
    EXPECT_LE(a.depth_median_rel, 1e-4) << c.name << ": " << a.describe();
    EXPECT_GT(d.pairs, 1000u) << c.name;
    EXPECT_LT(d.convex_crease_deg, kLargestSmoothTurnDeg) << c.name << ": " << d.describe();
    EXPECT_LT(d.convex_normal_jump_deg, kLargestSmoothTurnDeg) << c.name << ": " << d.describe();
  }
}

TEST(RenderGlJoints, TheBlendedCrotchesFilletMeshMatchesTheCpusMarchedFillet) {
  // docs/joints.md "Crotches": GL draws each fillet as crotch_mesh.h's triangles after the
  // frusta, the CPU marches the field: the close-ups agree as the frusta do (the facets
  // are within a few millimetres of the field), and GL's crease is filled, a little less
  // than the CPU's (the facets chamfer the fillet: measured fork 93.1° → 49.7°, y_fork
  // 83.1° → 31.9°, against the CPU's 39.7°, 26.4°). The crown's exact skin turns by 21.5° at
  // most since the minor-axis fit closed its crack; its fillets cross (31.7° on GL, 28.1°
  // on the CPU), held under the smooth limit (tests/cpu/render_joints_test.cpp).
  SYLVA_REQUIRE_GL();
  RenderOptions o;
  o.aovs = kAovDepth | kAovNormal;
  o.skin.blend_crotches = false;  // the exact frusta
  RenderOptions blended = o;
  blended.skin.blend_crotches = true;
  for (const test::JointCloseUp& c : test::joint_close_ups()) {
    if (c.name != "fork" && c.name != "crown" && c.name != "y_fork") continue;
    const RenderResult gl = gl_test::gl_render(c.scene, blended), cpu = gl_test::cpu_render(c.scene, blended);
    const gl_test::Agreement a = gl_test::compare(gl.image, cpu.image);
    const test::SurfaceDefects d = test::surface_defects(c.scene, gl.image);
    const test::SurfaceDefects exact = test::surface_defects(c.scene, gl_test::gl_render(c.scene, o).image);
    std::printf("[ joints ] %-12s blended GL vs CPU %s; GL concave crease %.1f° (%.1f° exact); %s\n", c.name.c_str(),
                a.describe().c_str(), d.concave_crease_deg, exact.concave_crease_deg, d.describe().c_str());
    EXPECT_GE(a.hit_miss, 0.99) << c.name << ": " << a.describe();
    EXPECT_LE(a.depth_median_rel, 1e-3) << c.name << ": " << a.describe();
    if (c.name == "crown") {
      EXPECT_LT(d.concave_crease_deg, kLargestSmoothTurnDeg) << c.name;
    } else {
      EXPECT_LT(d.concave_crease_deg, 0.8 * exact.concave_crease_deg) << c.name;
    }
    EXPECT_LT(d.convex_crease_deg, kLargestSmoothTurnDeg) << c.name << ": " << d.describe();
    EXPECT_LT(d.convex_normal_jump_deg, kLargestSmoothTurnDeg) << c.name << ": " << d.describe();
  }
}

// The CPU's AViewLeavesOutTheFilletsUnderTwoPixels on GL (gl_mesh.cpp): a renderer made for
// the scene's camera meshes only the fillets at least kFilletMinPixels wide there — the
// fork from 20 times its close-up's distance draws as its exact skin, pixel for pixel, and
// meshes no fillet; with culling off (the studio's renderer, whose camera moves) and in
// the close-up the fillet is meshed.
TEST(RenderGlJoints, AViewLeavesOutTheFilletsUnderTwoPixels) {
  SYLVA_REQUIRE_GL();
  const test::JointCloseUp fork = test::joint_close_ups().at(2);
  ASSERT_EQ(fork.name, "fork");
  Scene far = fork.scene;
  far.camera.eye = far.camera.target + 20.0 * (far.camera.eye - far.camera.target);
  RenderOptions exact;
  exact.aovs = kAovDepth | kAovNormal;
  exact.skin.blend_crotches = false;
  RenderOptions blended = exact;
  blended.skin.blend_crotches = true;
  auto fillet_pass = [](const RenderResult& r) { return test::find_pass(r, "fillets tessellate"); };
  const RenderResult far_blended = gl_test::gl_render(far, blended), far_exact = gl_test::gl_render(far, exact);
  EXPECT_EQ(fillet_pass(far_blended), nullptr) << "a fillet under 2 px was meshed";
  const size_t seen = std::count_if(far_exact.image.depth.begin(), far_exact.image.depth.end(),
                                    [](float z) { return std::isfinite(z); });
  EXPECT_GT(seen, 10u) << "the far view still sees the fork";
  EXPECT_EQ(far_blended.image.depth, far_exact.image.depth);
  EXPECT_EQ(far_blended.image.beauty, far_exact.image.beauty);

  RenderOptions every = blended;
  every.geometry.cull = false;
  const RenderResult far_every = gl_test::gl_render(far, every), near_blended = gl_test::gl_render(fork.scene, blended);
  const RenderPass* all = fillet_pass(far_every);
  ASSERT_NE(all, nullptr) << "culling off keeps every fillet";
  EXPECT_EQ(all->detail.find("under 2 px"), std::string::npos) << all->detail;
  const RenderPass* near = fillet_pass(near_blended);
  ASSERT_NE(near, nullptr) << "the close-up meshes its fillet";
  EXPECT_EQ(near->detail.find("under 2 px"), std::string::npos) << near->detail;
}

TEST(RenderGlJoints, NoPixelSeesInsideAnotherSolidWithOrWithoutTheBlend) {
  // tests/cpu/render_joints_test.cpp's measure on GL's depth AOV, with the exact joints and
  // with the fillets drawn as triangles (their vertices outside the exact union, their
  // chords too): nothing seen lies inside a solid by more than the depth's float rounding
  // (measured at most 4.7e-7 m).
  SYLVA_REQUIRE_GL();
  SkinOptions blended;
  blended.blend_crotches = true;
  SkinOptions exact;
  exact.blend_crotches = false;
  for (const SkinOptions& skin : {exact, blended}) {
    RenderOptions o;
    o.aovs = kAovDepth;
    o.spp = 1;
    o.skin = skin;
    for (const test::JointCloseUp& c : test::joint_close_ups()) {
      const test::InsideView v = test::deepest_inside_view(c.scene, gl_test::gl_render(c.scene, o).image, o.skin);
      std::printf("[ joints ] %-12s GL %s: deepest inside another solid %.2e m (pixel %d, %d)\n", c.name.c_str(),
                  skin.blend_crotches ? "blend" : "exact", v.deepest_m, v.x, v.y);
      EXPECT_GT(v.pixels, 1000u) << c.name;
      EXPECT_LT(v.deepest_m, 1e-5) << c.name;
    }
  }
}

TEST(RenderGlJoints, TheReliefsRibsFadeIntoTheBlendedCrotchAsOnTheCpu) {
  // tests/cpu/render_joints_test.cpp's measure on GL (crotch.glsl's fade in the relief
  // marcher): no rib stands out of the fillet's region. GL's fillet is a mesh whose facets
  // lie within millimetres of the CPU's marched field, so the region's height above the
  // field is held to 1 cm here (the unfaded ribs stand 4 cm); the frusta's relief agrees
  // with the CPU's as the relief close-ups do.
  SYLVA_REQUIRE_GL();
  test::TempFolder dir;
  const double depth = 0.04;
  const Scene scene = test::ribbed_fork(dir.file("ribs.exr"), depth);
  RenderOptions o;
  o.aovs = kAovDepth;
  o.spp = 1;
  o.skin.blend_crotches = true;
  const RenderResult gl = gl_test::gl_render(scene, o), cpu = gl_test::cpu_render(scene, o);
  const gl_test::Agreement a = gl_test::compare(gl.image, cpu.image);
  const test::ReliefAtCrotches m = test::relief_at_crotches(scene, gl.image, o.skin, depth);
  std::printf("[ joints ] fork relief GL vs CPU %s; GL %s\n", a.describe().c_str(), m.describe().c_str());
  EXPECT_GE(a.hit_miss, 0.99) << a.describe();
  EXPECT_LE(a.depth_median_rel, 1e-3) << a.describe();
  EXPECT_GT(m.faded_pixels, 300u);
  EXPECT_LT(m.faded_height_m, 1e-2);
  EXPECT_LT(m.excess_m, 1e-2);
  EXPECT_GT(m.ribbed_height_m, 0.9 * depth);
}

TEST(RenderGlJoints, ThePapersSkinByTheScenesKeyMatchesTheCpu) {
  // The `skin` key reaches the GL skinning too (render_gl.cpp skin_one): the paper's
  // mitred close-ups agree with the CPU's, and differ from the smooth ones.
  SYLVA_REQUIRE_GL();
  RenderOptions o;
  o.aovs = kAovDepth;
  for (const test::JointCloseUp& c : test::joint_close_ups()) {
    if (c.name == "fork") continue;
    Scene paper = c.scene;
    override_skin(paper, SkinStyle::paper);
    const RenderResult gl = gl_test::gl_render(paper, o), cpu = gl_test::cpu_render(paper, o);
    const gl_test::Agreement a = gl_test::compare(gl.image, cpu.image);
    EXPECT_GE(a.hit_miss, 0.995) << c.name << ": " << a.describe();
    EXPECT_LE(a.depth_median_rel, 1e-4) << c.name << ": " << a.describe();
    const gl_test::Agreement smooth = gl_test::compare(gl.image, gl_test::gl_render(c.scene, o).image);
    EXPECT_TRUE(smooth.hit_miss < 1 || smooth.depth_max_rel > 1e-3)
        << c.name << ": paper and smooth drew the same: " << smooth.describe();
  }
}

TEST(RenderGlJoints, BarkGoesOnAcrossEveryContinuationWithoutARing) {
  // tests/cpu/render_joints_test.cpp's measure and limit on GL's uv and id AOVs: GL draws
  // the same mitred continuations with the same u and v.
  SYLVA_REQUIRE_GL();
  RenderOptions o;
  o.aovs = kAovUv | kAovId;
  o.spp = 1;
  for (const test::JointCloseUp& c : test::joint_close_ups()) {
    if (c.name != "continuation" && c.name != "y_fork") continue;
    const test::UvContinuity d = test::uv_continuity(c.scene, gl_test::gl_render(c.scene, o).image);
    std::printf("[ joints ] %-12s GL uv: %s\n", c.name.c_str(), d.describe().c_str());
    EXPECT_GT(d.pairs, 20u) << c.name;
    EXPECT_LT(d.worst_v, 3) << c.name << ": " << d.describe();
    EXPECT_LT(d.worst_u, 3) << c.name << ": " << d.describe();
  }
}

}  // namespace
}  // namespace sylva
