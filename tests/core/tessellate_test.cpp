// The polygon baseline: frusta as triangle meshes on the analytic surface, watertight
// across joints, with the paper's GS triangle counts.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>

#include "core/tessellate.h"

namespace sylva {
namespace {

Skeleton chain_of(std::vector<std::array<double, 4>> joints) {
  Skeleton sk;
  for (const auto& j : joints) sk.joints.push_back(Joint{{j[0], j[1], j[2]}, j[3], 0});
  sk.chains.push_back(Chain{0, static_cast<uint32_t>(joints.size()), std::nullopt});
  return sk;
}

// Distance of p from the frustum's infinite cone surface (radially).
double distance_to_cone(const FrustumShape& s, const glm::dvec3& p) {
  const glm::dvec3 w = p - s.base;
  const double y = glm::dot(w, s.axis);
  const double radial = glm::length(w - y * s.axis);
  return std::fabs(radial - s.radius_at(y));
}

TEST(Tessellate, TriangleCountsFollowThePapersGsColumn) {
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.2}, {0, 1, 0, 0.15}, {0.3, 2, 0, 0.1}}));
  ASSERT_EQ(sk.frusta.size(), 2u);
  for (int m = 0; m <= 3; ++m) {
    TessellateOptions o;
    o.level = m;
    o.caps = false;
    TriangleMesh mesh = tessellate(sk, o);
    EXPECT_EQ(mesh.triangle_count(), 2u * 16u * (1u << (2 * m))) << "level " << m;
    EXPECT_EQ(mesh.triangle_frustum.size(), mesh.triangle_count());
  }
  TessellateOptions caps;  // chain ends: two caps of 8 triangles at level 0
  EXPECT_EQ(tessellate(sk, caps).triangle_count(), 2u * 16u + 2u * 8u);
}

TEST(Tessellate, EveryVertexLiesOnTheAnalyticSurfaceBetweenTheCuts) {
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.3}, {0, 1, 0, 0.2}, {0.5, 1.8, 0.2, 0.1}, {0.6, 2.5, 0.9, 0}}));
  TessellateOptions o;
  o.level = 2;
  o.caps = false;
  TriangleMesh mesh = tessellate(sk, o);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Frustum& fr = sk.frusta[mesh.triangle_frustum[t]];
    const FrustumShape& s = fr.shape;
    // A shared bottom row lies on the frustum below: off this cone by at most the seam.
    const double seam = fr.parent >= 0 ? seam_error(sk.frusta[static_cast<size_t>(fr.parent)], fr) : 0.0;
    for (int c = 0; c < 3; ++c) {
      const glm::dvec3& p = mesh.positions[mesh.indices[3 * t + c]];
      ASSERT_LT(distance_to_cone(s, p), 1e-12 + 1.01 * seam);
      ASSERT_GE(glm::dot(s.lower.normal, p) - s.lower.offset, -1e-12);
      ASSERT_LE(glm::dot(s.upper.normal, p) - s.upper.offset, 1e-12);
      ASSERT_NEAR(glm::length(mesh.normals[mesh.indices[3 * t + c]]), 1.0, 1e-12);
    }
  }
}

TEST(Tessellate, NeighbouringFrustaShareTheirCutVerticesSoTheMeshHasNoCracks) {
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.2}, {0, 1, 0, 0.2}, {0.7, 1.7, 0, 0.15}, {0.7, 2.7, 0.4, 0.1}}));
  ASSERT_EQ(sk.frusta.size(), 3u);
  ASSERT_EQ(sk.split_joints, 0u);
  TessellateOptions o;
  o.level = 1;
  o.caps = false;
  TriangleMesh mesh = tessellate(sk, o);
  const int n = tessellation_columns(o), k = tessellation_rows(o);
  const size_t per = static_cast<size_t>(n + 1) * (k + 1);
  for (size_t f = 0; f + 1 < sk.frusta.size(); ++f) {
    for (int i = 0; i <= n; ++i) {
      const glm::dvec3& top = mesh.positions[f * per + static_cast<size_t>(k * (n + 1) + i)];
      const glm::dvec3& bottom = mesh.positions[(f + 1) * per + static_cast<size_t>(i)];
      EXPECT_LT(glm::length(top - bottom), 1e-9) << "joint " << f + 1 << " column " << i;
    }
  }
}

TEST(Tessellate, TrianglesFaceOutward) {
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.2}, {0, 1, 0, 0.1}}));
  TriangleMesh mesh = tessellate(sk, TessellateOptions{});
  const FrustumShape& s = sk.frusta[0].shape;
  const glm::dvec3 centre = s.base + 0.5 * s.length * s.axis;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const glm::dvec3 a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
                     c = mesh.positions[mesh.indices[3 * t + 2]];
    const glm::dvec3 n = glm::cross(b - a, c - a);
    EXPECT_GT(glm::dot(n, (a + b + c) / 3.0 - centre), 0) << "triangle " << t;
  }
}

TEST(Tessellate, ATipCollapsesToAPointWithoutZeroAreaTriangles) {
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.2}, {0, 1, 0, 0}}));
  TessellateOptions o;
  o.level = 1;
  TriangleMesh mesh = tessellate(sk, o);
  // 16 columns × 2 rows: the top row has one triangle per column; one cap at the base.
  EXPECT_EQ(mesh.triangle_count(), 16u * 2u * 2u - 16u + 16u);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const glm::dvec3 a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
                     c = mesh.positions[mesh.indices[3 * t + 2]];
    EXPECT_GT(glm::length(glm::cross(b - a, c - a)), 1e-12) << "triangle " << t;
  }
}

TEST(Tessellate, ChordErrorFallsFourfoldPerLevel) {
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 1.0}, {0, 1, 0, 1.0}}));
  double previous = 0;
  for (int m = 0; m <= 3; ++m) {
    TessellateOptions o;
    o.level = m;
    o.caps = false;
    TriangleMesh mesh = tessellate(sk, o);
    // Worst radial gap of a triangle's centroid-of-edge to the cylinder: the sagitta.
    const int n = tessellation_columns(o);
    const double sagitta = 1.0 - std::cos(3.141592653589793 / n);
    const glm::dvec3 a = mesh.positions[mesh.indices[0]], b = mesh.positions[mesh.indices[1]];
    const glm::dvec3 mid = 0.5 * (a + b);
    const double gap = 1.0 - std::hypot(mid.x, mid.z);
    EXPECT_NEAR(gap, sagitta, 1e-12);
    if (m > 0) {
      EXPECT_NEAR(previous / gap, 4.0, 0.2);
    }
    previous = gap;
  }
}

TEST(Tessellate, SegmentsAroundOverridesTheColumnsForExport) {
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.2}, {0, 1, 0, 0.2}}));
  TessellateOptions o;
  o.segments_around = 5;
  o.caps = false;
  EXPECT_EQ(tessellate(sk, o).triangle_count(), 10u);
}

}  // namespace
}  // namespace sylva
