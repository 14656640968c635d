// sun_maps.cpp — building the sun-space depth maps (sun_maps.h).
#include "core/cpu/sun_maps.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <numbers>

#include "core/geometry/skin.h"
#include "core/util/clock.h"
#include "core/util/parallel.h"

namespace sylva {

namespace {

constexpr size_t kTileBytes = SunDepthMap::kTile * SunDepthMap::kTile * sizeof(float);
constexpr size_t kIndexBytesPerTile = 3 * sizeof(uint32_t);

std::string mib(size_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MiB", bytes / 1048576.0);
  return text;
}

}  // namespace

std::vector<glm::dvec3> sun_map_directions(const glm::dvec3& to_sun, double radius_rad, uint32_t disc_maps) {
  const glm::dvec3 s = glm::normalize(to_sun);
  if (!(radius_rad > 0) || disc_maps <= 1) return {s};
  const AxisFrame f = axis_frame(s);
  const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
  std::vector<glm::dvec3> out;
  for (uint32_t k = 0; k < disc_maps; ++k) {
    // Equal areas of the disc (for a sun a few milliradians wide, of the solid angle too).
    const double theta = radius_rad * std::sqrt((k + 0.5) / disc_maps), phi = k * golden;
    out.push_back(glm::normalize(std::cos(theta) * s +
                                 std::sin(theta) * (std::cos(phi) * f.e0 + std::sin(phi) * f.e1)));
  }
  return out;
}

std::string SunMaps::describe() const {
  if (maps.empty()) return "no sun maps";
  size_t tiles = 0;
  for (const SunDepthMap& m : maps) tiles += m.allocated_tiles();
  const uint32_t size = maps[0].frame().size, per_side = maps[0].tiles_per_side();
  char text[256];
  std::snprintf(text, sizeof text, "%zu map%s of %u², %.0f of %u tiles each (texel %.2f cm), %s, %.2f M texel rays",
                maps.size(), maps.size() == 1 ? "" : "s", size, double(tiles) / maps.size(), per_side * per_side,
                maps[0].frame().texel_m() * 100, mib(bytes).c_str(), rays * 1e-6);
  return text;
}

Expected<SunMaps> build_sun_maps(const SunPhotonTracer& tracer, const ShadowVectors& vectors,
                                 const SunMapOptions& options) {
  const uint32_t n = options.resolution;
  if (n < kFogMinMapResolution || n > kFogMaxMapResolution || n % SunDepthMap::kTile != 0)
    return file_diagnostic("", "the sun map's resolution must be a multiple of 32 from 32 to 65536 texels, not " +
                                   std::to_string(n));
  const Clock::time_point start = Clock::now();
  const double cpu_start = process_cpu_seconds();
  const SunEmitter& e = tracer.emitter();
  SunMaps out;
  const std::vector<glm::dvec3> directions = sun_map_directions(e.to_sun, e.sun_radius_rad, options.disc_maps);

  // The frames and their tiles, before any texel is allocated.
  const uint32_t per_side = n / SunDepthMap::kTile;
  const size_t grid_tiles = static_cast<size_t>(per_side) * per_side;
  std::vector<SunMapFrame> frames;
  std::vector<std::vector<uint8_t>> allocated(directions.size(), std::vector<uint8_t>(grid_tiles, 0));
  size_t need = 0;
  const glm::dvec3 offset = vectors.origin - e.centre;
  const int dilate = static_cast<int>(options.dilate_tiles);
  for (size_t k = 0; k < directions.size(); ++k) {
    SunMapFrame f;
    f.centre = e.centre;
    f.to_sun = directions[k];
    const AxisFrame axes = axis_frame(f.to_sun);
    f.e0 = axes.e0, f.e1 = axes.e1;
    f.half_extent_m = std::max(e.disc_radius_m, 1e-6);
    f.size = n;
    frames.push_back(f);
    const double tile_m = f.texel_m() * SunDepthMap::kTile;
    std::vector<uint8_t>& flags = allocated[k];
    for (const ShadowVector& v : vectors.vectors) {
      const glm::dvec3 p = glm::dvec3(v.position) + offset;
      const double x = (glm::dot(p, f.e0) + f.half_extent_m) / tile_m, y = (glm::dot(p, f.e1) + f.half_extent_m) / tile_m;
      if (!(x >= 0 && y >= 0 && x < per_side && y < per_side)) continue;
      const int tx = static_cast<int>(x), ty = static_cast<int>(y);
      for (int j = std::max(0, ty - dilate); j <= std::min<int>(per_side - 1, ty + dilate); ++j)
        for (int i = std::max(0, tx - dilate); i <= std::min<int>(per_side - 1, tx + dilate); ++i)
          flags[static_cast<size_t>(j) * per_side + i] = 1;
    }
    size_t tiles = 0;
    for (uint8_t flag : flags) tiles += flag;
    need += tiles * kTileBytes + grid_tiles * kIndexBytesPerTile;
  }
  if (need > options.memory_limit_bytes)
    return file_diagnostic("", "the sun maps would need " + mib(need) + " (" + std::to_string(directions.size()) +
                                   " of " + std::to_string(n) + "² texels), more than the limit of " +
                                   mib(options.memory_limit_bytes) + ": lower the resolution or the disc directions");

  // Trace: one ray per texel of every allocated tile, from the plane above the plants.
  const double above = e.sphere_radius_m * 1.001 + 1e-6;
  for (size_t k = 0; k < directions.size(); ++k) {
    SunDepthMap& map = out.maps.emplace_back(frames[k], allocated[k]);
    std::atomic<uint64_t> rays{0};
    const bool finished = parallel_for(map.allocated_tiles(), options.threads, options.cancel, [&](size_t slot, unsigned) {
      const uint32_t tile = map.tile_of_slot(slot);
      const uint32_t tx = tile % per_side, ty = tile / per_side;
      float* heights = map.slot_texels(slot);
      for (uint32_t j = 0; j < SunDepthMap::kTile; ++j)
        for (uint32_t i = 0; i < SunDepthMap::kTile; ++i) {
          const glm::dvec3 c = map.texel_centre(tx * SunDepthMap::kTile + i, ty * SunDepthMap::kTile + j);
          const Ray ray{c + above * frames[k].to_sun, -frames[k].to_sun};
          const double t = tracer.first_hit(ray);
          heights[j * SunDepthMap::kTile + i] = std::isfinite(t) ? static_cast<float>(above - t) : SunDepthMap::kNoPlant;
        }
      map.finish_tile(slot);
      rays.fetch_add(SunDepthMap::kTile * SunDepthMap::kTile, std::memory_order_relaxed);
    });
    out.rays += rays.load();
    out.bytes += map.memory_bytes();
    if (!finished) {
      out.cancelled = true;
      break;
    }
  }
  out.seconds = seconds_since(start);
  out.cpu_seconds = process_cpu_seconds() - cpu_start;
  return out;
}

Expected<SunMaps> build_sun_maps_of(const SceneGeometry& geometry, const Scene& scene, uint64_t photons,
                                    const SunMapOptions& options, std::vector<RenderPass>* passes) {
  const Clock::time_point start = Clock::now();
  const SunPhotonTracer tracer(geometry, scene.sun, options.threads);
  SunPhotonOptions po;
  po.photons = tracer.emitter().to_sun.y > 0 ? photons : 0;
  po.threads = options.threads;
  po.cancel = options.cancel;
  const SunPhotons traced = tracer.trace(po);
  if (passes)
    passes->push_back({"photons", seconds_since(start),
                       std::to_string(traced.traced) + " photons, " + std::to_string(traced.vectors.vectors.size()) +
                           " shadow vectors (the sun maps' tiles)"});
  if (traced.cancelled) {
    SunMaps out;
    out.cancelled = true;
    return out;
  }
  Expected<SunMaps> maps = build_sun_maps(tracer, traced.vectors, options);
  if (maps && passes) passes->push_back({"sun maps", maps->seconds, maps->describe()});
  return maps;
}

SunMapOptions sun_map_options_for(const Scene& scene, const RenderOptions& options) {
  SunMapOptions mo;
  mo.resolution = options.fog.map_resolution.value_or(scene.fog->map_resolution);
  mo.disc_maps = options.fog.map_directions.value_or(scene.fog->map_directions);
  mo.threads = options.threads;
  mo.cancel = options.progress.cancel_flag();
  return mo;
}

uint64_t sun_map_tile_photons(const Scene& scene, const RenderOptions& options) {
  return std::min(options.fog.photons.value_or(scene.fog->photons), kSunMapTilePhotons);
}

}  // namespace sylva
