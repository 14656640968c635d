// shading.glsl — the shading model of core/light/shading.h in float, function by function: the
// same names, the same arguments in the same order, the same expressions in the same order
// (the header states the model, units and preconditions; tests/gl/gl_shading_twin_test.cpp
// compares the two case by case). The constants come from core/light/shading.h through
// #defines (gl_shaders.h shading_defines), so they cannot drift.

#if !defined(SHADING_SPECULAR) || !defined(SHADING_SHININESS)
#error "shading.glsl needs SHADING_SPECULAR and SHADING_SHININESS (gl_shaders.h shading_defines)"
#endif
#ifndef kInfinity  // ray_frustum.glsl's or bark.glsl's, where one comes first
#define kInfinity uintBitsToFloat(0x7F800000u)  // +inf (a const initializer cannot call it)
#endif

const float kPi = 3.14159265358979323846;
const float kSpecular = SHADING_SPECULAR;    // k_s
const float kShininess = SHADING_SHININESS;  // s
const vec3 kGroundNormal = vec3(0.0, 1.0, 0.0);

// ρ · L_sky · (1 + n_y)/2.
vec3 sky_ambient(vec3 albedo, vec3 n, vec3 sky) { return albedo * sky * (0.5 * (1.0 + n.y)); }

// n·l where both normals face the sun, else 0.
float sun_cosine(vec3 n, vec3 n_geometric, vec3 l) {
  float n_dot_l = dot(n, l);
  return n_dot_l <= 0.0 || dot(n_geometric, l) <= 0.0 ? 0.0 : n_dot_l;
}

// k_s · (s + 8)/(8π) · max(n·h, 0)^s, h = normalize(l + view).
float blinn_phong(vec3 n, vec3 l, vec3 view) {
  vec3 h = normalize(l + view);
  return kSpecular * (kShininess + 8.0) / (8.0 * kPi) * pow(max(0.0, dot(n, h)), kShininess);
}

// ρ/π, plus `specular` (the lobe's weight) times blinn_phong.
vec3 surface_brdf(vec3 albedo, vec3 n, vec3 l, vec3 view, float specular) {
  vec3 brdf = albedo / kPi;
  if (specular > 0.0) brdf += vec3(specular * blinn_phong(n, l, view));
  return brdf;
}

// brdf · E · (cos θ · V).
vec3 sun_reflected(vec3 brdf, vec3 sun_irradiance, float cos_sun, float visibility) {
  return brdf * sun_irradiance * (cos_sun * visibility);
}

// sky_ambient, plus the sunlight where cos_sun > 0 and visibility > 0.
vec3 surface_radiance(vec3 albedo, vec3 n, vec3 l, vec3 view, float specular, vec3 sky, vec3 sun_irradiance,
                      float cos_sun, float visibility) {
  vec3 ambient = sky_ambient(albedo, n, sky);
  if (cos_sun <= 0.0 || visibility == 0.0) return ambient;
  return ambient + sun_reflected(surface_brdf(albedo, n, l, view, specular), sun_irradiance, cos_sun, visibility);
}

// t where origin + t·direction meets the ground, `above_ground` = origin.y − ground height;
// +inf where it never does.
float ground_distance(float above_ground, float direction_y) {
  return direction_y < 0.0 && above_ground > 0.0 ? -above_ground / direction_y : kInfinity;
}

// What a ray that hits nothing sees.
vec3 sky_radiance(vec3 sky) { return sky; }
