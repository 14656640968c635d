// light_cases.cpp — the closed-form cases of the light (light_cases.h).
#include "core/scene/light_cases.h"

#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <numbers>
#include <random>
#include <utility>

namespace sylva {

Scene light_check_scene(LightSky sky, const glm::dvec3& to_sun, double sun_radius_deg, uint64_t photons,
                        double sensor_radius_m) {
  Scene s;
  s.sun.direction = glm::normalize(to_sun);
  s.sun.angular_radius_deg = sun_radius_deg;
  s.ground.height = 0;
  LightEnvironment e;
  e.sky = sky;
  e.photons = photons;
  e.sensor_radius_m = sensor_radius_m;
  e.sun_fraction = 0.6;
  s.environment = e;
  return s;
}

Skeleton light_disc(double radius_m, double y_m) {
  Skeleton sk;
  Leaf leaf;
  for (int i = 0; i < 64; ++i) {
    const double phi = 2 * std::numbers::pi * i / 64;
    leaf.vertices_m.push_back({radius_m * std::cos(phi), y_m, radius_m * std::sin(phi)});
  }
  sk.leaves.push_back(std::move(leaf));
  return sk;
}

Skeleton leaf_slab(double lai, uint64_t seed) {
  Skeleton sk;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const double side = 0.1, width = 10;
  const long leaves = std::lround(lai * width * width / (side * side));
  for (long i = 0; i < leaves; ++i) {
    const glm::dvec3 c(width * (u(rng) - 0.5), 1 + u(rng), width * (u(rng) - 0.5));
    const double mu = 2 * u(rng) - 1, phi = 2 * std::numbers::pi * u(rng);
    const double s = std::sqrt(1 - mu * mu);
    const glm::dvec3 n(s * std::cos(phi), mu, s * std::sin(phi));
    const glm::dvec3 helper = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 e0 = glm::normalize(glm::cross(n, helper)), e1 = glm::cross(n, e0);
    Leaf leaf;
    for (const auto& [a, b] : {std::pair{-1.0, -1.0}, std::pair{1.0, -1.0}, std::pair{1.0, 1.0}, std::pair{-1.0, 1.0}}) {
      const glm::dvec3 v = c + 0.5 * side * (a * e0 + b * e1);
      leaf.vertices_m.push_back({v.x, v.y, v.z});
    }
    sk.leaves.push_back(std::move(leaf));
  }
  return sk;
}

double beer_lambert_q(double lai, double sun_zenith_rad) { return std::exp(-0.5 * lai / std::cos(sun_zenith_rad)); }

double under_disc_q(double radius_m, double depth_m, bool overcast) {
  const double mu0 = depth_m / std::hypot(depth_m, radius_m);
  return overcast ? (mu0 + mu0 * mu0) / 2 : mu0;
}

}  // namespace sylva
