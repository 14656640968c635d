// bvh.h — a bounding volume hierarchy over skinned frusta (skin.h), the acceleration
// structure of the CPU ray caster.
//
// Build: binned SAH (Wald 2007, "On fast construction of SAH-based bounding volume
// hierarchies"): 16 bins along the widest centroid axis, leaves of at most
// kBvhMaxLeafSize frusta, a median split when all centroids coincide. Each frustum is
// bounded by the box of its bounding pyramid's 8 vertices (skin.h, sec. 2.6), which holds
// the whole cut frustum and its caps.
//
// Layout: a flat array of 32-byte nodes in depth-first order: an interior node's left
// child is the next node, its right child is at `right_or_first`. Boxes are stored in
// float, rounded outward (so they stay conservative at coordinates of 1e6 m) and tested
// against the ray in double.
//
// Queries: nearest hit and any hit (shadow rays), iterative with a fixed stack of
// kBvhStackSize entries (the build limits the depth so it cannot overflow), each leaf
// calling intersect_frustum (ray_frustum.h). Results are identical to testing every
// frustum (tests/cpu/bvh_test.cpp): same nearest t, same frustum up to ties.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <span>
#include <vector>

#include "core/geometry/ray_frustum.h"
#include "core/util/bounds.h"
#include "core/geometry/skin.h"

namespace sylva {

inline constexpr uint32_t kBvhMaxLeafSize = 4;  // frusta per leaf at most (unless depth-capped)
inline constexpr uint32_t kBvhStackSize = 64;   // traversal stack entries; depth < this

// One node: 32 bytes. count > 0: a leaf of frusta order[right_or_first .. + count);
// count == 0: interior, left child = this index + 1, right child = right_or_first.
struct BvhNode {
  float lo[3];
  uint32_t right_or_first;
  float hi[3];
  uint32_t count;
};
static_assert(sizeof(BvhNode) == 32, "BvhNode is documented as 32 bytes");

struct Bvh {
  std::vector<BvhNode> nodes;   // nodes[0] is the root (empty when there are no frusta)
  std::vector<uint32_t> order;  // leaf ranges index this; values index the frustum array
  uint32_t depth = 0;           // deepest node (root = 1)
};

// The box around a frustum: its bounding pyramid's vertices, grown by a hair so that
// rounding cannot put a surface point outside.
Aabb frustum_bounds(const FrustumShape& shape);

// Builds the BVH over `frusta` (any count, including 0). Deterministic.
Bvh build_bvh(std::span<const Frustum> frusta);

// A hit and the frustum it belongs to (index into the array the BVH was built over).
struct BvhHit {
  FrustumHit hit;          // hit.kind == none: no hit
  uint32_t frustum = 0;    // valid only on a hit
  bool hit_any() const { return hit.hit(); }
};

// The nearest hit with t in (t_min, t_max) over all frusta. `frusta` must be the array
// the BVH was built over.
BvhHit intersect_nearest(const Bvh& bvh, std::span<const Frustum> frusta, const Ray& ray,
                         double t_min, double t_max);

// Whether anything is hit with t in (t_min, t_max): stops at the first hit found.
bool intersect_any(const Bvh& bvh, std::span<const Frustum> frusta, const Ray& ray,
                   double t_min, double t_max);

}  // namespace sylva
