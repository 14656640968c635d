// shading_test.cpp — the shading model of core/light/shading.h against values worked out by hand
// (in the comments), term by term and at the points the renderers meet most: a sunlit
// ground point, a lit frustum at a known normal, the specular peak, a shadowed point, a
// grazing sun and a sun below the horizon.
#include "core/light/shading.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <limits>

namespace sylva {
namespace {

using namespace shading;

const glm::dvec3 kSky{0.25, 0.3, 0.4};         // L_sky
const glm::dvec3 kSun{3, 3, 2.8};              // E_sun, W/m² at normal incidence
const glm::dvec3 kGround{0.35, 0.3, 0.25};     // ρ of the ground
const glm::dvec3 kWood{0.30, 0.20, 0.12};      // ρ of a plant (material 0)

void expect_near(const glm::dvec3& actual, const glm::dvec3& expected, double tolerance) {
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(actual[k], expected[k], tolerance) << "channel " << k;
}

TEST(Shading, TheConstantsAreADielectricsReflectanceAndExponent40) {
  EXPECT_EQ(kSpecular, 0.04);
  EXPECT_EQ(kShininess, 40.0);
  EXPECT_EQ(kGroundNormal, glm::dvec3(0, 1, 0));
}

TEST(Shading, SkyAmbientIsTheSkysShareOfTheHemisphereAroundTheNormal) {
  // Facing up: all of the sky, ρ·L_sky = (0.35·0.25, 0.3·0.3, 0.25·0.4).
  expect_near(sky_ambient(kGround, {0, 1, 0}, kSky), {0.0875, 0.09, 0.1}, 1e-15);
  // Vertical: half of it, (0.30·0.25, 0.20·0.3, 0.12·0.4)/2 = (0.0375, 0.03, 0.024).
  expect_near(sky_ambient(kWood, {1, 0, 0}, kSky), {0.0375, 0.03, 0.024}, 1e-15);
  // Facing down: none; 60° from the zenith (n_y = 1/2): three quarters.
  expect_near(sky_ambient(kWood, {0, -1, 0}, kSky), {0, 0, 0}, 0);
  expect_near(sky_ambient(kWood, {std::sqrt(0.75), 0.5, 0}, kSky), {0.05625, 0.045, 0.036}, 1e-15);
}

TEST(Shading, SunCosineIsNDotLWhereBothNormalsFaceTheSun) {
  const glm::dvec3 l(0.6, 0.8, 0);
  EXPECT_NEAR(sun_cosine({0, 1, 0}, {0, 1, 0}, l), 0.8, 1e-15);
  EXPECT_NEAR(sun_cosine({1, 0, 0}, {0, 1, 0}, l), 0.6, 1e-15);
  // The shading normal faces the sun, the geometry does not (a bent normal at a
  // silhouette): no sunlight. Nor where the shading normal turns away.
  EXPECT_EQ(sun_cosine({1, 0, 0}, {0, -1, 0}, l), 0.0);
  EXPECT_EQ(sun_cosine({0, -1, 0}, {0, 1, 0}, l), 0.0);
}

TEST(Shading, BlinnPhongPeaksAt0point24OverPiWhereNEqualsH) {
  // Normal incidence, l = v = n: h = n, k_s·(s + 8)/(8π) = 0.04·48/(8π) = 0.24/π = 0.0763944.
  const glm::dvec3 n(0, 0, 1);
  EXPECT_NEAR(blinn_phong(n, n, n), 0.0763943727, 1e-10);
  // Any l, v mirrored about n also has h = n: l = (0.6, 0, 0.8), v = (−0.6, 0, 0.8).
  EXPECT_NEAR(blinn_phong(n, {0.6, 0, 0.8}, {-0.6, 0, 0.8}), 0.0763943727, 1e-10);
  // l = (0.6, 0, 0.8), v = n: h = (0.6, 0, 1.8)/√3.6, n·h = 3/√10, (n·h)^40 = 0.9^20 =
  // 0.121577, f_s = 0.0763944·0.121577 = 0.00928777.
  EXPECT_NEAR(blinn_phong(n, {0.6, 0, 0.8}, n), 0.0092877723, 1e-10);
  // h below the tangent plane (l and v both below it, which the renderers never pass): 0,
  // not a negative number to the 40th power.
  EXPECT_EQ(blinn_phong(n, {0.8, 0, -0.6}, {0.6, 0, -0.8}), 0.0);
}

TEST(Shading, TheBrdfIsLambertPlusTheLobeOnPlantsAndLambertOnTheGround) {
  const glm::dvec3 n(0, 0, 1), l(0.6, 0, 0.8);
  // ρ/π = (0.3, 0.2, 0.12)/π = (0.0954930, 0.0636620, 0.0381972).
  expect_near(surface_brdf(kWood, n, l, n, false), {0.0954929659, 0.0636619772, 0.0381971863}, 1e-10);
  // + f_s = 0.00928777 on every channel.
  expect_near(surface_brdf(kWood, n, l, n, true), {0.1047807381, 0.0729497495, 0.0474849586}, 1e-10);
}

TEST(Shading, ReflectedSunlightIsBrdfTimesIrradianceTimesCosineTimesVisibility) {
  // (0.1, 0.2, 0.3) · (3, 3, 2.8) · (0.5 · 0.25).
  expect_near(sun_reflected({0.1, 0.2, 0.3}, kSun, 0.5, 0.25), {0.0375, 0.075, 0.105}, 1e-15);
}

TEST(Shading, ASunlitGroundPointIsLambertPlusTheWholeSky) {
  // Sun at 36.87° from the zenith, l = (0.6, 0.8, 0), cos θ = 0.8, V = 1:
  //   ρ·L_sky + ρ/π·E·0.8 = (0.0875 + 0.84/π, 0.09 + 0.72/π, 0.1 + 0.56/π)
  //                      = (0.354880, 0.319183, 0.278254).
  const glm::dvec3 l(0.6, 0.8, 0), view(0, 1, 0);
  const double cos_sun = sun_cosine(kGroundNormal, kGroundNormal, l);
  expect_near(surface_radiance(kGround, kGroundNormal, l, view, false, kSky, kSun, cos_sun, 1),
              {0.3548803044, 0.3191831181, 0.2782535363}, 1e-10);
  // Half the sun's disc hidden (V = 1/2): half the sunlight,
  //   (0.0875 + 0.42/π, 0.09 + 0.36/π, 0.1 + 0.28/π) = (0.221190, 0.204592, 0.189127).
  expect_near(surface_radiance(kGround, kGroundNormal, l, view, false, kSky, kSun, cos_sun, 0.5),
              {0.2211901522, 0.2045915590, 0.1891267681}, 1e-10);
}

TEST(Shading, ALitFrustumAtAKnownNormal) {
  // n = n_g = v = (0, 0, 1) (a cylinder seen head-on), l = (0.6, 0, 0.8): n_y = 0, half the
  // sky, (0.0375, 0.03, 0.024); brdf (0.1047807, 0.0729497, 0.0474850) · E · 0.8:
  //   R 0.0375 + 0.1047807·2.4 = 0.288974, G 0.03 + 0.0729497·2.4 = 0.205079,
  //   B 0.024 + 0.0474850·2.24 = 0.130366.
  const glm::dvec3 n(0, 0, 1), l(0.6, 0, 0.8);
  const double cos_sun = sun_cosine(n, n, l);
  EXPECT_NEAR(cos_sun, 0.8, 1e-15);
  expect_near(surface_radiance(kWood, n, l, n, true, kSky, kSun, cos_sun, 1),
              {0.2889737715, 0.2050793988, 0.1303663073}, 1e-10);
}

TEST(Shading, TheSpecularPeakAtNEqualsH) {
  // l = v = n: cos θ = 1, brdf ρ/π + 0.24/π = (0.54, 0.44, 0.36)/π:
  //   (0.0375 + 1.62/π, 0.03 + 1.32/π, 0.024 + 1.008/π) = (0.553162, 0.450169, 0.344856).
  const glm::dvec3 n(0, 0, 1);
  expect_near(surface_radiance(kWood, n, n, n, true, kSky, kSun, sun_cosine(n, n, n), 1),
              {0.5531620156, 0.4501690498, 0.3448563653}, 1e-10);
}

TEST(Shading, AShadowedPointIsLitByTheSkyAlone) {
  // V = 0: exactly the ambient term, ρ·L_sky/2 for a vertical face.
  const glm::dvec3 n(0, 0, 1), l(0.6, 0, 0.8);
  const glm::dvec3 shadowed = surface_radiance(kWood, n, l, n, true, kSky, kSun, sun_cosine(n, n, l), 0);
  EXPECT_EQ(shadowed, sky_ambient(kWood, n, kSky));
  expect_near(shadowed, {0.0375, 0.03, 0.024}, 1e-15);
}

TEST(Shading, AGrazingSunFadesLinearlyToTheSkyAlone) {
  // l_y = 0.01 (0.57° above the horizon): the ground gets ρ/π·E·0.01 of sunlight,
  //   (0.0875 + 0.0105/π, 0.09 + 0.009/π, 0.1 + 0.007/π) = (0.0908423, 0.0928648, 0.1022282).
  const glm::dvec3 view(0, 1, 0);
  const glm::dvec3 grazing(std::sqrt(1 - 0.01 * 0.01), 0.01, 0);
  expect_near(surface_radiance(kGround, kGroundNormal, grazing, view, false, kSky, kSun,
                               sun_cosine(kGroundNormal, kGroundNormal, grazing), 1),
              {0.0908422538, 0.0928647890, 0.1022281692}, 1e-10);
  // On the horizon (l_y = 0): no sunlight at all, the ambient term exactly.
  const glm::dvec3 horizon(1, 0, 0);
  EXPECT_EQ(sun_cosine(kGroundNormal, kGroundNormal, horizon), 0.0);
  EXPECT_EQ(surface_radiance(kGround, kGroundNormal, horizon, view, false, kSky, kSun, 0, 1),
            glm::dvec3(0.35 * 0.25, 0.3 * 0.3, 0.25 * 0.4));
}

TEST(Shading, TheGroundUnderASunBelowTheHorizonIsLitByTheSkyAlone) {
  const glm::dvec3 below(0.6, -0.8, 0), view(0, 1, 0);
  const double cos_sun = sun_cosine(kGroundNormal, kGroundNormal, below);
  EXPECT_EQ(cos_sun, 0.0);
  // Even where the caller passes V = 1 (nothing blocks it; the ground casts no shadow).
  EXPECT_EQ(surface_radiance(kGround, kGroundNormal, below, view, false, kSky, kSun, cos_sun, 1),
            sky_ambient(kGround, kGroundNormal, kSky));
}

TEST(Shading, TheGroundIsFoundAlongDescendingRaysFromAboveIt) {
  // 2 m above, straight down at unit speed: t = 2; at 45° with |d_y| = 0.5: t = 4.
  EXPECT_EQ(ground_distance(2, -1), 2.0);
  EXPECT_EQ(ground_distance(2, -0.5), 4.0);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ground_distance(2, 0), inf);     // level
  EXPECT_EQ(ground_distance(2, 0.3), inf);   // rising
  EXPECT_EQ(ground_distance(0, -1), inf);    // on the ground
  EXPECT_EQ(ground_distance(-1, -1), inf);   // below it
}

TEST(Shading, AMissSeesTheSky) { EXPECT_EQ(sky_radiance(kSky), kSky); }

}  // namespace
}  // namespace sylva
