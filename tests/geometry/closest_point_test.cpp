// Tests of core/geometry/closest_point.h against distances worked out by hand, one per
// Voronoi region of the triangle.
#include "core/geometry/closest_point.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sylva {
namespace {

using glm::dvec3;

TEST(ClosestPoint, PointTriangleDistanceInEveryRegion) {
  const dvec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_NEAR(point_triangle_distance({0.2, 0.2, 0.5}, a, b, c), 0.5, 1e-15);         // over the face
  EXPECT_NEAR(point_triangle_distance({-1, -1, 0}, a, b, c), std::sqrt(2.0), 1e-15);  // vertex a
  EXPECT_NEAR(point_triangle_distance({3, 0, 0}, a, b, c), 2, 1e-15);                 // vertex b
  EXPECT_NEAR(point_triangle_distance({-1, 3, 0}, a, b, c), std::sqrt(5.0), 1e-15);   // vertex c
  EXPECT_NEAR(point_triangle_distance({0.5, -2, 0}, a, b, c), 2, 1e-15);              // edge ab
  EXPECT_NEAR(point_triangle_distance({-2, 0.5, 0}, a, b, c), 2, 1e-15);              // edge ac
  EXPECT_NEAR(point_triangle_distance({1, 1, 0}, a, b, c), std::sqrt(0.5), 1e-15);    // edge bc
}

TEST(ClosestPoint, PointSegmentDistanceAlongBeyondAndDegenerate) {
  const dvec3 a(0, 0, 0), b(2, 0, 0);
  EXPECT_NEAR(point_segment_distance({1, 3, 0}, a, b), 3, 1e-15);
  EXPECT_NEAR(point_segment_distance({5, 4, 0}, a, b), 5, 1e-15);
  EXPECT_NEAR(point_segment_distance({0, 0, 2}, a, a), 2, 1e-15);
}

}  // namespace
}  // namespace sylva
