// skeleton_bounds.h — the box a skeleton occupies: its joints grown by their radii and its
// leaves' vertices (metres, the skeleton's frame). Framing cameras (scene.h), culling, the
// fillets' coarsest cell (crotch_mesh.h) and `sylva grow`'s summary all measure a plant by it.
#pragma once

#include "core/geometry/skeleton.h"
#include "core/util/bounds.h"

namespace sylva {

using SkeletonBounds = Aabb;
// empty_box() for a skeleton with no joints and no leaves.
SkeletonBounds skeleton_bounds(const Skeleton& skeleton);

}  // namespace sylva
