// scatter.h — where a scene's `scatter` entry puts its plants (docs/scatter.md).
//
// Placement is Poisson-disc dart throwing: candidate positions uniform over the area's
// bounding box, kept when inside the area (a disc, or a simple polygon by the even–odd
// rule) and at least min_spacing from every plant kept before (a uniform grid of cells
// min_spacing wide: a candidate checks the 3 × 3 cells around it). At most
// 30·count + 1000 darts are thrown; an entry that cannot fit its count is an error saying
// how many fit. Rotation, scale and each plant's grammar seed come from a second stream,
// drawn in placement order, so changing a range never moves a plant. Both streams are
// SplitMix64 from the entry's seed, with floats made from the top 53 bits: the same entry
// places the same plants on every machine and compiler.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec2.hpp>

#include "core/scene/scene.h"
#include "core/util/diagnostic.h"

namespace sylva {

struct ScatterPlacement {
  glm::dvec2 xz{0, 0};      // metres, on the ground
  double rotate_y_deg = 0;
  double scale = 1;
  uint64_t plant_seed = 0;  // the grammar seed of this plant
};

// The area of `scatter` in m² (π r², or the polygon's by the shoelace formula).
double scatter_area_m2(const SceneScatter& scatter);

// The plants of `scatter` (its count), or why they do not fit: a Diagnostic with the
// message alone (no file or place: the scene reader reports it at the entry).
Expected<std::vector<ScatterPlacement>> place_scatter(const SceneScatter& scatter);

}  // namespace sylva
