// plant_mesh.h — the polygon baseline of one plant (Bhagvat et al. 2009 sec. 4: GS and GS+R), built
// the same way for every path that draws meshes: the CPU's MeshTracer (core/cpu/) and
// GL's GlMesh (core/gl/).
#pragma once

#include <span>

#include "core/geometry/crotch.h"
#include "core/geometry/skin.h"
#include "core/geometry/tessellate.h"

namespace sylva {

// One plant's GS mesh as every mesh path builds it (the CPU's MeshTracer here, GL's
// GlMesh): `skinned` tessellated with `tessellation`, then, where `height` is set
// (height_function_for), displaced by it (GS+R) as deep as the relief shell is thick —
// relief.h's min(relief_depth_m, max_depth_per_radius·r) at each end of a vertex's
// frustum, linear between — so that GS+R lifts a twig or needle no more than the relief
// marcher's shell does. The bark is the wood's (material 0): vertices of other materials'
// frusta are not displaced. `crotches` (find_crotches of `skinned`, where its skin blends
// them): the displacement fades into the fillets as the marcher's relief does (crotch.h
// crotch_relief_fade at each vertex of a crotch's frusta, before it moves). Adds the
// seconds spent to *tessellate_s and *displace_s.
TriangleMesh plant_mesh(const SkinnedSkeleton& skinned, const TessellateOptions& tessellation, const HeightFn& height,
                        double relief_depth_m, double max_depth_per_radius, double* tessellate_s, double* displace_s,
                        std::span<const Crotch> crotches = {});

}  // namespace sylva
