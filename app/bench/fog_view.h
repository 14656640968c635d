// fog_view.h — the fog AOV's in-scatter through pixel centres, as render_cpu computes it,
// for the benchmarks that measure fog error (bench fog: the CPU modes; bench gpu --fog:
// the GL pass) against the CPU `reference` mode (docs/spec/fog.md).
//
// A View holds a scene camera's pixel-centre rays (unit directions, world metres) and
// where each ends: the first plant or the ground, +inf for the sky. A strided view keeps a
// uniform grid of them (every S-th pixel each way), on which a slow reference can be
// computed for an image too large to compute it whole: the RMSE over a uniform grid is
// the whole image's in expectation.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/scene/fog_integrator.h"
#include "core/scene/scene.h"
#include "core/geometry/surface.h"
#include "core/util/progress.h"

namespace sylva::cli {

struct View {
  uint32_t width = 0, height = 0;
  std::vector<glm::dvec3> origin, direction;  // direction unit
  std::vector<double> t_end;
};

// The pixel-centre camera rays of `scene`'s camera and where each ends on `tracer`'s
// plants or scene.ground (+inf: the sky).
View pixel_rays(const Scene& scene, const SceneTracer& tracer);

// The pixels of `v` on a `stride` grid: (x, y) with x, y ≡ stride/2 (mod stride), as one
// row; *pixels gets their indices in `v` (row-major), in the view's order.
View strided(const View& v, uint32_t stride, std::vector<size_t>* pixels);

// The in-scatter of every ray of `v` (RGB, in the view's order) by `integrator` on
// `threads` threads (0: every core); ray i's random numbers from (seed, i) only, so the
// image does not depend on the thread count. *seconds: wall time; *cpu_seconds (when
// given): the process's CPU time meanwhile (core-seconds). `progress` is told the fraction
// of the rays done, every 16 chunks of 256.
std::vector<float> fog_image(const View& v, const FogIntegrator& integrator, uint64_t seed, unsigned threads,
                             double* seconds, double* cpu_seconds = nullptr, const Progress& progress = {});

// RMSE over `pixels` (indices into `image`, RGB per pixel with `stride` floats) and the
// channels R, G, B against `reference` (RGB, one per pixel in `pixels`' order).
template <typename T>
double rmse_at(const std::vector<T>& image, size_t stride, const std::vector<double>& reference,
               const std::vector<size_t>& pixels) {
  double sum = 0;
  for (size_t k = 0; k < pixels.size(); ++k)
    for (int c = 0; c < 3; ++c) {
      const double d = double(image[pixels[k] * stride + c]) - reference[k * 3 + c];
      sum += d * d;
    }
  return std::sqrt(sum / double(pixels.empty() ? 1 : 3 * pixels.size()));
}

}  // namespace sylva::cli
