// light_cases.h — the closed-form cases of docs/spec/light.md "Accuracy and cost", shared by
// the tests (tests/cpu/light_tracer_test.cpp) and `sylva bench light`: the plants each
// case is made of and the q it must give.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

#include "core/geometry/skeleton.h"
#include "core/scene/scene.h"

namespace sylva {

// The scene of a check: the sun toward `to_sun` (any length) with angular radius
// `sun_radius_deg`, the ground at y = 0, and an environment of `sky` (sun_fraction 0.6
// for the sun+ skies), `photons` and `sensor_radius_m`.
Scene light_check_scene(LightSky sky, const glm::dvec3& to_sun, double sun_radius_deg, uint64_t photons,
                        double sensor_radius_m);

// A horizontal opaque disc (a 64-gon leaf) of radius `radius_m` centred at (0, y_m, 0).
Skeleton light_disc(double radius_m, double y_m);

// A slab 10 m × 10 m (x, z centred on 0), from y = 1 to 2 m, of square leaves 0.1 m a
// side at uniform random places with uniform random orientations (the spherical leaf
// angle distribution, G = 0.5), `lai` m² of leaf per m² of ground; `seed` draws them.
Skeleton leaf_slab(double lai, uint64_t seed);

// Beer–Lambert below such a slab under a sun at zenith angle θ: exp(−0.5·lai / cos θ).
double beer_lambert_q(double lai, double sun_zenith_rad);

// q at a point `depth_m` below the centre of an opaque disc of radius `radius_m` in a
// uniform (overcast = false) or CIE overcast sky, over solid angle (a sphere's view):
// with μ0 = depth/√(depth² + radius²), UOC μ0, SOC (μ0 + μ0²)/2.
double under_disc_q(double radius_m, double depth_m, bool overcast);

}  // namespace sylva
