// light_queries.h — the contract between growth and light (docs/spec/light.md): after a
// derivation step, the grow stage (core/grow/) hands the plants as they stand and the
// positions of their `?E` queries to a LightOracle, which answers every query at once.
// The oracle is implemented where the tracers are (core/cpu/light_tracer.h, sun and sky
// photons through the exact frusta and leaves); growth only sees this interface, so data
// still flows one way (grammar → grow → scene → cpu) and a front end wires the two.
//
// Units and frames: world space, metres, Y up. A query's answer:
//   q       the relative irradiance at the sensor: the light reaching a sphere of radius
//           environment.sensor_radius_m centred there (scalar irradiance: every direction
//           alike), over what it would receive with no plant and no obstacle, in [0, 1]
//           up to the estimator's noise (q may exceed 1 by noise: it is not clamped, so
//           that its mean stays unbiased; the grow stage clamps what the grammar reads).
//   toward  the unit vector toward where the received light comes from (the received
//           light's mean direction, reversed), (0, 0, 0) where nothing was received.
//   std_error  the standard error of q.
// Surfaces that cross a sensor's sphere (the twig it sits on, its own leaf) do not shade
// that sensor.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <span>
#include <vector>

#include "core/geometry/skeleton.h"
#include "core/scene/scene.h"
#include "core/util/diagnostic.h"

namespace sylva {

struct LightAnswer {
  double q = 0;
  glm::dvec3 toward{0, 0, 0};
  double std_error = 0;
};

// What one answer cost and how noisy it was (`sylva grow --verbose` prints it).
struct LightAnswerStats {
  uint64_t photons = 0;        // traced
  uint64_t sensors = 0;
  double seconds = 0;          // wall, the accelerators' build included
  double build_seconds = 0;    // of seconds: skinning, accelerators, sensor grid, crossings
  double cpu_seconds = 0;      // CPU time of the process over the answer
  double mean_relative_error = 0;  // mean over sensors with q > 0 of std_error / q
};

class LightOracle {
 public:
  virtual ~LightOracle() = default;
  // Answers every sensor (one per query, in order) in the light of `scene` (its sun, its
  // ground plane, which stops light, and its environment, or the defaults without one)
  // with `plants` (skeletons placed in the world) as the obstacles. The photons are drawn
  // from (environment.seed, step), so the same inputs give the same answers on any
  // number of threads. Errors: a Diagnostic without a place (the caller adds one).
  virtual Expected<std::vector<LightAnswer>> answer(std::span<const Skeleton> plants,
                                                    std::span<const glm::dvec3> sensors, const Scene& scene,
                                                    int64_t step, LightAnswerStats* stats = nullptr) const = 0;
};

}  // namespace sylva
