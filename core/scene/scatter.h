// scatter.h — where a scene's `scatter` entry puts its plants (docs/scatter.md).
//
// Placement is Poisson-disc dart throwing: candidate positions uniform over the area's
// bounding box, kept when inside the area (a disc, or a simple polygon by the even–odd
// rule) and at least min_spacing from every plant kept before (a uniform grid of cells
// min_spacing wide: a candidate checks the 3 × 3 cells around it). At most
// 30·count + 1000 darts are thrown (a disc's faded rim keeps a dart in it with the
// probability scatter_rim_weight, drawn from a third stream so the darts stay the same); an entry that cannot fit its count is an error saying
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

// Point in polygon by the even–odd rule (a rightward ray's crossings), the slow exact
// reference: every edge.
bool inside_polygon(const std::vector<glm::dvec2>& polygon, glm::dvec2 p);

// The same test in about constant time for an outline of many corners (issue 32: 80,000
// corners made every dart test every edge): the polygon's height cut into bands, each
// listing the edges that reach into it, so a point tests only its band's edges — with the
// same arithmetic, so the answer is inside_polygon's exactly. About one band per edge,
// fewer where edges are tall, so the lists hold at most about 9 entries per edge.
class PolygonBands {
 public:
  explicit PolygonBands(const std::vector<glm::dvec2>& polygon);  // kept by reference
  bool inside(glm::dvec2 p) const;
  double mean_band_edges() const;  // the edges a point tests, on average over the bands

 private:
  uint32_t band(double y) const;
  const std::vector<glm::dvec2>& polygon_;
  double lo_ = 0, hi_ = 0, scale_ = 0;
  uint32_t bands_ = 0;
  std::vector<uint32_t> first_;  // per band, its first entry in edges_ (and one past the last)
  std::vector<uint32_t> edges_;  // edge i joins corners i − 1 and i
};

// Placement refuses a polygon whose darts would test more edges than this in all (a comb
// of 80,000 full-height teeth and a million plants), saying so, rather than run for hours.
inline constexpr double kMaxScatterEdgeTests = 2e10;

// The area of `scatter` in m² (π r², or the polygon's by the shoelace formula).
double scatter_area_m2(const SceneScatter& scatter);

// The area weighted by the density's fall at a disc's faded rim (docs/scatter.md): a disc
// of radius R faded over f has π(R² − R·f + f²/3); without a fade, scatter_area_m2.
// `density` counts plants per m² of this area, so the unfaded inside keeps that density.
double scatter_weighted_area_m2(const SceneScatter& scatter);

// The probability that a dart at `xz` inside the area is kept before the spacing test:
// 1 inside, falling linearly from 1 at fade metres inside a disc's rim to 0 at the rim.
double scatter_rim_weight(const SceneScatter& scatter, glm::dvec2 xz);

// The plants of `scatter` (its count), or why they do not fit: a Diagnostic with the
// message alone (no file or place: the scene reader reports it at the entry).
Expected<std::vector<ScatterPlacement>> place_scatter(const SceneScatter& scatter);

}  // namespace sylva
