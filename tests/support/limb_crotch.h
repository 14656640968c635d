// limb_crotch.h — the crotch the tests of core/geometry/crotch.h and crotch_mesh.h share: a
// trunk of radius 0.3 m with, from its middle joint, a limb at 45° (radius 0.15 m) and a
// twig at 60° on the other side (0.05 m, under a quarter of the trunk's: no crotch).
#pragma once

#include <cmath>
#include <glm/geometric.hpp>
#include <random>

#include "core/geometry/crotch.h"
#include "tests/support/skeleton_builder.h"

namespace sylva::test {

inline Skeleton limb_on_trunk() {
  Skeleton sk;
  add_chain(sk, {{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {0.3, 0.3, 0.28}, std::nullopt);
  const double s = std::sqrt(0.5);
  add_chain(sk, {{0, 1, 0}, {1.2 * s, 1 + 1.2 * s, 0}}, {0.15, 0.12}, ChainParent{0, 1});
  add_chain(sk, {{0, 1, 0}, {-0.8 * std::sin(1.047), 1 + 0.8 * std::cos(1.047), 0}}, {0.05, 0.04}, ChainParent{0, 1});
  return sk;
}

// The limb's crotch, skinned smooth.
struct LimbCrotch {
  Skeleton skeleton = limb_on_trunk();
  SkinnedSkeleton skinned = skin_skeleton(skeleton);
  Crotch crotch = find_crotches(skeleton, skinned.frusta).at(0);
};

inline glm::dvec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return glm::normalize(glm::dvec3(n(rng), n(rng), n(rng)));
}

}  // namespace sylva::test
