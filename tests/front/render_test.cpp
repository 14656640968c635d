// render_test.cpp — the GL renderer composed with the CPU's sun photons
// (app/front/render.h): core/gl/ takes shadow cones from a cone source and never makes
// them; render_gl_scene hands it the CPU's, as the CLI renders.
#include <gtest/gtest.h>

#include <string>

#include "app/front/render.h"
#include "core/gl/gl_context.h"
#include "core/gl/render_gl.h"
#include "tests/support/gl_checks.h"
#include "tests/support/test_scenes.h"

namespace sylva {
namespace {

TEST(FrontRender, TheGlRendererRefusesAConeModeWithoutAConeSource) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::foggy_cylinder(FogMode::fast, 8, 32, 24);
  try {
    (void)render_gl(s, RenderOptions{});
    FAIL() << "a cone mode rendered without cones";
  } catch (const GlError& e) {
    EXPECT_NE(std::string(e.what()).find("need shadow cones"), std::string::npos) << e.what();
  }
  // Brute needs no cones: drawn by the GL backend alone.
  const Scene brute = test::foggy_cylinder(FogMode::brute, 8, 32, 24);
  const RenderResult r = render_gl(brute, RenderOptions{});
  EXPECT_FALSE(r.cancelled);
  EXPECT_EQ(r.image.beauty.size(), 32u * 24u * 4u);
  EXPECT_EQ(test::find_pass(r, "cone upload"), nullptr);
}

TEST(FrontRender, RenderGlSceneBringsTheCpusConesAndTheirPassesInOrder) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::foggy_cylinder(FogMode::fast, 8, 32, 24);
  RenderOptions options;
  options.fog.photons = 20000;
  const RenderResult r = render_gl_scene(s, options);
  ASSERT_FALSE(r.cancelled);
  ASSERT_EQ(r.image.beauty.size(), 32u * 24u * 4u);
  // The setup passes, then the cone source's (photons, cones), the upload, the frame.
  size_t skin = r.passes.size(), photons = r.passes.size(), upload = r.passes.size(), frame = r.passes.size();
  for (size_t i = 0; i < r.passes.size(); ++i) {
    const std::string& name = r.passes[i].name;
    if (name == "skin" && skin == r.passes.size()) skin = i;
    if (name == "photons") photons = i;
    if (name == "cone upload") upload = i;
    if (name == "frame (wall)") frame = i;
  }
  ASSERT_LT(frame, r.passes.size()) << "no frame pass";
  EXPECT_LT(skin, photons);
  EXPECT_LT(photons, upload);
  EXPECT_LT(upload, frame);
  EXPECT_NE(test::find_pass(r, "photons")->detail.find("20000 photons"), std::string::npos)
      << test::find_pass(r, "photons")->detail;
}

TEST(FrontRender, ACancelledConeSourceCancelsTheRender) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::foggy_cylinder(FogMode::medium, 8, 32, 24);
  bool asked = false;
  const GlConeSource never = [&](FogMode mode, std::vector<RenderPass>&) -> std::shared_ptr<const ConeSet> {
    asked = true;
    EXPECT_EQ(mode, FogMode::medium);
    return nullptr;
  };
  const RenderResult r = render_gl(s, RenderOptions{}, nullptr, never);
  EXPECT_TRUE(asked);
  EXPECT_TRUE(r.cancelled);
  EXPECT_TRUE(r.image.beauty.empty());
}

}  // namespace
}  // namespace sylva
