// sun_maps.h — the sun-space depth maps of fog mode `map` (docs/spec/fog.md; docs/fog-map.md),
// built once per (plants, sun) like the photons and cones, and reused by every camera,
// frame and seed.
//
// One map per direction of the sun's disc (a point sun: one, toward its centre; a disc:
// `disc_maps` directions spread evenly over it, a Vogel spiral r = α·√((k + ½)/K), φ = k·golden
// angle), each a SunDepthMap (core/light/sun_map.h) over the photon emitter's disc (the
// plants' bounding sphere seen from the sun), `resolution` texels a side. A texel's
// height comes from one sun ray through its centre, traced through the same plants as the
// photons (SunPhotonTracer::first_hit: exact frusta and leaves, instances included).
//
// Only tiles that may hold a plant are allocated and traced: those the photon pass's shadow
// vectors fall in (each vector projected along the map's direction), grown by
// `dilate_tiles` tiles on every side, so a plant part between photons (vectors lie
// `spacing` apart: 14 cm at 10⁵ photons on the pine stand) still gets its texels. Elsewhere
// the map says "lit", which is what a plant no photon met would give in the cone modes too.
//
// Memory: 4 KiB a tile (32 × 32 floats) and 12 bytes of index per tile of the grid; a build
// that would exceed `memory_limit_bytes` is refused before anything is allocated (the
// message names what it needs).
#pragma once

#include <atomic>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/cpu/photons.h"
#include "core/light/sun_map.h"
#include "core/util/diagnostic.h"

namespace sylva {

// The memory bound of docs/spec/fog.md's `map` (the resolution's and the directions'
// defaults are the scene's, Fog in core/scene/scene.h; docs/fog-map.md says how they were chosen).
constexpr uint64_t kSunMapDefaultMemoryLimit = 64ull << 20;

struct SunMapOptions {
  uint32_t resolution = Fog{}.map_resolution;  // texels a side: a multiple of 32 in
                                               // [kFogMinMapResolution, kFogMaxMapResolution]
  uint32_t disc_maps = Fog{}.map_directions;   // directions of a disc sun; a point sun has one
  uint32_t dilate_tiles = 1;
  uint64_t memory_limit_bytes = kSunMapDefaultMemoryLimit;
  unsigned threads = 0;     // 0: every core
  const std::atomic<bool>* cancel = nullptr;
};

// What render_cpu throws when build_sun_maps refuses the scene's or the flags' maps (over
// the memory bound, before anything was allocated): bad input, not a fault (exit 1).
struct SunMapsRefused : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct SunMaps {
  std::vector<SunDepthMap> maps;  // one per disc direction
  uint64_t rays = 0;              // texel rays traced (allocated texels)
  size_t bytes = 0;               // memory of every map
  double seconds = 0, cpu_seconds = 0;  // the build: wall, and CPU of the process
  bool cancelled = false;
  // "4 maps of 4096², 1811 of 16384 tiles each on average, 29.8 MiB, 7.4 M texel rays".
  std::string describe() const;
};

// The photons that find the tiles of mode map's maps: the scene's `photons`, at most this many
// (measured on the pine stand: 10⁴, 10⁵ and 10⁶ give the same image, docs/fog-map.md).
constexpr uint64_t kSunMapTilePhotons = 100'000;

// The options `options` and `scene`'s fog ask for (resolution and directions: the flags', else
// the fog's; threads and cancellation: the render's), and the photons that find the tiles
// (the fog's photons, at most kSunMapTilePhotons): what render_cpu and the GL front end build.
SunMapOptions sun_map_options_for(const Scene& scene, const RenderOptions& options);
uint64_t sun_map_tile_photons(const Scene& scene, const RenderOptions& options);

// The directions of the maps for a sun toward unit `to_sun` of angular radius `radius_rad`
// (0: one, the centre).
std::vector<glm::dvec3> sun_map_directions(const glm::dvec3& to_sun, double radius_rad, uint32_t disc_maps);

// The maps of the plants `tracer` holds under its sun, allocated where `vectors` (that
// tracer's photons) fall. Errors (without a location: the caller adds it): a resolution
// that is not a multiple of 32 in range, or a build over the memory limit.
Expected<SunMaps> build_sun_maps(const SunPhotonTracer& tracer, const ShadowVectors& vectors,
                                 const SunMapOptions& options);

// Everything mode map needs for `geometry`'s plants under `scene`'s sun: the photon tracer,
// `photons` photons (seed 0) to find the tiles, and the maps; appends the passes "photons"
// and "sun maps" to *passes (may be null). A sun at or below the horizon, or no plants:
// no maps (the fog then has no sunlight to shadow, or nothing shadows it).
Expected<SunMaps> build_sun_maps_of(const SceneGeometry& geometry, const Scene& scene, uint64_t photons,
                                    const SunMapOptions& options, std::vector<RenderPass>* passes);

}  // namespace sylva
