// render_joints_test.cpp — branch joints and elbows in the CPU ray caster (docs/joints.md):
// close-ups of a crown, an axis going on past a branch, a lateral and a 60° elbow
// (tests/support/joint_scenes.h) show no convex crease — no rim, lip or radius step where
// a chain meets its parent, no facet line at an elbow — in the depth field or the normal
// AOV; with the paper's plain skinning (SkinOptions::paper) the same close-ups do. Where an
// axis goes on into a child, u and v go on with it (no ring in the bark).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/cpu/render_cpu.h"
#include "core/geometry/crotch.h"
#include "core/scene/culling.h"
#include "tests/support/joint_scenes.h"
#include "tests/support/test_scenes.h"

namespace sylva {
namespace {

// Measured with the joints of docs/joints.md: up to 32° (depth) and 45° (normal AOV) where
// a collar meets its parent's surface next to the crotch, under 26° elsewhere; with the
// paper's skinning a flat cap's rim turns 75–90° and a 60° mitre 60°.
constexpr double kLargestSmoothTurnDeg = 50;

test::SurfaceDefects defects(const test::JointCloseUp& c, const SkinOptions& skin) {
  RenderOptions o;
  o.aovs = kAovDepth | kAovNormal;
  o.skin = skin;
  const RenderResult r = render_cpu(c.scene, o);
  return test::surface_defects(c.scene, r.image);
}

TEST(RenderCpuJoints, CloseUpsOfJointsAndElbowsShowNoConvexCrease) {
  for (const test::JointCloseUp& c : test::joint_close_ups()) {
    const test::SurfaceDefects d = defects(c, SkinOptions{});
    std::printf("[ joints ] %-12s %s\n", c.name.c_str(), d.describe().c_str());
    RecordProperty(c.name + "_convex_crease_deg", std::to_string(d.convex_crease_deg));
    EXPECT_GT(d.pairs, 1000u) << c.name;  // the close-up sees its joint
    EXPECT_LT(d.convex_crease_deg, kLargestSmoothTurnDeg) << c.name << ": " << d.describe();
    EXPECT_LT(d.convex_normal_jump_deg, kLargestSmoothTurnDeg) << c.name << ": " << d.describe();
  }
}

TEST(RenderCpuJoints, ThePapersPlainSkinningShowsTheRimTheStepAndTheFacet) {
  // The measure is not blind: the crown's flat trunk end, the thinner continuation's
  // step and the mitred elbow each turn the surface by more than the limit.
  for (const test::JointCloseUp& c : test::joint_close_ups()) {
    if (c.name == "fork") continue;  // a lateral from a side has only concave creases
    const test::SurfaceDefects d = defects(c, SkinOptions::paper());
    std::printf("[ joints ] %-12s paper: %s\n", c.name.c_str(), d.describe().c_str());
    EXPECT_GT(d.convex_crease_deg, kLargestSmoothTurnDeg) << c.name << ": " << d.describe();
  }
}

// docs/joints.md "Crotches": with the blend, where a lateral leaves its parent the
// concave crease of the two solids is filled — the surface turns by much less between
// pixels 4 apart — and nothing turns convex by more than the smooth limit. Measured
// (200×150, blend 0.8 r): fork 93.1° → 39.7°, y_fork 83.1° → 26.4°; the largest convex
// turn 19.0° / 42.0° (depth; the swollen parent's offset of its bounds' kinks,
// docs/joints.md) and at most 20.4° in the normal AOV. The crown's 42.0° was the crack at
// the trunk's mitred end (closed by the minor-axis fit, skin.h): its exact skin turns by
// 21.5° at most, and its blend by 28.1°, where two limbs' fillets cross (each blends with
// its own k; one field per joint would not) — held under the smooth limit.
TEST(RenderCpuJoints, TheBlendFillsTheCrotchesConcaveCrease) {
  SkinOptions blended;
  blended.blend_crotches = true;
  SkinOptions exact_skin;
  exact_skin.blend_crotches = false;
  for (const test::JointCloseUp& c : test::joint_close_ups()) {
    if (c.name != "fork" && c.name != "crown" && c.name != "y_fork") continue;
    const test::SurfaceDefects exact = defects(c, exact_skin);
    const test::SurfaceDefects blend = defects(c, blended);
    std::printf("[ joints ] %-12s concave crease %.1f° exact (at %d, %d), %.1f° blended (at %d, %d); convex %.1f° blended\n",
                c.name.c_str(), exact.concave_crease_deg, exact.concave_x, exact.concave_y, blend.concave_crease_deg,
                blend.concave_x, blend.concave_y, blend.convex_crease_deg);
    if (c.name == "crown") {
      EXPECT_LT(exact.concave_crease_deg, kLargestSmoothTurnDeg) << "the crack is closed";
      EXPECT_LT(blend.concave_crease_deg, kLargestSmoothTurnDeg) << c.name;
    } else {
      EXPECT_GT(exact.concave_crease_deg, 40) << c.name << ": the crease the blend is for";
      EXPECT_LT(blend.concave_crease_deg, 0.75 * exact.concave_crease_deg) << c.name;
    }
    EXPECT_LT(blend.convex_crease_deg, kLargestSmoothTurnDeg) << c.name << ": " << blend.describe();
    EXPECT_LT(blend.convex_normal_jump_deg, kLargestSmoothTurnDeg) << c.name << ": " << blend.describe();
  }
}

// docs/joints.md "Fillets by their size on screen": a view leaves out the fillets whose
// width k spans under kFilletMinPixels (they move no surface by more than half a pixel),
// and says so in the skin pass. The fork seen from 40 times as far: its one crotch is left
// out and the picture is the exact skin's, pixel for pixel; from its close-up it is
// blended. Without culling (a view-independent build) every crotch is kept.
TEST(RenderCpuJoints, AViewLeavesOutTheFilletsUnderTwoPixels) {
  const test::JointCloseUp fork = test::joint_close_ups().at(2);
  ASSERT_EQ(fork.name, "fork");
  Scene far = fork.scene;
  far.camera.eye = far.camera.target + 20.0 * (far.camera.eye - far.camera.target);
  const Skeleton& sk = *far.plants.at(0).skeleton;
  const std::vector<Crotch> crotches = find_crotches(sk, skin_skeleton(sk).frusta);
  ASSERT_EQ(crotches.size(), 1u);
  EXPECT_FALSE(crotch_seen(crotches[0], far.camera.eye, pixels_per_radian(far)));
  EXPECT_TRUE(crotch_seen(crotches[0], fork.scene.camera.eye, pixels_per_radian(fork.scene)));
  auto k_pixels = [&](const Scene& s) {
    return crotches[0].k * pixels_per_radian(s) / (glm::length(crotches[0].centre - s.camera.eye) - crotches[0].radius);
  };
  std::printf("[ joints ] fork's fillet k spans %.2f px in its close-up, %.2f px from 20 times as far\n",
              k_pixels(fork.scene), k_pixels(far));

  RenderOptions exact;
  exact.aovs = kAovDepth | kAovNormal;
  exact.skin.blend_crotches = false;
  RenderOptions blended = exact;
  blended.skin.blend_crotches = true;
  auto skin_detail = [](const RenderResult& r) {
    for (const RenderPass& p : r.passes)
      if (p.name == "skin") return p.detail;
    return std::string();
  };
  const RenderResult far_blended = render_cpu(far, blended), far_exact = render_cpu(far, exact);
  EXPECT_NE(skin_detail(far_blended).find("0 of 1 crotches blended (the rest under 2 px)"), std::string::npos)
      << skin_detail(far_blended);
  const size_t seen = std::count_if(far_exact.image.depth.begin(), far_exact.image.depth.end(),
                                    [](float z) { return std::isfinite(z); });
  EXPECT_GT(seen, 10u) << "the far view still sees the fork";
  EXPECT_EQ(far_blended.image.depth, far_exact.image.depth);
  EXPECT_EQ(far_blended.image.normal, far_exact.image.normal);
  EXPECT_EQ(far_blended.image.beauty, far_exact.image.beauty);

  const RenderResult near = render_cpu(fork.scene, blended);
  EXPECT_NE(skin_detail(near).find("1 of 1 crotches blended"), std::string::npos) << skin_detail(near);
  EXPECT_EQ(skin_detail(near).find("under 2 px"), std::string::npos) << skin_detail(near);
}

// The smooth skin (the default) blends its crotches; the paper's (--skin paper, the scene's
// key) does not: the fork's close-up, as a user renders it.
TEST(RenderCpuJoints, TheSmoothSkinBlendsItsCrotchesAndThePapersDoesNot) {
  const test::JointCloseUp fork = test::joint_close_ups().at(2);
  ASSERT_EQ(fork.name, "fork");
  RenderOptions o;
  o.aovs = kAovDepth;
  const RenderResult smooth = render_cpu(fork.scene, o);
  const RenderPass* skin = test::find_pass(smooth, "skin");
  ASSERT_NE(skin, nullptr);
  EXPECT_NE(skin->detail.find("1 of 1 crotches blended"), std::string::npos) << skin->detail;
  Scene paper = fork.scene;
  override_skin(paper, SkinStyle::paper);
  const RenderResult paper_render = render_cpu(paper, o);
  const RenderPass* paper_skin = test::find_pass(paper_render, "skin");
  ASSERT_NE(paper_skin, nullptr);
  EXPECT_EQ(paper_skin->detail.find("crotches blended"), std::string::npos) << paper_skin->detail;
  RenderOptions exact = o;
  exact.skin.blend_crotches = false;
  const RenderResult unblended = render_cpu(fork.scene, exact);
  const size_t filled = test::differing_pixels(smooth.image.depth, unblended.image.depth, 1, 1e-6);
  std::printf("[ joints ] fork: the default skin's fillet moves %zu pixels' depth\n", filled);
  EXPECT_GT(filled, 50u) << "the fillet fills the fork's crease";
}

// Issue 31 §1: no pixel of a crotch sees the inside of the other solid — with the exact
// joints and with the blend (the fillets lie outside the exact union). Measured: at most
// 0.12 µm (the depth AOV's float rounding) on every close-up.
TEST(RenderCpuJoints, NoPixelSeesInsideAnotherSolidWithOrWithoutTheBlend) {
  SkinOptions blended;
  blended.blend_crotches = true;
  SkinOptions exact;
  exact.blend_crotches = false;
  for (const test::JointCloseUp& c : test::joint_close_ups()) {
    for (const SkinOptions& skin : {exact, blended}) {
      RenderOptions o;
      o.aovs = kAovDepth;
      o.skin = skin;
      const test::InsideView v = test::deepest_inside_view(c.scene, render_cpu(c.scene, o).image, skin);
      std::printf("[ joints ] %-12s %s: deepest inside another solid %.2e m (pixel %d, %d) of %llu pixels\n",
                  c.name.c_str(), skin.blend_crotches ? "blend" : "exact", v.deepest_m, v.x, v.y,
                  static_cast<unsigned long long>(v.pixels));
      EXPECT_GT(v.pixels, 1000u) << c.name;
      // The crown's exact skin saw a collar 6.2 mm inside the trunk through a 0.71 mm crack
      // where the trunk's end met its tilted, faster-tapering continuation, before the
      // smooth skin fitted the continuation's base radius (skin.h fit_minor_axis).
      EXPECT_LT(v.deepest_m, 1e-4) << c.name;
    }
  }
}

// Issue 31 §1: the relief's ribs fade into the blend (crotch.h crotch_relief_fade; the
// saguaro's arms). The fork close-up with ribbed bark 4 cm deep: where the blend adds
// material every pixel sees the smooth blended surface, no rib anywhere in the ball stands
// higher than the fade allows, and away from the crotch the ribs keep their full height.
TEST(RenderCpuJoints, TheReliefsRibsFadeIntoTheBlendedCrotch) {
  test::TempFolder dir;
  const double depth = 0.04;
  const Scene scene = test::ribbed_fork(dir.file("ribs.exr"), depth);
  RenderOptions o;
  o.aovs = kAovDepth;
  o.skin.blend_crotches = true;
  const RenderResult r = render_cpu(scene, o);
  const test::ReliefAtCrotches m = test::relief_at_crotches(scene, r.image, o.skin, depth);
  std::printf("[ joints ] fork relief: %s\n", m.describe().c_str());
  EXPECT_GT(m.faded_pixels, 300u);
  EXPECT_LT(m.faded_height_m, 1e-4);
  EXPECT_LT(m.excess_m, 1e-4);
  EXPECT_GT(m.ribbed_pixels, 5000u);
  EXPECT_GT(m.ribbed_height_m, 0.9 * depth);  // the measure is not blind: full ribs elsewhere

  // The polygon baseline (GS+R): the displacement fades at the vertices (plant_mesh.h), so
  // it follows the fade only as finely as the mesh samples it — near a ball's rim, where
  // k(p) and the fade's width go to 0, a triangle spans the whole fade (measured: up to
  // 2.5 cm above the blend at levels 2–5). Its median in the fillet's region is the
  // fillet's facets' (6 mm at most without any relief); the ribs stand 4 cm without the fade.
  o.geometry.kind = GeometryKind::mesh;
  o.geometry.mesh_level = 3;
  const test::ReliefAtCrotches mesh = test::relief_at_crotches(scene, render_cpu(scene, o).image, o.skin, depth);
  std::printf("[ joints ] fork relief, mesh: %s\n", mesh.describe().c_str());
  EXPECT_GT(mesh.faded_pixels, 300u);
  EXPECT_LT(mesh.faded_median_m, 5e-3);
  EXPECT_GT(mesh.ribbed_height_m, 0.8 * depth);
}

// The polygon baseline (GeometryKind::mesh) carries the fillets as triangles
// (crotch_mesh.h): its crease is filled too, and it agrees with the marched fillet.
TEST(RenderCpuJoints, TheMeshPathCarriesTheFilletsTriangles) {
  for (const test::JointCloseUp& c : test::joint_close_ups()) {
    if (c.name != "fork") continue;
    RenderOptions o;
    o.aovs = kAovDepth | kAovNormal;
    o.geometry.kind = GeometryKind::mesh;
    o.geometry.mesh_level = 2;
    o.skin.blend_crotches = false;
    const RenderResult exact = render_cpu(c.scene, o);
    o.skin.blend_crotches = true;
    const RenderResult mesh = render_cpu(c.scene, o);
    o.geometry.kind = GeometryKind::frusta;
    const RenderResult marched = render_cpu(c.scene, o);
    const double before = test::surface_defects(c.scene, exact.image).concave_crease_deg;
    const double after = test::surface_defects(c.scene, mesh.image).concave_crease_deg;
    std::printf("[ joints ] %-12s mesh concave crease %.1f° exact, %.1f° with the fillets\n", c.name.c_str(), before,
                after);
    EXPECT_LT(after, 0.8 * before);
    size_t near = 0, hits = 0;
    for (size_t i = 0; i < marched.image.depth.size(); ++i) {
      if (!std::isfinite(marched.image.depth[i])) continue;
      ++hits;
      near += std::abs(mesh.image.depth[i] - marched.image.depth[i]) < 0.01f;  // the facets' chord error
    }
    EXPECT_GT(near, 0.98 * hits) << "the mesh (fillet and GS 2 frusta) lies on the marched one: measured 98.9 %";
  }
}

TEST(RenderCpuJoints, TheScenesPaperSkinIsThePapersSkinningPlantByPlant) {
  // docs/spec/scene.md "Skin": a plant's `skin` reaches the renderer with the default
  // options: its depth is exactly that of SkinOptions::paper(); a smooth plant beside it
  // keeps the joints.
  for (const test::JointCloseUp& c : test::joint_close_ups()) {
    Scene paper = c.scene;
    override_skin(paper, SkinStyle::paper);
    RenderOptions o;
    o.aovs = kAovDepth;
    o.spp = 1;
    const RenderResult by_key = render_cpu(paper, o);
    o.skin = SkinOptions::paper();
    const RenderResult by_options = render_cpu(c.scene, o);
    EXPECT_EQ(by_key.image.depth, by_options.image.depth) << c.name;
    if (c.name == "fork") continue;  // its paper and smooth silhouettes may agree
    o.skin = SkinOptions{};
    EXPECT_NE(render_cpu(c.scene, o).image.depth, by_key.image.depth) << c.name << ": the key changed nothing";
  }
}

// docs/joints.md "Continuations": where a chain's axis goes on into a child, the bark goes
// on with it — v (arc length) and u carried across, so no ring where the texture breaks.
// Measured (200×150): at most 1.6 local steps in v and 1.3 in u with the smooth skin; the
// paper's skin starts the child at v = 0 (hundreds of steps) with its own u.
constexpr double kLargestUvJumpInSteps = 3;

TEST(RenderCpuJoints, BarkGoesOnAcrossEveryContinuationWithoutARing) {
  for (const test::JointCloseUp& c : test::joint_close_ups()) {
    if (c.name != "continuation" && c.name != "y_fork") continue;
    RenderOptions o;
    o.aovs = kAovUv | kAovId;
    o.spp = 1;
    const test::UvContinuity smooth = test::uv_continuity(c.scene, render_cpu(c.scene, o).image);
    std::printf("[ joints ] %-12s uv: %s\n", c.name.c_str(), smooth.describe().c_str());
    EXPECT_GT(smooth.pairs, 20u) << c.name << ": the close-up sees the boundary";
    EXPECT_LT(smooth.worst_v, kLargestUvJumpInSteps) << c.name << ": " << smooth.describe();
    EXPECT_LT(smooth.worst_u, kLargestUvJumpInSteps) << c.name << ": " << smooth.describe();
    o.skin = SkinOptions::paper();  // the measure is not blind: the paper's ring
    const test::UvContinuity paper = test::uv_continuity(c.scene, render_cpu(c.scene, o).image);
    std::printf("[ joints ] %-12s uv, paper: %s\n", c.name.c_str(), paper.describe().c_str());
    EXPECT_GT(paper.worst_v, 10 * kLargestUvJumpInSteps) << c.name << ": " << paper.describe();
  }
}

}  // namespace
}  // namespace sylva
