// leaf_mesh.cpp — see leaf_mesh.h. Ear clipping: D. Eberly, "Triangulation by Ear
// Clipping" (Geometric Tools, 2002), with the reflex vertices in a k-d tree (as mapbox's
// earcut keeps them on a z-order curve) so that an ear asks only its neighbourhood.
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

namespace {

// The polygon's reflex vertices — bending inward by however little: a vertex too flat to
// make an ear still blocks one (the only ones that can lie in an ear of a simple polygon:
// Eberly §2; clipping only ever makes a vertex more convex) in a static 2D k-d tree with a
// count of the live ones below each node: an ear asks the tree for the live vertices in its
// box, O(log n + k), and a vertex that is clipped or has turned convex leaves it in O(log n).
class ReflexTree {
 public:
  ReflexTree(const std::vector<Point2>& p, std::vector<uint32_t> members) : p_(p), items_(std::move(members)) {
    size_t nodes = 1;
    while (nodes < 2 * std::max<size_t>(items_.size(), 1) / kLeaf + 2) nodes *= 2;
    nodes_.resize(2 * nodes);
    slot_.assign(p.size(), kAbsent);
    if (!items_.empty()) build(0, 0, items_.size(), 0);
    for (size_t i = 0; i < items_.size(); ++i) slot_[items_[i]] = static_cast<uint32_t>(i);
  }

  // Calls test(v) for each live member v inside the box [lo, hi] until one returns true; a
  // member for which live(v) is false is removed as met.
  template <class Live, class Test>
  bool any_in(const Point2& lo, const Point2& hi, Live&& live, Test&& test) {
    return any_in(0, 0, items_.size(), lo, hi, live, test);
  }

  bool contains(uint32_t v) const { return slot_[v] != kAbsent; }

  void remove(uint32_t v) {
    if (slot_[v] == kAbsent) return;
    const size_t at = slot_[v];
    slot_[v] = kAbsent;
    size_t node = 0, begin = 0, end = items_.size();
    for (;;) {
      --nodes_[node].live;
      if (end - begin <= kLeaf) return;
      const size_t mid = (begin + end) / 2;
      if (at < mid) {
        end = mid, node = 2 * node + 1;
      } else {
        begin = mid, node = 2 * node + 2;
      }
    }
  }

 private:
  static constexpr size_t kLeaf = 8;
  static constexpr uint32_t kAbsent = UINT32_MAX;
  struct Node {
    Point2 lo{}, hi{};
    uint32_t live = 0;
  };

  void build(size_t node, size_t begin, size_t end, int axis) {
    Node& n = nodes_[node];
    n.live = static_cast<uint32_t>(end - begin);
    n.lo = n.hi = p_[items_[begin]];
    for (size_t i = begin; i < end; ++i) {
      const Point2& q = p_[items_[i]];
      n.lo = {std::min(n.lo.x, q.x), std::min(n.lo.y, q.y)};
      n.hi = {std::max(n.hi.x, q.x), std::max(n.hi.y, q.y)};
    }
    if (end - begin <= kLeaf) return;
    const size_t mid = (begin + end) / 2;
    auto first = items_.begin();
    std::nth_element(first + static_cast<std::ptrdiff_t>(begin), first + static_cast<std::ptrdiff_t>(mid),
                     first + static_cast<std::ptrdiff_t>(end), [&](uint32_t a, uint32_t b) {
                       return axis == 0 ? p_[a].x < p_[b].x : p_[a].y < p_[b].y;
                     });
    build(2 * node + 1, begin, mid, 1 - axis);
    build(2 * node + 2, mid, end, 1 - axis);
  }

  template <class Live, class Test>
  bool any_in(size_t node, size_t begin, size_t end, const Point2& lo, const Point2& hi, Live& live, Test& test) {
    const Node& n = nodes_[node];
    if (n.live == 0 || n.hi.x < lo.x || n.lo.x > hi.x || n.hi.y < lo.y || n.lo.y > hi.y) return false;
    if (end - begin <= kLeaf) {
      for (size_t i = begin; i < end; ++i) {
        const uint32_t v = items_[i];
        if (slot_[v] == kAbsent) continue;
        if (!live(v)) {
          remove(v);
          continue;
        }
        if (test(v)) return true;
      }
      return false;
    }
    const size_t mid = (begin + end) / 2;
    return any_in(2 * node + 1, begin, mid, lo, hi, live, test) || any_in(2 * node + 2, mid, end, lo, hi, live, test);
  }

