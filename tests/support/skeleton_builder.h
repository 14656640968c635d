// skeleton_builder.h — skeletons written by hand in tests: a joint at a point, a chain
// through points (metres, Y up) attached to a parent joint. Geometry only, so every room's
// tests may use it.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <optional>
#include <vector>

#include "core/geometry/skeleton.h"

namespace sylva::test {

inline Joint joint_at(glm::dvec3 p, double radius) { return Joint{{p.x, p.y, p.z}, radius, 0}; }

// Appends a chain through `points` with `radii`, attached to `parent`.
inline void add_chain(Skeleton& sk, const std::vector<glm::dvec3>& points, const std::vector<double>& radii,
                      std::optional<ChainParent> parent) {
  const auto first = static_cast<uint32_t>(sk.joints.size());
  for (size_t i = 0; i < points.size(); ++i) sk.joints.push_back(joint_at(points[i], radii[i]));
  sk.chains.push_back(Chain{first, static_cast<uint32_t>(points.size()), parent});
}

}  // namespace sylva::test
