// shading_scenes.h — tiny scenes in which one pixel's beauty is known in closed form from
// the model of core/light/shading.h, with the values worked out by hand below. The CPU
// (tests/cpu/render_shading_test.cpp) and GL (tests/gl/render_gl_shading_test.cpp) renders
// must each give them: an error both backends shared would fail here, where comparing the
// two with each other passes it.
//
// Every scene: sky L_sky = (0.25, 0.3, 0.4), a point sun (angular radius 0) of irradiance
// E = (3, 3, 2.8) W/m² at normal incidence, square images (the centre pixel of an odd size
// is sampled exactly along the camera's forward axis), 40° field of view.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>

#include "core/scene/scene.h"
#include "tests/support/test_scenes.h"

namespace sylva::test {

inline constexpr glm::dvec3 kShadingSky{0.25, 0.3, 0.4};
inline constexpr glm::dvec3 kShadingSun{3, 3, 2.8};
inline constexpr glm::dvec3 kShadingGroundAlbedo{0.35, 0.3, 0.25};

// A pixel and the beauty it must have.
struct KnownPixel {
  uint32_t x = 0, y = 0;
  glm::dvec3 beauty{0};
};

inline Scene shading_scene(const Skeleton& sk, glm::dvec3 eye, glm::dvec3 target, uint32_t size,
                           glm::dvec3 sun_direction, double ground_height) {
  Scene s = scene_around(sk, eye, target, size, size, ground_height);
  s.sky = kShadingSky;
  s.sun.radiance = kShadingSun;
  s.sun.direction = sun_direction;
  s.ground.albedo = kShadingGroundAlbedo;
  return s;
}

// The ground (y = 0, albedo ρ = (0.35, 0.3, 0.25)) seen straight down from 10 m, 9×9
// pixels, the sun at 36.87° from the zenith: l = (3, 4, 0)/5, cos θ = n·l = l_y = 0.8.
// A thin cylinder stands near a corner (r = 0.2, 1 m tall at (2.5, 0, 2.5)) so the scene
// has a plant; its shadow falls toward −x, away from the centre. The centre pixel sees the
// ground at the origin (n = +Y, no specular, V = 1):
//   beauty = ρ · L_sky · (1 + 1)/2 + ρ/π · E · 0.8
//     R: 0.35·0.25 + 0.35·3·0.8/π = 0.0875 + 0.84/π = 0.0875 + 0.267380 = 0.354880
//     G: 0.3·0.3  + 0.3·3·0.8/π  = 0.09   + 0.72/π = 0.09   + 0.229183 = 0.319183
//     B: 0.25·0.4 + 0.25·2.8·0.8/π = 0.1  + 0.56/π = 0.1    + 0.178254 = 0.278254
inline Scene sunlit_ground_scene() {
  Scene s = shading_scene(cylinder(0.2, 0, 1), {0, 10, 0}, {0, 0, 0}, 9, {3, 4, 0}, 0);
  s.camera.up = {0, 0, -1};  // looking straight down: image up is −Z
  s.plants.front().position = {2.5, 0, 2.5};
  return s;
}
inline constexpr KnownPixel kSunlitGround{4, 4, {0.3548803044, 0.3191831181, 0.2782535363}};

// The same with the sun below the horizon, l = (3, −4, 0)/5: the ground faces away from it
// (cos θ = l_y < 0), so it is lit by the sky alone:
//   beauty = ρ · L_sky = (0.35·0.25, 0.3·0.3, 0.25·0.4) = (0.0875, 0.09, 0.1)
inline Scene sun_below_horizon_scene() {
  Scene s = sunlit_ground_scene();
  s.sun.direction = {3, -4, 0};
  return s;
}
inline constexpr KnownPixel kGroundUnderSunBelowHorizon{4, 4, {0.0875, 0.09, 0.1}};

// A wide cylinder (radius 1, y from −3 to 3, material 0: wood, ρ = (0.30, 0.20, 0.12)) seen
// head-on from (0, 0, 10), 33×33 pixels. The centre pixel's ray runs along −Z and hits the
// surface at (0, 0, 1): n = n_g = v = (0, 0, 1), n_y = 0, so the sky ambient is half
// the sky's: ρ · L_sky / 2 = (0.0375, 0.03, 0.024). The ground is 100 m below.
inline Scene head_on_cylinder_scene(glm::dvec3 sun_direction) {
  return shading_scene(cylinder(1, -3, 3), {0, 0, 10}, {0, 0, 0}, 33, sun_direction, -100);
}

// Sun l = (0.6, 0, 0.8): cos θ = n·l = 0.8; h = normalize(l + v) = (0.6, 0, 1.8)/√3.6, so
// n·h = 1.8/√3.6 = 3/√10 and (n·h)^40 = (9/10)^20 = 0.121577. The lobe's peak
// k_s·(s + 8)/(8π) = 0.04·48/(8π) = 0.24/π = 0.0763944, so f_s = 0.0763944·0.121577 =
// 0.00928777, and
//   beauty = ρ·L_sky/2 + (ρ/π + f_s) · E · 0.8
//     R: 0.0375 + (0.3/π + 0.00928777)·3·0.8   = 0.0375 + 0.1047808·2.4  = 0.288974
//     G: 0.03   + (0.2/π + 0.00928777)·3·0.8   = 0.03   + 0.0729498·2.4  = 0.205079
//     B: 0.024  + (0.12/π + 0.00928777)·2.8·0.8 = 0.024 + 0.0474853·2.24 = 0.130366
inline Scene lit_cylinder_scene() { return head_on_cylinder_scene({0.6, 0, 0.8}); }
inline constexpr KnownPixel kLitCylinder{16, 16, {0.2889737715, 0.2050793988, 0.1303663073}};

// Sun behind the camera, l = v = n = (0, 0, 1): h = n, the specular peak 0.24/π, cos θ = 1:
//   beauty = ρ·L_sky/2 + (ρ/π + 0.24/π) · E
//     R: 0.0375 + 0.54/π·3    = 0.0375 + 0.515662 = 0.553162
//     G: 0.03   + 0.44/π·3    = 0.03   + 0.420169 = 0.450169
//     B: 0.024  + 0.36/π·2.8  = 0.024  + 0.320856 = 0.344856
inline Scene specular_peak_scene() { return head_on_cylinder_scene({0, 0, 1}); }
inline constexpr KnownPixel kSpecularPeak{16, 16, {0.5531620156, 0.4501690498, 0.3448563653}};

// The same with the scene's `materials` table (docs/materials.md) describing material 0 as
// ρ = (0.5, 0.4, 0.2) with half the lobe, specular 0.5:
//   beauty = ρ·L_sky/2 + (ρ/π + 0.5·0.24/π) · E
//     R: 0.0625 + 0.62/π·3    = 0.0625 + 0.592056 = 0.654556
//     G: 0.06   + 0.52/π·3    = 0.06   + 0.496563 = 0.556563
//     B: 0.04   + 0.32/π·2.8  = 0.04   + 0.285206 = 0.325206
inline Scene material_table_scene() {
  Scene s = specular_peak_scene();
  s.materials[0] = SceneMaterial{glm::dvec3(0.5, 0.4, 0.2), 0.5};
  return s;
}
inline constexpr KnownPixel kMaterialTablePeak{16, 16, {0.6545563883, 0.5565634224, 0.3252056580}};

// lit_cylinder_scene with a second cylinder (radius 0.5, out of view at x = 3, z = 5)
// standing in the sun's way: the shadow ray from (0, 0, 1) along l = (0.6, 0, 0.8) passes
// its axis at t = 5. V = 0, so the centre is lit by the sky alone:
//   beauty = ρ·L_sky/2 = (0.0375, 0.03, 0.024)
inline Scene shadowed_cylinder_scene() {
  Scene s = lit_cylinder_scene();
  ScenePlant blocker;
  blocker.skeleton = cylinder(0.5, -3, 3);
  blocker.position = {3, 0, 5};
  s.plants.push_back(blocker);
  return s;
}
inline constexpr KnownPixel kShadowedCylinder{16, 16, {0.0375, 0.03, 0.024}};

// In lit_cylinder_scene the sun is on the horizon (l_y = 0): the ground, seen in the
// bottom-left corner pixel, has cos θ = 0 and gets the sky alone,
//   beauty = ρ_ground · L_sky = (0.0875, 0.09, 0.1);
// the top-left corner pixel looks above the horizon at nothing: beauty = L_sky.
inline constexpr KnownPixel kGroundUnderHorizontalSun{0, 32, {0.0875, 0.09, 0.1}};
inline constexpr KnownPixel kSkyCorner{0, 0, {0.25, 0.3, 0.4}};

}  // namespace sylva::test
