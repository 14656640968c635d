// render.h — the GL renderer composed with what the CPU makes for it: for a fog in a cone
// mode, the sun photons and shadow cones (core/cpu/photons.h) that the GL fog pass reads.
// core/gl/ takes cones and never includes core/cpu/; front ends join the two here.
#pragma once

#include "core/gl/render_gl.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"

namespace sylva {

// The cone source render_gl asks for a fog in a cone mode: the plants skinned for the
// photons (instanced as options.geometry.instance asks), build_sun_cones with the mode's
// options (photons: options.fog.photons, else the scene fog's), its passes appended; null
// when options.progress is cancelled.
GlConeSource sun_cone_source(const Scene& scene, const RenderOptions& options);

// render_gl(scene, options, stats, sun_cone_source(scene, options)): a render with the GL
// backend as the CLI makes it, fog in every mode the GL pass draws.
RenderResult render_gl_scene(const Scene& scene, const RenderOptions& options, GlFrameStats* stats = nullptr);

}  // namespace sylva
