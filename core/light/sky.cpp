// sky.cpp — sky sampling and the sun's share of a sensor's light (sky.h).
#include "core/light/sky.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sylva {

double sky_sample_mu(SkyShape shape, double u) {
  if (shape == SkyShape::uniform) return u;
  return 4 * u / (1 + std::sqrt(1 + 8 * u));
}

glm::dvec3 sky_sample_direction(SkyShape shape, double u, double v) {
  const double mu = sky_sample_mu(shape, u);
  const double sin_theta = std::sqrt(std::max(0.0, (1 - mu) * (1 + mu)));
  const double phi = 2 * std::numbers::pi * v;
  return {sin_theta * std::cos(phi), mu, sin_theta * std::sin(phi)};
}

double sky_scalar_over_horizontal(SkyShape shape) { return shape == SkyShape::uniform ? 2.0 : 12.0 / 7.0; }

double sun_scalar_share(double sun_fraction, double sun_mu, SkyShape shape) {
  if (!(sun_mu > 0) || sun_fraction <= 0) return 0;
  if (sun_fraction >= 1) return 1;
  const double sun = sun_fraction / sun_mu;
  return sun / (sun + (1 - sun_fraction) * sky_scalar_over_horizontal(shape));
}

}  // namespace sylva
