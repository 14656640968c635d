// sky.h — the skies that answer light queries (docs/spec/light.md): where their light comes
// from and how a sensor sphere's light splits between the sun and the sky. Math only.
//
// A sensor is a sphere: it receives light from every direction alike (scalar irradiance),
// so the photons that estimate it are drawn in proportion to radiance over solid angle
// (not cosine-weighted), each from a disc perpendicular to its own direction.
// Frames: world space, Y up; θ is the zenith angle, μ = cos θ.
#pragma once

#include <glm/vec3.hpp>

namespace sylva {

// The sky's radiance as a function of μ = cos θ, up to a constant: the uniform overcast
// sky (UOC) is 1, the CIE standard overcast sky (SOC, Moon and Spencer 1942) 1 + 2μ.
enum class SkyShape { uniform, overcast };

// μ of a direction drawn in proportion to the sky's radiance over the upper hemisphere's
// solid angle, from u uniform in [0, 1): UOC μ = u; SOC p(μ) = (1 + 2μ)/2, whose inverse
// CDF μ = (√(1 + 8u) − 1)/2 is computed as 4u/(1 + √(1 + 8u)) (no cancellation near u = 0).
double sky_sample_mu(SkyShape shape, double u);

// The unit direction toward the sky drawn from (u, v) uniform in [0, 1)²: μ from u, the
// azimuth 2πv (the sky is symmetric about the zenith).
glm::dvec3 sky_sample_direction(SkyShape shape, double u, double v);

// The sky's scalar irradiance over its horizontal irradiance: ∫L dω / ∫L μ dω over the
// hemisphere — UOC 2π/π = 2; SOC 4π/(7π/3) = 12/7.
double sky_scalar_over_horizontal(SkyShape shape);

// The share of a sensor's light (scalar irradiance, open sky) that comes from the sun when
// `sun_fraction` of the horizontal irradiance does and the sun's zenith cosine is
// `sun_mu`: s = (f/μs) / (f/μs + (1 − f)·k), k = sky_scalar_over_horizontal. A sun at or
// below the horizon (μs ≤ 0) gives none (0); f = 1 gives 1 for a sun above it.
double sun_scalar_share(double sun_fraction, double sun_mu, SkyShape shape);

}  // namespace sylva
