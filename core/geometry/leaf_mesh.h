// leaf_mesh.h — a scene's leaves (docs/spec/skeleton.md "Leaves") as triangles, the one form every
// renderer and the glTF export draws them in: each placed leaf's polygon triangulated
// (ear clipping in the polygon's plane, so a concave leaf keeps its outline), flat, with
// one unit normal per leaf (Newell's: the polygon's vector area, counter-clockwise seen
// from the side it points to). A leaf is two-sided unless its material says otherwise
// (leaf_images.h): renderers turn the normal toward the viewer (or the light) and never
// cull a face. Every vertex has texture coordinates (leaf_uvs).
//
// Units and frames: world metres, Y up, double (callers re-centre before going to float).
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec2.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <span>
#include <vector>

#include "core/geometry/skeleton.h"
#include "core/util/bounds.h"

namespace sylva {

// Newell's normal of a polygon (its vector area, twice), not normalised; zero for a
// polygon without area.
glm::dvec3 polygon_newell_normal(std::span<const std::array<double, 3>> vertices);

// Triangles (indices into `vertices`, 3 per triangle, counter-clockwise around the Newell
// normal) covering a simple planar polygon: ear clipping (Eberly, "Triangulation by ear
// clipping", 2002) in the plane of the Newell normal. Ears without area (repeated or
// collinear vertices) are clipped without a triangle; a polygon that is not simple (where
// no ear is left) is finished as a fan. Empty for fewer than 3 vertices or no area.
// Cost: the ring is walked clipping ears as they come, and an ear is tested only against the
// reflex vertices in its box, found in a k-d tree — O(n log n) for a turtle's leaves, convex
// or toothed (issue 32: a 524,288-vertex leaf had taken minutes); `work`, when given,
// receives the counts (tests bound them).
struct TriangulationWork {
  uint64_t ear_tests = 0;    // vertices tried as an ear
  uint64_t point_tests = 0;  // reflex vertices in an ear's box tested against it
};
std::vector<uint32_t> triangulate_polygon(std::span<const std::array<double, 3>> vertices,
                                          TriangulationWork* work = nullptr);

// A leaf's texture coordinates (docs/leaves.md "Texture coordinates"), one (u, v) per
// vertex: v runs from the petiole (vertex 0, the one nearest to where the turtle stood at `{`) toward the tip
// (the vertex farthest from it), u across, left to right seen from the front (the side
// `normal` points to); both scaled to [0, 1] over the leaf's bounding rectangle in that
// frame, so an image drawn upright (petiole at its bottom row) covers the leaf. `normal`:
// the unit Newell normal. A leaf without extent along an axis gets 0 on it.
std::vector<glm::dvec2> leaf_uvs(std::span<const std::array<double, 3>> vertices, const glm::dvec3& normal);

// Which leaf a triangle belongs to.
struct LeafRef {
  uint32_t plant = 0;     // index into Scene::plants
  uint32_t leaf = 0;      // index into that plant's Skeleton::leaves
  uint32_t material = 0;  // the leaf's material index (its front's, when it has a back)
  uint32_t back_material = 0;  // the material seen from behind (Leaf::back_material, else `material`)
  glm::dvec3 normal{0, 0, 1};  // unit Newell normal
  // The material a ray along `direction` sees: the back's when it runs along the normal
  // (it meets the side the normal points away from).
  uint32_t material_seen_along(const glm::dvec3& direction) const {
    return back_material != material && glm::dot(direction, normal) > 0 ? back_material : material;
  }
};

// The leaves of a scene (or of one plant) as one triangle soup.
struct LeafMesh {
  std::vector<glm::dvec3> positions;    // metres; each leaf's own vertices, unshared
  std::vector<glm::dvec2> uvs;          // per position: leaf_uvs
  std::vector<uint32_t> indices;        // 3 per triangle into positions
  std::vector<uint32_t> triangle_leaf;  // per triangle: index into `leaves`
  std::vector<uint32_t> vertex_leaf;    // per position: index into `leaves` (a vertex the
                                        //   triangulation dropped included)
  std::vector<LeafRef> leaves;          // per leaf with at least one triangle

  size_t triangle_count() const { return indices.size() / 3; }
  bool empty() const { return indices.empty(); }
  Aabb bounds() const;  // the vertices' (empty_box() when there are none)
};

// Appends the leaves of `placed` (a skeleton in world space: place_plant) as plant `plant`.
void append_leaves(LeafMesh& mesh, const Skeleton& placed, uint32_t plant);

// The box of a skeleton's leaf vertices, empty_box() when it has none.
Aabb leaf_bounds(const Skeleton& skeleton);

}  // namespace sylva
