// height_maps.h — a scene's bark height maps as the displacement of its GS+R meshes
// (Bhagvat et al. 2009 sec. 4; tessellate.h displace), read without a texture system so that every
// backend displaces the same triangles: the CPU's mesh tracer and the GL mesh path.
//
// A height map is read once per distinct file, channel 0 of its finest level as floats
// (OpenImageIO's ImageInput; a 16-bit PNG at full precision) into HeightTexels
// (relief.h), sampled as the relief marcher samples it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/geometry/relief.h"
#include "core/geometry/tessellate.h"
#include "core/scene/scene.h"
#include "core/util/diagnostic.h"

namespace sylva {

// Channel 0 of the finest level of the image at `path`. Error: a Diagnostic for the file
// ("cannot open texture 'PATH': REASON" or "cannot read texture ...").
Expected<HeightTexels> read_height_texels(const std::string& path);

// Per plant of `scene`: the displacement of its mesh, relief_displacement of its bark's
// height map, relief_depth_m and repeats; an empty function where the plant has no height
// map or no depth. The functions share the texels they read (each file once) and may
// outlive this call. Error: read_height_texels's.
Expected<std::vector<HeightFn>> scene_displacements(const Scene& scene);

}  // namespace sylva
