// fog_view.cpp — see fog_view.h.
#include "app/bench/fog_view.h"

#include <algorithm>
#include <atomic>
#include <limits>

#include "core/scene/render_common.h"
#include "core/light/shading.h"
#include "core/util/random.h"
#include "core/util/clock.h"
#include "core/util/parallel.h"

namespace sylva::cli {

View pixel_rays(const Scene& scene, const SceneTracer& tracer) {
  View v;
  v.width = scene.width, v.height = scene.height;
  const size_t n = size_t(v.width) * v.height;
  v.origin.resize(n), v.direction.resize(n), v.t_end.resize(n);
  for (uint32_t y = 0; y < v.height; ++y)
    for (uint32_t x = 0; x < v.width; ++x) {
      const size_t i = size_t(y) * v.width + x;
      const Ray ray = camera_ray(scene, x + 0.5, y + 0.5);
      const double length = glm::length(ray.direction);
      const double surface = tracer.nearest(ray, 0, std::numeric_limits<double>::infinity()).t;
      const double ground = shading::ground_distance(ray.origin.y - scene.ground.height, ray.direction.y);
      v.origin[i] = ray.origin;
      v.direction[i] = ray.direction / length;
      v.t_end[i] = std::min(surface, ground) * length;
    }
  return v;
}

View strided(const View& v, uint32_t stride, std::vector<size_t>* pixels) {
  View out;
  pixels->clear();
  for (uint32_t y = stride / 2; y < v.height; y += stride)
    for (uint32_t x = stride / 2; x < v.width; x += stride) {
      const size_t i = size_t(y) * v.width + x;
      pixels->push_back(i);
      out.origin.push_back(v.origin[i]), out.direction.push_back(v.direction[i]), out.t_end.push_back(v.t_end[i]);
    }
  out.width = static_cast<uint32_t>(pixels->size()), out.height = 1;
  return out;
}

std::vector<float> fog_image(const View& v, const FogIntegrator& integrator, uint64_t seed, unsigned threads,
                             double* seconds, double* cpu_seconds, const Progress& progress) {
  const size_t n = v.origin.size();
  std::vector<float> out(n * 3);
  constexpr size_t kChunk = 256;  // pixels per work item
  const size_t chunks = (n + kChunk - 1) / kChunk;
  std::atomic<size_t> chunks_done{0};
  const auto start = Clock::now();
  const double cpu_start = process_cpu_seconds();
  parallel_for(chunks, threads, nullptr, [&](size_t chunk, unsigned) {
    for (size_t i = chunk * kChunk; i < std::min(n, (chunk + 1) * kChunk); ++i) {
      render_common::SampleRng rng(mix_pair(seed, i));
      const FogRayResult r = integrator.integrate(v.origin[i], v.direction[i], v.t_end[i], rng);
      for (int c = 0; c < 3; ++c) out[i * 3 + c] = static_cast<float>(r.inscatter[c]);
    }
    const size_t done = chunks_done.fetch_add(1, std::memory_order_relaxed) + 1;
    if (progress.reporting() && done % 16 == 0) progress.report(double(done) / double(chunks), "fog");
  });
  progress.report(1, "fog");
  *seconds = seconds_since(start);
  if (cpu_seconds) *cpu_seconds = process_cpu_seconds() - cpu_start;
  return out;
}

}  // namespace sylva::cli
