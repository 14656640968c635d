// leaf_mesh_test.cpp — leaves as triangles: ear clipping keeps a concave outline, every
// triangle turns as the polygon does, a placed plant's leaves move with it.
#include "core/geometry/leaf_mesh.h"

#include <gtest/gtest.h>

#include <array>
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
  sk.leaves.push_back({std::nullopt, 1, kite});
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

}  // namespace
}  // namespace sylva
