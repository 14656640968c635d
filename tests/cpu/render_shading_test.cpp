// render_shading_test.cpp — the CPU renderer's beauty where it is known in closed form
// (tests/support/shading_scenes.h works the values out by hand): a sunlit ground pixel, the
// ground under a sun below the horizon, a lit frustum at a known normal, the specular
// peak, a shadowed point, the ground under a sun on the horizon, the sky. The GL renderer
// is held to the same pixels by tests/gl/render_gl_shading_test.cpp.
#include "core/cpu/render_cpu.h"

#include <gtest/gtest.h>

#include <initializer_list>

#include "tests/support/shading_scenes.h"

namespace sylva {
namespace {

using test::KnownPixel;

// The beauty is float: the double values behind it to float rounding (and the ray
// casting's ~1e-15 in the normal).
void expect_pixels(const Scene& scene, std::initializer_list<KnownPixel> pixels) {
  const RenderResult r = render_cpu(scene, {});
  ASSERT_FALSE(r.cancelled);
  for (const KnownPixel& known : pixels) {
    const float* px = &r.image.beauty[(static_cast<size_t>(known.y) * scene.width + known.x) * 4];
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(px[k], known.beauty[k], 1e-7 * known.beauty[k] + 1e-9)
          << "pixel (" << known.x << ", " << known.y << ") channel " << k;
    EXPECT_EQ(px[3], 1.0f);
  }
}

TEST(RenderShading, ASunlitGroundPixelIsLambertPlusTheSky) {
  expect_pixels(test::sunlit_ground_scene(), {test::kSunlitGround});
}

TEST(RenderShading, TheGroundUnderASunBelowTheHorizonIsLitByTheSkyAlone) {
  expect_pixels(test::sun_below_horizon_scene(), {test::kGroundUnderSunBelowHorizon});
}

TEST(RenderShading, ALitCylinderSeenHeadOnAtItsCentre) {
  expect_pixels(test::lit_cylinder_scene(),
                {test::kLitCylinder, test::kGroundUnderHorizontalSun, test::kSkyCorner});
}

TEST(RenderShading, TheSpecularPeakWithTheSunBehindTheCamera) {
  expect_pixels(test::specular_peak_scene(), {test::kSpecularPeak});
}

TEST(RenderShading, TheScenesMaterialTableGivesAlbedoAndSpecularWeight) {
  expect_pixels(test::material_table_scene(), {test::kMaterialTablePeak});
}

TEST(RenderShading, AShadowedPointIsLitByTheSkyAlone) {
  expect_pixels(test::shadowed_cylinder_scene(), {test::kShadowedCylinder});
}

}  // namespace
}  // namespace sylva
