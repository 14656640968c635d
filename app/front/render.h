// render.h — the GL renderer composed with what the CPU makes for it: for a fog in a cone
// mode, the sun photons and shadow cones (core/cpu/photons.h) that the GL fog pass reads;
// for mode map, the sun maps (core/cpu/sun_maps.h). core/gl/ takes cones and maps and never
// includes core/cpu/; front ends join the two here.
#pragma once

#include <vector>

#include "core/cpu/sun_maps.h"
#include "core/gl/render_gl.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"

namespace sylva {

// The cone source render_gl asks for a fog in a cone mode: the plants skinned for the
// photons (instanced as options.geometry.instance asks), build_sun_cones with the mode's
// options (photons: options.fog.photons, else the scene fog's), its passes appended; null
// when options.progress is cancelled.
GlConeSource sun_cone_source(const Scene& scene, const RenderOptions& options);

// Mode map's sun maps for `scene`'s plants and sun as render_cpu builds them (resolution and
// directions: options.fog's, else the scene fog's; photons to find the tiles: the fog's, at
// most kSunMapTilePhotons), its passes appended to *passes. Throws SunMapsRefused over the
// memory bound; `cancelled` set when options.progress is.
SunMaps sun_maps_for(const Scene& scene, const RenderOptions& options, std::vector<RenderPass>* passes);

// render_gl(scene, options, stats, sun_cone_source(scene, options)): a render with the GL
// backend as the CLI makes it, fog in every mode the GL pass draws (mode map, and auto, which
// is map on the GL backend: with the maps of sun_maps_for, unless options.fog.maps brings them).
RenderResult render_gl_scene(const Scene& scene, const RenderOptions& options, GlFrameStats* stats = nullptr);

}  // namespace sylva
