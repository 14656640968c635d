// vlab_enviro.h — vlab's environmental programs that sylva has built in (docs/cpfg.md
// "Environmental programs"): what they answer to a cpfg word's `?E` queries, given where
// the turtle met each query. Pure functions of the queries; grow.cpp finds the queries,
// places them and writes the answers back.
//
// Frame: the plant's own, metres, y up (cpfg's world frame: the turtle starts along +y, and
// sylva's left and heading agree with cpfg's). Directions need not be unit vectors.
#pragma once

#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "lsystem/grammar.h"

namespace sylva {

// A query as honda81 reads it: ?E(vigor[, index]) at `position`.
struct Honda81Query {
  glm::dvec3 position;
  double vigor = 0, index = 0;
};

// honda81 (vlab's ENVIRO/honda81, Honda 1981): 1 unless another query of the same index and
// at least this one's vigor lies within the radius (x, y, z with three_d, else x and z); then
// 0. A grid of cells one radius wide makes it O(n) (honda81 itself compares all pairs).
std::vector<double> honda81_answers(const lsys::Grammar::Honda81& spec, std::span<const Honda81Query> queries);

// A leaf cluster as chiba reads it: a ball where the turtle met ?E(r), of radius r (the
// spec's default when r <= 0).
struct ChibaBall {
  glm::dvec3 centre;
  double radius = 0;
};
struct ChibaAnswer {
  double light = 0;                    // the fraction of the sky's (or the sources') light reaching the centre
  glm::dvec3 brightest{0.0, 0.0, 0.0}; // the light-weighted mean direction, unit (zero when no light arrives)
};

// The light directions and intensities chiba samples (sum 1): the spec's sources, or the
// centres of a subdivided octahedron's triangles (Leech's sphere, as chiba's sphere.c),
// the upper ones weighted 1 and the lower `lower_to_upper`, or by the CIE overcast sky.
struct ChibaSample {
  glm::dvec3 direction;  // unit
  double intensity = 0;
};
std::vector<ChibaSample> chiba_samples(const lsys::Grammar::Chiba& spec);

// chiba (vlab's ENVIRO/chiba; Chiba et al. 1994): from each ball's centre a ray toward every
// sample; each other ball the ray meets dims it (by transmittance^(length / diameter), or
// with `estimate_area` by the share of this ball's disc the other's disc covers), and the
// answer sums the samples' dimmed intensities. Every ball the ray meets counts: a uniform
// grid walked cell by cell (Amanatides & Woo) finds them, so the answer is that of testing
// all balls (tested against it).
std::vector<ChibaAnswer> chiba_answers(const lsys::Grammar::Chiba& spec, std::span<const ChibaBall> balls);

// The dimming one ball `other` puts on a ray from `from` (the centre of a ball of radius
// `own_radius`) along the unit `direction`, as chiba's IsClusterIntersection and
// ComputeCoveredArea define it: the factor the ray's light is multiplied by (1: untouched).
double chiba_dimming(const lsys::Grammar::Chiba& spec, const glm::dvec3& from, double own_radius,
                     const glm::dvec3& direction, const ChibaBall& other);

}  // namespace sylva
