// test_scenes.h — the small scenes the core tests render: a cylinder whose answers are
// known analytically, seen by a camera placed by the test, no ground in view, a hard sun.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>
#include <optional>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/scene/render_common.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"
#include "core/light/shading.h"
#include "tests/support/plants.h"

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

// The leaf tests' grammar (tests/cpu/render_leaves_test.cpp, tests/gl/render_gl_leaves_test.cpp):
// a thin stem (radius 0.02 m) from the origin to (0, 1, 0), then, of material 2, one
// square leaf 1 m wide in the plane z = 0 with corners (0, 1), (−1, 1), (−1, 2), (0, 2)
// (x, y), hanging from the stem's top joint.
inline constexpr const char* kOneLeafGrammar = "angle: 90\naxiom: !(0.02)F(1)'(2){.+f(1).-f(1).-f(1).}\n";
inline constexpr uint32_t kOneLeafMaterial = 2;
inline const glm::dvec3 kOneLeafAlbedo{0.7, 0.15, 0.1};  // the scene's table entry for it

// kOneLeafGrammar's plant seen from `eye` (looking at (−0.5, 1, −0.5)), the ground at
// y = 0, a point sun toward `sun`, material 2 described by the table (kOneLeafAlbedo,
// specular 0.5); 96 × 72 pixels.
inline Scene one_leaf_scene(glm::dvec3 eye, glm::dvec3 sun, uint32_t width = 96, uint32_t height = 72) {
  Scene s = scene_around(grown(kOneLeafGrammar), eye, {-0.5, 1, -0.5}, width, height, 0);
  s.sun.direction = glm::normalize(sun);
  SceneMaterial m;
  m.albedo_rgb = kOneLeafAlbedo;
  m.specular = 0.5;
  s.materials[kOneLeafMaterial] = m;
  return s;
}

// one_leaf_scene with the sun along (0, 1, 1), seen from (−0.5, 3, 4): the square (z = 0,
// 1 <= y <= 2) throws its shadow onto the ground at −2 <= z <= −1, −1 <= x <= 0, in view.
inline Scene leaf_shadow_scene() { return one_leaf_scene({-0.5, 3, 4}, {0, 1, 1}); }

// Where world point p appears in `scene`'s image: continuous pixel coordinates (x right,
// y down), the inverse of camera_ray.
inline glm::dvec2 pixel_of(const Scene& scene, const glm::dvec3& p) {
  const render_common::CameraFrame f = render_common::camera_frame(scene);
  const glm::dvec3 d = p - f.eye;
  const double z = glm::dot(d, f.forward);
  const double sx = glm::dot(d, f.right) / z, sy = glm::dot(d, f.up) / z;
  return {(sx / f.half_width + 1) * 0.5 * f.width, (1 - sy / f.half_height) * 0.5 * f.height};
}

// What pixel (x, y)'s centre ray sees of one_leaf_scene's leaf, computed here from the
// square itself: the hit's distance from the eye and its radiance under the sun
// (shading.h with the leaf's normal turned toward the eye, the sun unoccluded); none when
// the ray misses the square or passes within `margin_m` of its edges or of the stem.
struct LeafPixel {
  double distance = 0;
  glm::dvec3 radiance{0};
};
inline std::optional<LeafPixel> one_leaf_pixel(const Scene& s, uint32_t x, uint32_t y, double margin_m = 0.05) {
  const Ray ray = camera_ray(s, x + 0.5, y + 0.5);
  if (ray.direction.z == 0) return std::nullopt;
  const double t = -ray.origin.z / ray.direction.z;
  const glm::dvec3 p = ray.origin + t * ray.direction;
  if (!(t > 0) || p.x < -1 + margin_m || p.x > -margin_m || p.y < 1 + margin_m || p.y > 2 - margin_m)
    return std::nullopt;
  const glm::dvec3 view = -glm::normalize(ray.direction);
  const glm::dvec3 n(0, 0, view.z > 0 ? 1 : -1);
  const glm::dvec3 l = glm::normalize(s.sun.direction);
  const double cos_sun = shading::sun_cosine(n, n, l);
  LeafPixel out;
  out.distance = t * glm::length(ray.direction);
  out.radiance = shading::surface_radiance(kOneLeafAlbedo, n, l, view, 0.5, s.sky, s.sun.radiance, cos_sun, 1);
  return out;
}


