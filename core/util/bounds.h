// bounds.h — axis-aligned boxes in metres: the BVH's nodes, culling's plant and shadow
// boxes, a skeleton's extent, the fog's photon disc. An empty box has lo > hi.
#pragma once

#include <array>
#include <limits>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace sylva {

struct Aabb {
  glm::dvec3 lo{0, 0, 0};
  glm::dvec3 hi{0, 0, 0};
};

// The box that contains nothing: growing it by anything gives that thing's box.
inline Aabb empty_box() {
  const double inf = std::numeric_limits<double>::infinity();
  return {{inf, inf, inf}, {-inf, -inf, -inf}};
}

inline void grow(Aabb& box, const Aabb& other) {
  box.lo = glm::min(box.lo, other.lo);
  box.hi = glm::max(box.hi, other.hi);
}

inline void grow(Aabb& box, const glm::dvec3& p) {
  box.lo = glm::min(box.lo, p);
  box.hi = glm::max(box.hi, p);
}

// The eight corners, x varying fastest.
inline std::array<glm::dvec3, 8> corners(const Aabb& b) {
  std::array<glm::dvec3, 8> c;
  for (int i = 0; i < 8; ++i) c[i] = {i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z};
  return c;
}

}  // namespace sylva
