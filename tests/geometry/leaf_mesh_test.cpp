// leaf_mesh_test.cpp — leaves as triangles: ear clipping keeps a concave outline, every
// triangle turns as the polygon does, a placed plant's leaves move with it.
#include "core/geometry/leaf_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <glm/geometric.hpp>
#include <vector>


namespace sylva {
namespace {

using Polygon = std::vector<std::array<double, 3>>;

glm::dvec3 at(const Polygon& p, uint32_t i) { return {p[i][0], p[i][1], p[i][2]}; }

// Sum of the triangles' vector areas (twice), and whether each turns along `normal`.
glm::dvec3 doubled_area(const Polygon& p, const std::vector<uint32_t>& t, const glm::dvec3& normal) {
  glm::dvec3 sum(0);
  for (size_t k = 0; k < t.size(); k += 3) {
    const glm::dvec3 a = glm::cross(at(p, t[k + 1]) - at(p, t[k]), at(p, t[k + 2]) - at(p, t[k]));
    EXPECT_GT(glm::dot(a, normal), 0) << "triangle " << k / 3 << " turns the other way";
    sum += a;
  }
  return sum;
}

TEST(LeafMesh, EarClippingCoversAConcaveLeafExactly) {
  // An L of area 3 in the plane y = 1, counter-clockwise seen from +y (x, then −z).
  const Polygon l = {{0, 1, 0}, {2, 1, 0}, {2, 1, -1}, {1, 1, -1}, {1, 1, -2}, {0, 1, -2}};
  const std::vector<uint32_t> t = triangulate_polygon(l);
  ASSERT_EQ(t.size(), 3u * 4u);  // n − 2 triangles
  const glm::dvec3 n = polygon_newell_normal(l);
  EXPECT_NEAR(n.y, 6, 1e-12);  // twice the area, along +y
  const glm::dvec3 sum = doubled_area(l, t, n);
  EXPECT_NEAR(sum.y, 6, 1e-12);  // no overlap, no gap: the concave corner is not bridged
}

TEST(LeafMesh, ALeafsUvRunFromPetioleToTipAndAcrossOverItsBox) {
  // A kite in the plane z = 2, seen from +z (its Newell normal): petiole at the origin, tip
  // 3 m up +y, the widest points at y = 1, x = -1 (left) and x = +0.5 (right).
  const Polygon kite = {{0, 0, 2}, {0.5, 1, 2}, {0, 3, 2}, {-1, 1, 2}};
  const glm::dvec3 n = glm::normalize(polygon_newell_normal(kite));
  ASSERT_NEAR(n.z, 1, 1e-12);
  const std::vector<glm::dvec2> uv = leaf_uvs(kite, n);
  ASSERT_EQ(uv.size(), 4u);
  EXPECT_NEAR(uv[0].y, 0, 1e-12);  // the petiole: v = 0
  EXPECT_NEAR(uv[2].y, 1, 1e-12);  // the tip: v = 1
  EXPECT_NEAR(uv[1].y, 1.0 / 3, 1e-12);
  // Seen from the front with v up, u grows to the right: x = -1 is u = 0, x = 0.5 is u = 1.
  EXPECT_NEAR(uv[3].x, 0, 1e-12);
  EXPECT_NEAR(uv[1].x, 1, 1e-12);
  EXPECT_NEAR(uv[0].x, 2.0 / 3, 1e-12);
  // The same kite turned over (seen from −z) mirrors u, keeps v.
  const Polygon back = {kite[0], kite[3], kite[2], kite[1]};
  const std::vector<glm::dvec2> mirrored = leaf_uvs(back, -n);
  EXPECT_NEAR(mirrored[1].x, 1 - 0, 1e-12);  // x = -1 (back[1]) is now on the right
  EXPECT_NEAR(mirrored[3].x, 0, 1e-12);
  EXPECT_NEAR(mirrored[2].y, 1, 1e-12);
  // append_leaves stores one uv per position, the same.
  Skeleton sk;
  sk.leaves.push_back({std::nullopt, 1, kite, std::nullopt});
  LeafMesh mesh;
  append_leaves(mesh, sk, 0);
  ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
  for (size_t i = 0; i < uv.size(); ++i) {
    EXPECT_EQ(mesh.uvs[i].x, uv[i].x);
    EXPECT_EQ(mesh.uvs[i].y, uv[i].y);
  }
}

TEST(LeafMesh, RepeatedAndCollinearVerticesAddNoTriangleWithoutArea) {
  // A unit square with a repeated corner and a vertex in the middle of its top edge.
  const Polygon square = {{0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0.5, 1, 0}, {0, 1, 0}};
  const std::vector<uint32_t> t = triangulate_polygon(square);
  EXPECT_LE(t.size(), 3u * 3u);  // doubled_area fails any triangle without area
  EXPECT_NEAR(doubled_area(square, t, {0, 0, 1}).z, 2, 1e-12);
  EXPECT_TRUE(triangulate_polygon(Polygon{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}).empty());
}

// Polygons in the plane z = 0 (counter-clockwise seen from +z) with many reflex vertices.
Polygon star(size_t n, uint32_t seed) {  // random radii about the origin, angles in order
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> radius(0.2, 1.0);
  Polygon p;
  for (size_t i = 0; i < n; ++i) {
    const double a = 2 * M_PI * static_cast<double>(i) / static_cast<double>(n), r = radius(rng);
    p.push_back({r * std::cos(a), r * std::sin(a), 0});
  }
  return p;
}
Polygon comb(size_t teeth) {  // a base bar with `teeth` deep teeth above it
  Polygon p;
  p.push_back({0, 0, 0});
  p.push_back({2.0 * static_cast<double>(teeth), 0, 0});
  for (size_t k = teeth; k-- > 0;) {
    const double x = 2.0 * static_cast<double>(k);
    p.push_back({x + 1.5, 1, 0});
    p.push_back({x + 1.5, 10, 0});
    p.push_back({x + 0.5, 10, 0});
    p.push_back({x + 0.5, 1, 0});
  }
  return p;
}
Polygon spiral(size_t n) {  // a thick spiral strip: out along one arm, back along the other
  Polygon p;
  const size_t half = n / 2;
  for (size_t i = 0; i < half; ++i) {
    const double t = 6 * M_PI * static_cast<double>(i) / static_cast<double>(half);
    p.push_back({(1 + t) * std::cos(t), (1 + t) * std::sin(t), 0});
  }
  for (size_t i = half; i-- > 0;) {
    const double t = 6 * M_PI * static_cast<double>(i) / static_cast<double>(half);
    p.push_back({(2 + t) * std::cos(t), (2 + t) * std::sin(t), 0});
  }
  std::reverse(p.begin(), p.end());  // counter-clockwise: the strip to the left of the way
  return p;
}

// Whether segments pq and rs cross at a point inside both (not at an end).
bool properly_cross(const glm::dvec3& p, const glm::dvec3& q, const glm::dvec3& r, const glm::dvec3& s) {
  auto side = [](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  };
  const double d1 = side(p, q, r), d2 = side(p, q, s), d3 = side(r, s, p), d4 = side(r, s, q);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

// The slow exact check of a triangulation of a simple polygon in z = 0: at most n − 2
// triangles (a vertex that clipping leaves between two collinear ones goes without one),
// each counter-clockwise, their areas summing to the polygon's, no triangle edge crossing the
// outline, no vertex strictly inside a triangle.
void expect_triangulates(const Polygon& poly, const std::vector<uint32_t>& t) {
  const size_t n = poly.size();
  ASSERT_LE(t.size(), 3 * (n - 2));
  ASSERT_GE(t.size(), 3u);
  const double area = polygon_newell_normal(poly).z;
  EXPECT_NEAR(doubled_area(poly, t, {0, 0, 1}).z, area, 1e-9 * std::abs(area));
  for (size_t k = 0; k < t.size(); k += 3)
    for (int e = 0; e < 3; ++e) {
      const glm::dvec3 a = at(poly, t[k + e]), b = at(poly, t[k + (e + 1) % 3]);
      for (uint32_t i = 0; i < n; ++i)
        ASSERT_FALSE(properly_cross(a, b, at(poly, i), at(poly, static_cast<uint32_t>((i + 1) % n))))
            << "triangle " << k / 3 << " leaves the outline at edge " << i;
    }
  for (size_t k = 0; k < t.size(); k += 3)
    for (uint32_t i = 0; i < n; ++i) {
      if (i == t[k] || i == t[k + 1] || i == t[k + 2]) continue;
      const glm::dvec3 q = at(poly, i), a = at(poly, t[k]), b = at(poly, t[k + 1]), c = at(poly, t[k + 2]);
      auto side = [&](const glm::dvec3& u, const glm::dvec3& v) {
        return (v.x - u.x) * (q.y - u.y) - (v.y - u.y) * (q.x - u.x);
      };
      ASSERT_FALSE(side(a, b) > 1e-12 && side(b, c) > 1e-12 && side(c, a) > 1e-12)
          << "vertex " << i << " inside triangle " << k / 3;
    }
}

TEST(LeafMesh, RandomStarsCombsAndSpiralsAreTriangulatedExactly) {
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE("star seed " + std::to_string(seed));
    const Polygon p = star(5 + seed * 3, seed);
    expect_triangulates(p, triangulate_polygon(p));
  }
  for (size_t teeth : {1u, 2u, 7u, 30u}) {
    SCOPED_TRACE("comb of " + std::to_string(teeth));
    const Polygon p = comb(teeth);
    expect_triangulates(p, triangulate_polygon(p));
  }
  for (size_t n : {200u, 600u}) {
    SCOPED_TRACE("spiral of " + std::to_string(n));
    const Polygon p = spiral(n);
    expect_triangulates(p, triangulate_polygon(p));
  }
}

// Issue 32 item 10: a 110-byte grammar grew one leaf of 524,288 vertices, and ear clipping
// that restarts at the first vertex and tests every vertex took minutes (quadratic). The work
// is now about linear in the vertices, convex or toothed.
TEST(LeafMesh, TriangulationWorkGrowsLinearlyWithTheVertices) {
  struct Case {
    std::string name;
    Polygon polygon;
  };
  std::vector<Case> cases;
  Polygon circle;
  for (size_t i = 0; i < 524288; ++i) {
    const double a = 2 * M_PI * static_cast<double>(i) / 524288;
    circle.push_back({std::cos(a), std::sin(a), 0});
  }
  cases.push_back({"circle", std::move(circle)});
  cases.push_back({"star", star(100000, 7)});
  cases.push_back({"comb", comb(25000)});
  cases.push_back({"spiral", spiral(100000)});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    TriangulationWork work;
    const std::vector<uint32_t> t = triangulate_polygon(c.polygon, &work);
    const double n = static_cast<double>(c.polygon.size());
    EXPECT_LE(t.size(), 3 * (c.polygon.size() - 2));
    // Vertices between nearly collinear ones go without a triangle: slivers below 1e-12 of
    // the box's area each.
    EXPECT_NEAR(doubled_area(c.polygon, t, {0, 0, 1}).z, polygon_newell_normal(c.polygon).z,
                1e-6 * std::abs(polygon_newell_normal(c.polygon).z));
    EXPECT_LE(static_cast<double>(work.ear_tests), 16 * n) << work.ear_tests;
    EXPECT_LE(static_cast<double>(work.point_tests), 64 * n * std::log2(n)) << work.point_tests;  // ~n²/50 before
  }
}

// A fine convex leaf is halved pass by pass, not fanned from one vertex: the triangles'
// boxes (what a ray tracer's hierarchy pays for) add up to a few times the leaf's box; a
// fan of 100,000 slivers adds up to thousands of times.
TEST(LeafMesh, AFineConvexLeafIsNotFannedIntoSlivers) {
  Polygon circle;
  const size_t n = 100000;
  for (size_t i = 0; i < n; ++i) {
    const double a = 2 * M_PI * static_cast<double>(i) / static_cast<double>(n);
    circle.push_back({std::cos(a), std::sin(a), 0});
  }
  const std::vector<uint32_t> t = triangulate_polygon(circle);
  double boxes = 0;
  for (size_t k = 0; k < t.size(); k += 3) {
    const glm::dvec3 a = at(circle, t[k]), b = at(circle, t[k + 1]), c = at(circle, t[k + 2]);
    boxes += (std::max({a.x, b.x, c.x}) - std::min({a.x, b.x, c.x})) *
             (std::max({a.y, b.y, c.y}) - std::min({a.y, b.y, c.y}));
  }
  EXPECT_LT(boxes, 4 * 4.0) << "the circle's box is 2 × 2";
  EXPECT_NEAR(doubled_area(circle, t, {0, 0, 1}).z, 2 * M_PI, 1e-6);
}

}  // namespace
}  // namespace sylva