// The instancing tests' grove (tests/cpu/instance_tracer_test.cpp, tests/gl/...): 13 plants
// of three skeletons — a forked stem with a leaf (6 plants), the cylinder of radius 0.12 m
// (6 plants) and one crooked stem no other plant shares — turned and scaled apart on a
// 3 m grid, seen from above the front so that plants hide and shadow each other, the ground
// at y = 0 in view, a point sun from (0.5, 1, 0.3).
inline constexpr const char* kForkGrammar =
    "angle: 35\naxiom: !(0.08)F(1)[+!(0.05)F(0.8)'(2){.+f(0.4).-f(0.4).-f(0.4).}][-!(0.05)F(0.7)]!(0.06)F(0.6)\n";
// Pixels where two images of `channels` floats per pixel differ by more than `tolerance`
// (relative to max(1, |a|)) in any channel.
inline size_t differing_pixels(const std::vector<float>& a, const std::vector<float>& b, int channels, double tolerance) {
  size_t n = 0;
  for (size_t px = 0; px * channels < a.size() && px * channels < b.size(); ++px)
    for (int c = 0; c < channels; ++c) {
      const double x = a[px * channels + c], y = b[px * channels + c];
      if (x == y) continue;
      if (!(std::abs(x - y) <= tolerance * std::max(1.0, std::abs(x)))) {
        ++n;
        break;
      }
    }
  return n + (a.size() == b.size() ? 0 : 1);
}

// The pass named `name` of a render, or null.
inline const RenderPass* find_pass(const RenderResult& r, const std::string& name) {
  for (const RenderPass& p : r.passes)
    if (p.name == name) return &p;
  return nullptr;
}

// How many pixels of an id AOV name each of `plants` plants.
inline std::vector<int> pixels_per_plant(const RenderImage& image, size_t plants) {
  std::vector<int> seen(plants, 0);
  for (size_t px = 0; px * 3 < image.id.size(); ++px)
    if (image.id[px * 3] >= 0 && image.id[px * 3] < static_cast<float>(plants)) ++seen[static_cast<size_t>(image.id[px * 3])];
  return seen;
}

// The V channel of a uv AOV.
inline std::vector<float> v_of_uv(const RenderImage& image) {
  std::vector<float> v;
  for (size_t px = 0; 2 * px < image.uv.size(); ++px) v.push_back(image.uv[2 * px + 1]);
  return v;
}

inline Scene instanced_grove(uint32_t width = 96, uint32_t height = 72) {
  const Skeleton fork = grown(kForkGrammar);
  const Skeleton stem = cylinder(0.12, 0, 1.6);
  const Skeleton crooked = grown("angle: 25\naxiom: !(0.1)F(0.8)+F(0.8)-F(0.5)\n");
  Scene s = scene_around(fork, {9, 7, 12}, {-0.5, 0.6, 0}, width, height, 0);
  s.sun.direction = glm::normalize(glm::dvec3(0.5, 1, 0.3));
  s.plants.clear();
  for (int k = 0; k < 13; ++k) {
    ScenePlant p;
    p.skeleton = k == 6 ? crooked : k % 2 == 0 ? fork : stem;
    p.position = {3.0 * (k % 4) - 4.5, 0, 3.0 * (k / 4) - 4.5};
    p.rotate_y_deg = 37.0 * k;
    p.scale = 0.7 + 0.05 * k;
    s.plants.push_back(p);
  }
  return s;
}

}  // namespace sylva::test
