// skeleton_bounds.cpp — see skeleton_bounds.h.
#include "core/geometry/skeleton_bounds.h"

#include <glm/common.hpp>
#include <limits>

#include "core/geometry/leaf_mesh.h"

namespace sylva {

SkeletonBounds skeleton_bounds(const Skeleton& skeleton) {
  SkeletonBounds b;
  if (skeleton.joints.empty() && skeleton.leaves.empty()) return b;
  const double inf = std::numeric_limits<double>::infinity();
  b.lo = glm::dvec3(inf);
  b.hi = glm::dvec3(-inf);
  for (const Joint& j : skeleton.joints) {
    glm::dvec3 p(j.position_m[0], j.position_m[1], j.position_m[2]);
    b.lo = glm::min(b.lo, p - glm::dvec3(j.radius_m));
    b.hi = glm::max(b.hi, p + glm::dvec3(j.radius_m));
  }
  grow(b, leaf_bounds(skeleton));  // empty without leaves
  return b;
}

}  // namespace sylva
