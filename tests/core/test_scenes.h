// test_scenes.h — the small scenes the core tests render: a cylinder whose answers are
// known analytically, seen by a camera placed by the test, no ground in view, a hard sun.
#pragma once

#include <cstdint>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/scene.h"

namespace sylva::test {

// One vertical cylinder on the Y axis from y0 to y1 of radius r, every joint `material`.
inline Skeleton cylinder(double radius, double y0, double y1, uint32_t material = 0) {
  Skeleton sk;
  sk.joints = {{{0, y0, 0}, radius, material}, {{0, y1, 0}, radius, material}};
  sk.chains = {{0, 2, std::nullopt}};
  return sk;
}

// A wood stem (material 0, radius 0.3 m at x = −0.7) and a needle-coloured one (material
// 1, radius 0.2 m at x = +0.7), each a root chain from y = 0 to 2: the sun (from +x, +y)
// throws neither's shadow on the other, so a bark on the wood changes no needle pixel.
inline Skeleton wood_and_needle() {
  Skeleton sk;
  sk.joints = {{{-0.7, 0, 0}, 0.3, 0}, {{-0.7, 2, 0}, 0.3, 0}, {{0.7, 0, 0}, 0.2, 1}, {{0.7, 2, 0}, 0.2, 1}};
  sk.chains = {{0, 2, std::nullopt}, {2, 2, std::nullopt}};
  return sk;
}

// One plant `sk` at the origin, width × height pixels, the camera at `eye` looking at
// `target` (40° vertical field of view, +Y up), the ground at `ground_height` (far below
// by default), a point sun (angular radius 0) in the default direction.
inline Scene scene_around(const Skeleton& sk, glm::dvec3 eye, glm::dvec3 target, uint32_t width, uint32_t height,
                          double ground_height = -100) {
  Scene s;
  s.width = width;
  s.height = height;
  s.camera.eye = eye;
  s.camera.target = target;
  s.camera.up = {0, 1, 0};
  s.camera.fov_y_deg = 40;
  s.ground.height = ground_height;
  s.sun.angular_radius_deg = 0;
  ScenePlant plant;
  plant.skeleton = sk;
  s.plants.push_back(plant);
  return s;
}

// The fog tests' scene (tests/cpu/render_fog_test.cpp, tests/gl/render_gl_fog_test.cpp): a
// cylinder of radius 0.5 and 2 m on the ground at the origin, seen from 6 m away and 1.5 m
// up (ground below, sky above, the plant in the middle); a point sun from (0.4, 1, −0.3);
// homogeneous fog (σ_s 0.05, σ_a 0.01, g 0.6) under a top at 30 m, `mode` with `steps`.
inline Scene foggy_cylinder(FogMode mode, uint32_t steps, uint32_t width = 48, uint32_t height = 36) {
  Scene s = scene_around(cylinder(0.5, 0, 2), {0, 1.5, 6}, {0, 1, 0}, width, height, 0);
  s.sun.direction = glm::normalize(glm::dvec3(0.4, 1, -0.3));
  Fog f;
  f.sigma_s = 0.05;
  f.sigma_a = 0.01;
  f.g = 0.6;
  f.top = 30;
  f.mode = mode;
  f.steps = steps;
  s.fog = f;
  return s;
}

}  // namespace sylva::test
