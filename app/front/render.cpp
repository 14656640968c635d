// render.cpp — see render.h.
#include "app/front/render.h"

#include <algorithm>
#include <memory>
#include <vector>

#include "core/cpu/photons.h"
#include "core/cpu/render_cpu.h"

namespace sylva {

GlConeSource sun_cone_source(const Scene& scene, const RenderOptions& options) {
  return [&scene, options](FogMode mode, std::vector<RenderPass>& passes) -> std::shared_ptr<const ConeSet> {
    // Plants that share a skeleton go through the photons as instances (photons.h).
    const SceneGeometry geometry = options.geometry.instance
                                       ? build_instanced_geometry(scene, options.skin, GeometryOptions{}, &passes)
                                       : build_scene_geometry(scene, options.skin, GeometryOptions{}, &passes);
    std::shared_ptr<const SunCones> cones = build_sun_cones(
        geometry, scene,
        sun_cone_options_for(mode, options.fog.photons.value_or(scene.fog->photons), options.fog.cone_params,
                             options.threads, options.progress.cancel_flag()));
    passes.insert(passes.end(), cones->passes.begin(), cones->passes.end());
    if (cones->cancelled) return nullptr;
    return std::shared_ptr<const ConeSet>(cones, &cones->cones);
  };
}

SunMaps sun_maps_for(const Scene& scene, const RenderOptions& options, std::vector<RenderPass>* passes) {
  const SceneGeometry geometry = options.geometry.instance
                                     ? build_instanced_geometry(scene, options.skin, GeometryOptions{}, passes)
                                     : build_scene_geometry(scene, options.skin, GeometryOptions{}, passes);
  Expected<SunMaps> maps = build_sun_maps_of(geometry, scene, sun_map_tile_photons(scene, options),
                                             sun_map_options_for(scene, options), passes);
  if (!maps) throw SunMapsRefused(maps.error().message);
  return std::move(*maps);
}

RenderResult render_gl_scene(const Scene& scene, const RenderOptions& options, GlFrameStats* stats) {
  if (!scene.fog || !gl_fog_walks_maps(options.fog.mode.value_or(scene.fog->mode)) || !options.fog.maps.empty())
    return render_gl(scene, options, stats, sun_cone_source(scene, options));
  std::vector<RenderPass> passes;
  const SunMaps maps = sun_maps_for(scene, options, &passes);
  if (maps.cancelled) {
    RenderResult cancelled;
    cancelled.cancelled = true;
    return cancelled;
  }
  RenderOptions with_maps = options;
  with_maps.fog.maps = maps.maps;
  RenderResult result = render_gl(scene, with_maps, stats);
  result.passes.insert(result.passes.begin(), passes.begin(), passes.end());
  return result;
}

}  // namespace sylva
