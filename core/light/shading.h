// shading.h — the shading model both renderers use, term by term: the CPU reference
// (core/cpu/render_cpu.cpp, in double) calls these functions, the GL renderer calls their
// GLSL twins in shaders/shading.glsl (float; same names, same arguments in the same order,
// the same expressions in the same order), from shaders/shade.frag.glsl.
// tests/light/shading_test.cpp pins their values by hand, tests/gl/gl_shading_twin_test.cpp
// compares the twins case by case, and tests/cpu and tests/gl render scenes whose pixels are
// known in closed form, so an error the two backends shared would still fail.
//
// The model (linear RGB radiance toward the eye), at a point with albedo ρ, unit shading
// normal n facing the eye, unit geometric normal n_g facing the eye, unit direction l toward
// the sun, unit view direction v (toward the eye), h = normalize(l + v):
//   L = ρ · L_sky · (1 + n_y)/2                              sky_ambient
//     + (ρ/π + w · k_s · (s + 8)/(8π) · max(n·h, 0)^s)       surface_brdf: Lambert +
//         · E_sun · cos θ · V                                  normalised Blinn-Phong
// with
//   - L_sky = Scene::sky, the uniform sky radiance (W/(m²·sr) per channel). The ambient term
//     is the sky's share of the hemisphere around n, (1 + n_y)/2 of it, unshadowed: the
//     ground below the horizon and the plants do not block it.
//   - E_sun = Sun::radiance, despite the scene key's name the sun's irradiance at normal
//     incidence (W/m² per channel): a surface facing the sun receives E_sun · cos θ.
//   - cos θ = sun_cosine(n, n_g, l): n·l where both n and n_g face the sun, else 0 (a
//     shading normal turned toward a sun that the surface's geometry faces away from must
//     not light it).
//   - V ∈ [0, 1], the sun's visibility from the point past the plants (the ground casts no
//     shadow). The caller finds it: a shadow ray on the CPU (render_cpu.h), a shadow map on
//     GL (render_gl.h). A sun below the horizon lights what faces it: the ground never
//     (cos θ = l_y ≤ 0), a plant face turned toward it, yes.
//   - k_s = kSpecular = 0.04 (a dielectric's reflectance at normal incidence), s =
//     kShininess = 40; (s + 8)/(8π) normalises the lobe so it reflects about k_s of what
//     arrives near normal incidence. w ∈ [0, 1] weighs the lobe: a plant's material's
//     `specular` (scene.h SceneMaterial, 1 by default), 0 for the ground.
//   - the ground: the plane y = Ground::height, n = n_g = +Y (kGroundNormal), ρ =
//     Ground::albedo, no specular term; ground_distance finds it along a ray.
//   - a ray that hits nothing sees the sky: sky_radiance (the sun's disc is not drawn).
// GLSL gets kSpecular and kShininess from here (gl_shaders.h shading_defines), so the two
// cannot drift.
//
// Fog (docs/spec/fog.md) attenuates the sun on its way to a surface: callers pass
// T_sun · E_sun as `sun_irradiance`.
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <limits>

#include "core/util/math.h"

namespace sylva::shading {

inline constexpr double kSpecular = 0.04;  // k_s: a dielectric's reflectance at normal incidence
inline constexpr double kShininess = 40;   // s: the Blinn-Phong exponent

// The ground's normal (shading and geometric): +Y.
inline constexpr glm::dvec3 kGroundNormal{0, 1, 0};

// ρ · L_sky · (1 + n_y)/2: the light of a uniform sky `sky` reflected by a Lambertian
// surface of albedo `albedo` with unit normal `n`, counting the sky's share of the
// hemisphere around n as (1 + n_y)/2 (1 facing up, 1/2 vertical, 0 facing down).
inline glm::dvec3 sky_ambient(const glm::dvec3& albedo, const glm::dvec3& n, const glm::dvec3& sky) {
  return albedo * sky * (0.5 * (1 + n.y));
}

// cos θ of the sun at a surface: n·l when the sun (unit direction `l`) is in front of both
// the unit shading normal `n` and the geometric normal `n_geometric`, else 0 (no sunlight).
inline double sun_cosine(const glm::dvec3& n, const glm::dvec3& n_geometric, const glm::dvec3& l) {
  const double n_dot_l = glm::dot(n, l);
  return n_dot_l <= 0 || glm::dot(n_geometric, l) <= 0 ? 0.0 : n_dot_l;
}

// The normalised Blinn-Phong lobe k_s · (s + 8)/(8π) · max(n·h, 0)^s (1/sr) for unit normal
// `n`, unit sun direction `l` and unit view direction `view`, h = normalize(l + view). Its
// peak, at n = h, is k_s · (s + 8)/(8π) = 0.24/π.
inline double blinn_phong(const glm::dvec3& n, const glm::dvec3& l, const glm::dvec3& view) {
  const glm::dvec3 h = glm::normalize(l + view);
  return kSpecular * (kShininess + 8) / (8 * kPi) * std::pow(std::max(0.0, glm::dot(n, h)), kShininess);
}

// The BRDF (1/sr, per channel): Lambert ρ/π, plus `specular` (the weight w, 0 for the
// ground) times blinn_phong.
inline glm::dvec3 surface_brdf(const glm::dvec3& albedo, const glm::dvec3& n, const glm::dvec3& l,
                               const glm::dvec3& view, double specular) {
  glm::dvec3 brdf = albedo / kPi;
  if (specular > 0) brdf += glm::dvec3(specular * blinn_phong(n, l, view));
  return brdf;
}

// The sunlight a surface reflects toward the eye: brdf · E · (cos θ · V), with `brdf` from
// surface_brdf, `sun_irradiance` E at normal incidence (W/m²), `cos_sun` from sun_cosine
// and `visibility` V ∈ [0, 1].
inline glm::dvec3 sun_reflected(const glm::dvec3& brdf, const glm::dvec3& sun_irradiance, double cos_sun,
                                double visibility) {
  return brdf * sun_irradiance * (cos_sun * visibility);
}

// The whole model at a surface point: sky_ambient, plus sun_reflected(surface_brdf(...))
// where the sun reaches it (cos_sun > 0 and visibility > 0; otherwise the ambient term
// alone, exactly). Arguments as above; `cos_sun` = sun_cosine(n, n_geometric, l).
inline glm::dvec3 surface_radiance(const glm::dvec3& albedo, const glm::dvec3& n, const glm::dvec3& l,
                                   const glm::dvec3& view, double specular, const glm::dvec3& sky,
                                   const glm::dvec3& sun_irradiance, double cos_sun, double visibility) {
  const glm::dvec3 ambient = sky_ambient(albedo, n, sky);
  if (cos_sun <= 0 || visibility == 0) return ambient;
  return ambient + sun_reflected(surface_brdf(albedo, n, l, view, specular), sun_irradiance, cos_sun, visibility);
}

// The ray parameter t at which origin + t·direction meets the ground, for an origin
// `above_ground` metres above it (origin.y − Ground::height) and `direction_y` the
// direction's y component (any length); +inf where it never does (going level or up, or
// starting on or below the ground).
inline double ground_distance(double above_ground, double direction_y) {
  return direction_y < 0 && above_ground > 0 ? -above_ground / direction_y
                                             : std::numeric_limits<double>::infinity();
}

// The radiance a ray that hits nothing sees: the uniform sky `sky` (Scene::sky).
inline glm::dvec3 sky_radiance(const glm::dvec3& sky) { return sky; }

}  // namespace sylva::shading
