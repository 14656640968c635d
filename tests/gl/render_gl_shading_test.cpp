// render_gl_shading_test.cpp — the GL renderer's beauty where it is known in closed form
// (tests/support/shading_scenes.h works the values out by hand), the same pixels the CPU
// renderer is held to by tests/cpu/render_shading_test.cpp: checked against the numbers
// themselves, not against the CPU, so an error in the model both shared would fail.
#include "core/gl/render_gl.h"

#include <gtest/gtest.h>

#include <initializer_list>

#include "tests/support/shading_scenes.h"
#include "tests/support/gl_checks.h"

namespace sylva {
namespace {

using test::KnownPixel;

// Float shading of float ray casting: the normal to ~1e-6 rad, which (n·h)^40 turns into
// ~1e-5 of the specular term; sums of a few float products otherwise.
void expect_pixels(const Scene& scene, std::initializer_list<KnownPixel> pixels) {
  const RenderResult r = gl_test::gl_render(scene, {});
  for (const KnownPixel& known : pixels) {
    const float* px = &r.image.beauty[(static_cast<size_t>(known.y) * scene.width + known.x) * 4];
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(px[k], known.beauty[k], 2e-6 * known.beauty[k] + 1e-7)
          << "pixel (" << known.x << ", " << known.y << ") channel " << k;
    EXPECT_EQ(px[3], 1.0f);
  }
}

TEST(RenderGlShading, ASunlitGroundPixelIsLambertPlusTheSky) {
  SYLVA_REQUIRE_GL();
  expect_pixels(test::sunlit_ground_scene(), {test::kSunlitGround});
}

TEST(RenderGlShading, TheGroundUnderASunBelowTheHorizonIsLitByTheSkyAlone) {
  SYLVA_REQUIRE_GL();
  expect_pixels(test::sun_below_horizon_scene(), {test::kGroundUnderSunBelowHorizon});
}

TEST(RenderGlShading, ALitCylinderSeenHeadOnAtItsCentre) {
  SYLVA_REQUIRE_GL();
  expect_pixels(test::lit_cylinder_scene(),
                {test::kLitCylinder, test::kGroundUnderHorizontalSun, test::kSkyCorner});
}

TEST(RenderGlShading, TheSpecularPeakWithTheSunBehindTheCamera) {
  SYLVA_REQUIRE_GL();
  expect_pixels(test::specular_peak_scene(), {test::kSpecularPeak});
}

TEST(RenderGlShading, TheScenesMaterialTableGivesAlbedoAndSpecularWeight) {
  SYLVA_REQUIRE_GL();
  expect_pixels(test::material_table_scene(), {test::kMaterialTablePeak});
}

TEST(RenderGlShading, AShadowedPointIsLitByTheSkyAlone) {
  SYLVA_REQUIRE_GL();
  expect_pixels(test::shadowed_cylinder_scene(), {test::kShadowedCylinder});
}

}  // namespace
}  // namespace sylva
