// leaf_mesh.cpp — see leaf_mesh.h. Ear clipping: D. Eberly, "Triangulation by Ear
// Clipping" (Geometric Tools, 2002), O(n²) per polygon, ample for a turtle's leaves.
#include "core/geometry/leaf_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <glm/geometric.hpp>

#include "core/geometry/skin.h"  // axis_frame

namespace sylva {

glm::dvec3 polygon_newell_normal(std::span<const std::array<double, 3>> vertices) {
  glm::dvec3 n(0);
  for (size_t v = 0; v < vertices.size(); ++v) {
    const auto& a = vertices[v];
    const auto& b = vertices[(v + 1) % vertices.size()];
    n.x += (a[1] - b[1]) * (a[2] + b[2]);
    n.y += (a[2] - b[2]) * (a[0] + b[0]);
    n.z += (a[0] - b[0]) * (a[1] + b[1]);
  }
  return n;
}

namespace {

struct Point2 {
  double x, y;
};

double orient(const Point2& a, const Point2& b, const Point2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// p inside or on the boundary of the counter-clockwise triangle abc.
bool in_triangle(const Point2& p, const Point2& a, const Point2& b, const Point2& c) {
  return orient(a, b, p) >= 0 && orient(b, c, p) >= 0 && orient(c, a, p) >= 0;
}

}  // namespace

std::vector<uint32_t> triangulate_polygon(std::span<const std::array<double, 3>> vertices) {
  std::vector<uint32_t> out;
  const size_t n = vertices.size();
  if (n < 3) return out;
  const glm::dvec3 newell = polygon_newell_normal(vertices);
  const double length = glm::length(newell);
  if (!(length > 0)) return out;
  // Coordinates in the plane, relative to the first vertex: e0 × e1 = the normal, so the
  // polygon runs counter-clockwise (positive area) in (e0, e1).
  const AxisFrame frame = axis_frame(newell / length);
  const glm::dvec3 origin(vertices[0][0], vertices[0][1], vertices[0][2]);
  std::vector<Point2> p(n);
  double extent = 0;
  for (size_t v = 0; v < n; ++v) {
    const glm::dvec3 d = glm::dvec3(vertices[v][0], vertices[v][1], vertices[v][2]) - origin;
    p[v] = {glm::dot(d, frame.e0), glm::dot(d, frame.e1)};
    extent = std::max({extent, std::abs(p[v].x), std::abs(p[v].y)});
  }
  const double flat = 1e-12 * extent * extent;  // an ear with less (doubled) area has none
  std::vector<uint32_t> ring(n);
  for (size_t v = 0; v < n; ++v) ring[v] = static_cast<uint32_t>(v);
  while (ring.size() > 3) {
    const size_t m = ring.size();
    bool clipped = false;
    for (size_t i = 0; i < m && !clipped; ++i) {
      const uint32_t a = ring[(i + m - 1) % m], b = ring[i], c = ring[(i + 1) % m];
      const double area = orient(p[a], p[b], p[c]);
      if (std::abs(area) <= flat) {  // no area: drop the vertex, emit nothing
        ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
        clipped = true;
        break;
      }
      if (area < 0) continue;  // reflex
      bool empty = true;
      for (size_t k = 0; k < m && empty; ++k) {
        const uint32_t q = ring[k];
        if (q == a || q == b || q == c) continue;
        empty = !in_triangle(p[q], p[a], p[b], p[c]);
      }
      if (!empty) continue;
      out.insert(out.end(), {a, b, c});
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
      clipped = true;
    }
    if (!clipped) {  // not simple: finish as a fan
      for (size_t i = 1; i + 1 < ring.size(); ++i) out.insert(out.end(), {ring[0], ring[i], ring[i + 1]});
      return out;
    }
  }
  if (std::abs(orient(p[ring[0]], p[ring[1]], p[ring[2]])) > flat) out.insert(out.end(), {ring[0], ring[1], ring[2]});
  return out;
}

std::vector<glm::dvec2> leaf_uvs(std::span<const std::array<double, 3>> vertices, const glm::dvec3& normal) {
  std::vector<glm::dvec2> uv(vertices.size(), glm::dvec2(0));
  if (vertices.empty()) return uv;
  const glm::dvec3 base(vertices[0][0], vertices[0][1], vertices[0][2]);
  // The tip: the vertex farthest from the petiole, the first of those within 1e-9 of the
  // farthest distance, so that vertices equally far (a symmetric leaf) are told apart by
  // their order and not by the rounding of a placement (a turned copy keeps its tip).
  std::vector<glm::dvec3> in_plane(vertices.size());
  double farthest = 0;
  for (size_t i = 0; i < vertices.size(); ++i) {
    const glm::dvec3 d = glm::dvec3(vertices[i][0], vertices[i][1], vertices[i][2]) - base;
    in_plane[i] = d - glm::dot(d, normal) * normal;
    farthest = std::max(farthest, glm::length(in_plane[i]));
  }
  if (!(farthest > 0)) return uv;
  glm::dvec3 along(0);
  for (const glm::dvec3& d : in_plane)
    if (const double l = glm::length(d); l >= farthest * (1 - 1e-9)) {
      along = d / l;
      break;
    }
  // Seen from the front (normal toward the viewer, v up), u grows to the right: v × n.
  const glm::dvec3 across = glm::normalize(glm::cross(along, normal));
  glm::dvec2 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < vertices.size(); ++i) {
    const glm::dvec3 d = glm::dvec3(vertices[i][0], vertices[i][1], vertices[i][2]) - base;
    uv[i] = {glm::dot(d, across), glm::dot(d, along)};
    lo = glm::min(lo, uv[i]), hi = glm::max(hi, uv[i]);
  }
  const glm::dvec2 extent = hi - lo;
  for (glm::dvec2& t : uv)
    t = {extent.x > 0 ? std::clamp((t.x - lo.x) / extent.x, 0.0, 1.0) : 0.0,
         extent.y > 0 ? std::clamp((t.y - lo.y) / extent.y, 0.0, 1.0) : 0.0};
  return uv;
}

Aabb LeafMesh::bounds() const {
  Aabb box = empty_box();
  for (const glm::dvec3& q : positions) grow(box, q);
  return box;
}

void append_leaves(LeafMesh& mesh, const Skeleton& placed, uint32_t plant) {
  for (uint32_t l = 0; l < placed.leaves.size(); ++l) {
    const Leaf& leaf = placed.leaves[l];
    const std::vector<uint32_t> triangles = triangulate_polygon(leaf.vertices_m);
    if (triangles.empty()) continue;
    const glm::dvec3 newell = polygon_newell_normal(leaf.vertices_m);
    const glm::dvec3 normal = newell / glm::length(newell);
    const std::vector<glm::dvec2> uv = leaf_uvs(leaf.vertices_m, normal);
    mesh.uvs.insert(mesh.uvs.end(), uv.begin(), uv.end());
    const uint32_t first = static_cast<uint32_t>(mesh.positions.size());
    const uint32_t index = static_cast<uint32_t>(mesh.leaves.size());
    for (const auto& v : leaf.vertices_m) mesh.positions.emplace_back(v[0], v[1], v[2]);
    for (uint32_t i : triangles) mesh.indices.push_back(first + i);
    mesh.triangle_leaf.insert(mesh.triangle_leaf.end(), triangles.size() / 3, index);
    mesh.vertex_leaf.insert(mesh.vertex_leaf.end(), leaf.vertices_m.size(), index);
    mesh.leaves.push_back({plant, l, leaf.material, normal});
  }
}

Aabb leaf_bounds(const Skeleton& skeleton) {
  Aabb box = empty_box();
  for (const Leaf& leaf : skeleton.leaves)
    for (const auto& v : leaf.vertices_m) grow(box, glm::dvec3(v[0], v[1], v[2]));
  return box;
}

}  // namespace sylva