  const std::vector<Point2>& p_;
  std::vector<uint32_t> items_;  // the members, in k-d order
  std::vector<Node> nodes_;      // heap order: node k's children are 2k + 1 and 2k + 2
  std::vector<uint32_t> slot_;   // per vertex: its place in items_, kAbsent when not (or no longer) in
};

}  // namespace

std::vector<uint32_t> triangulate_polygon(std::span<const std::array<double, 3>> vertices, TriangulationWork* work) {
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
  // The ring as a doubly linked list; `area` is a vertex's doubled turn with its neighbours.
  std::vector<uint32_t> prev(n), next(n);
  for (uint32_t v = 0; v < n; ++v) {
    prev[v] = static_cast<uint32_t>((v + n - 1) % n);
    next[v] = static_cast<uint32_t>((v + 1) % n);
  }
  std::vector<char> alive(n, 1);
  auto area = [&](uint32_t v) { return orient(p[prev[v]], p[v], p[next[v]]); };
  std::vector<uint32_t> reflex;
  for (uint32_t v = 0; v < n; ++v)
    if (area(v) < 0) reflex.push_back(v);
  ReflexTree tree(p, std::move(reflex));
  // Vertices that turn reflex later: only next to a dropped vertex without area (|turn| ≤
  // flat) that bent inward, or in a polygon that is not simple; few, so tested one by one.
  std::vector<uint32_t> late;
  TriangulationWork count;
  // No reflex vertex of the ring other than a, b, c in the counter-clockwise triangle abc.
  auto empty = [&](uint32_t a, uint32_t b, uint32_t c) {
    const Point2 lo{std::min({p[a].x, p[b].x, p[c].x}), std::min({p[a].y, p[b].y, p[c].y})};
    const Point2 hi{std::max({p[a].x, p[b].x, p[c].x}), std::max({p[a].y, p[b].y, p[c].y})};
    auto live = [&](uint32_t q) { return alive[q] && area(q) < 0; };
    auto inside = [&](uint32_t q) {
      ++count.point_tests;
      return q != a && q != b && q != c && in_triangle(p[q], p[a], p[b], p[c]);
    };
    for (size_t i = 0; i < late.size();) {
      if (!live(late[i])) {
        late[i] = late.back(), late.pop_back();
        continue;
      }
      if (inside(late[i++])) return false;
    }
    return !tree.any_in(lo, hi, live, inside);
  };
  auto unlink = [&](uint32_t v) {
    const uint32_t a = prev[v], c = next[v];
    next[a] = c, prev[c] = a, alive[v] = 0;
    tree.remove(v);
    for (uint32_t u : {a, c})
      if (area(u) < 0 && !tree.contains(u) && std::find(late.begin(), late.end(), u) == late.end())
        late.push_back(u);
  };
  // Walk the ring clipping ears as they come (Eberly's ear list, found lazily); a full turn
  // without a clip means no ear is left: not simple.
  constexpr uint32_t kNone = UINT32_MAX;
  size_t m = n, since = 0;
  uint32_t v = 0, skipped = kNone;
  while (m > 3) {
    if (since >= m) {  // not simple: finish as a fan
      for (uint32_t w = next[v]; next[w] != v; w = next[w]) out.insert(out.end(), {v, w, next[w]});
      if (work) *work = count;
      return out;
    }
    ++count.ear_tests;
    const uint32_t a = prev[v], c = next[v];
    const double turn = orient(p[a], p[v], p[c]);
    if (std::abs(turn) <= flat) {  // no area: drop the vertex, emit nothing
      unlink(v);
      v = c, skipped = kNone;
    } else if (turn > 0 && empty(a, v, c)) {
      out.insert(out.end(), {a, v, c});
      unlink(v);
      // Try past c first (as earcut does): a convex run is then halved pass by pass into
      // triangles of fair shape, not fanned from one vertex into slivers. Where that is no
      // ear, c is next (a strip is zipped up from its end, not walked round once per ear).
      skipped = c, v = next[c];
    } else if (skipped != kNone) {
      v = skipped, skipped = kNone;
      continue;
    } else {
      v = c, ++since;
      continue;
    }
    --m, since = 0;
  }
  const uint32_t a = prev[v], c = next[v];
  if (std::abs(orient(p[a], p[v], p[c])) > flat) out.insert(out.end(), {a, v, c});
  if (work) *work = count;
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
    mesh.leaves.push_back({plant, l, leaf.material, leaf.back_material.value_or(leaf.material), normal});
  }
}

Aabb leaf_bounds(const Skeleton& skeleton) {
  Aabb box = empty_box();
  for (const Leaf& leaf : skeleton.leaves)
    for (const auto& v : leaf.vertices_m) grow(box, glm::dvec3(v[0], v[1], v[2]));
  return box;
}

}  // namespace sylva
