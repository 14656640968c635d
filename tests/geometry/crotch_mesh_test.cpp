// Tests of core/geometry/crotch_mesh.h: the fillet's triangles lie on the blended surface,
// face out, cover what the marcher sees of the fillet, add nothing where the blend does
// not, and cost few triangles.
#include "core/geometry/crotch_mesh.h"

#include <gtest/gtest.h>

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <limits>
#include <random>

#include "core/geometry/closest_point.h"
#include "core/geometry/skeleton_bounds.h"
#include "tests/support/limb_crotch.h"

namespace sylva {
namespace {

using glm::dvec3;

using test::LimbCrotch;
using test::random_unit;

double distance_to_mesh(const TriangleMesh& mesh, const dvec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* i = &mesh.indices[3 * t];
    best = std::min(best, point_triangle_distance(p, mesh.positions[i[0]], mesh.positions[i[1]], mesh.positions[i[2]]));
  }
  return best;
}

// At cells of k/3 and k/2: every vertex on the blended surface within the ball, off the
// exact union by no more than the blend adds, triangles facing out, and the count.
TEST(CrotchMesh, VerticesLieOnTheBlendedSurfaceAndTrianglesFaceOut) {
  const LimbCrotch limb;
  const std::span<const Frustum> frusta = limb.skinned.frusta;
  const Crotch& c = limb.crotch;
  for (const double share : {1.0 / 3, 1.0 / 2}) {
    const double cell = share * c.k;
    const TriangleMesh mesh = crotch_fillet_mesh(c, frusta, cell);
    ASSERT_GT(mesh.triangle_count(), 0u);
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
    ASSERT_EQ(mesh.triangle_frustum.size(), mesh.triangle_count());
    double worst_f = 0, farthest = 0, most_off = 0;
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      const dvec3& p = mesh.positions[v];
      const CrotchSample s = crotch_field(c, frusta, p);
      worst_f = std::max(worst_f, std::abs(s.value));
      farthest = std::max(farthest, glm::length(p - c.centre));
      most_off = std::max(most_off, std::min(s.parent, s.lateral));
      EXPECT_LE(std::abs(s.value), 1e-6 * c.radius) << "vertex " << v << " off F = 0";
      EXPECT_LE(glm::length(p - c.centre), c.radius + cell) << "vertex " << v << " outside the ball";
      EXPECT_LE(std::min(s.parent, s.lateral), c.k / 4 + 1e-9) << "vertex " << v << " farther out than the blend adds";
      EXPECT_NEAR(glm::length(mesh.normals[v]), 1, 1e-12);
    }
    int facing_in = 0;
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
      const dvec3& a = mesh.positions[mesh.indices[3 * t]];
      const dvec3& b = mesh.positions[mesh.indices[3 * t + 1]];
      const dvec3& d = mesh.positions[mesh.indices[3 * t + 2]];
      const dvec3 centroid = (a + b + d) / 3.0;
      facing_in += glm::dot(glm::cross(b - a, d - a), crotch_shade(c, frusta, centroid).normal) <= 0;
      const uint32_t f = mesh.triangle_frustum[t];
      const bool in_a_group = std::count(c.parent_frusta.begin(), c.parent_frusta.end(), f) +
                                  std::count(c.lateral_frusta.begin(), c.lateral_frusta.end(), f) > 0;
      EXPECT_TRUE(in_a_group) << "triangle " << t << " names frustum " << f;
    }
    std::printf("cell k/%.0f = %.4f m: %zu triangles, %zu vertices; worst |F| %.2e m, farthest %.4f m of radius %.4f, "
                "at most %.4f m off the union (k/4 = %.4f), %d triangles facing in\n",
                1 / share, cell, mesh.triangle_count(), mesh.positions.size(), worst_f, farthest, c.radius, most_off,
                c.k / 4, facing_in);
    EXPECT_LE(facing_in, 0.01 * double(mesh.triangle_count())) << facing_in << " triangles face in";
    if (share == 0.5) {
      EXPECT_LT(mesh.triangle_count(), 2000u);
    }
  }
}

// Where the marcher sees the fillet proper (a hit off the exact union), a triangle is
// within a cell.
TEST(CrotchMesh, TheMeshCoversTheFilletTheMarcherSees) {
  const LimbCrotch limb;
  const std::span<const Frustum> frusta = limb.skinned.frusta;
  const Crotch& c = limb.crotch;
  for (const double share : {1.0 / 3, 1.0 / 2}) {
    const double cell = share * c.k;
    const TriangleMesh mesh = crotch_fillet_mesh(c, frusta, cell);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    int hits = 0, fillet_hits = 0;
    double worst = 0;
    for (int i = 0; i < 2000; ++i) {
      const dvec3 target = c.centre + 0.9 * c.radius * u(rng) * random_unit(rng);
      const dvec3 origin = c.centre + 3 * c.radius * random_unit(rng);
      const Ray ray{origin, target - origin};
      const std::optional<CrotchHit> hit = march_crotch(c, frusta, ray, 0, 10);
      if (!hit) continue;
      ++hits;
      const dvec3 p = ray.origin + hit->t * ray.direction;
      const CrotchSample s = crotch_field(c, frusta, p);
      if (!(std::min(s.parent, s.lateral) > 1e-3 * c.k)) continue;
      ++fillet_hits;
      const double d = distance_to_mesh(mesh, p);
      worst = std::max(worst, d);
      EXPECT_LE(d, cell) << "ray " << i << " hits the fillet at " << p.x << " " << p.y << " " << p.z;
    }
    std::printf("cell k/%.0f: %d hits of 2000 rays, %d on the fillet, the farthest %.5f m from the mesh (cell %.4f)\n",
                1 / share, hits, fillet_hits, worst, cell);
    EXPECT_GE(fillet_hits, 50);
  }
}

TEST(CrotchMesh, NoBlendNoTriangles) {
  const Skeleton sk = test::limb_on_trunk();
  const SkinnedSkeleton skinned = skin_skeleton(sk);
  const std::vector<Crotch> crotches = find_crotches(sk, skinned.frusta, CrotchOptions{0.0, 0.25});
  ASSERT_EQ(crotches.size(), 1u);
  EXPECT_EQ(crotches[0].k, 0);
  const TriangleMesh mesh = crotch_fillet_mesh(crotches[0], skinned.frusta, 0.025);
  EXPECT_EQ(mesh.triangle_count(), 0u);
  EXPECT_TRUE(mesh.positions.empty());
}

// skeleton_fillets meshes each crotch at cells of k/2, but no finer than
// kFilletMinCellPerExtent of the skeleton's extent: the limb alone (extent ~2.4 m, k/2 =
// 60 mm) at k/2; with a far stem widening the extent to ~200 m, at 0.2 m.
TEST(CrotchMesh, TheSkeletonsFilletsAreNoFinerThanAThousandthOfItsExtent) {
  const LimbCrotch limb;
  const TriangleMesh fine = skeleton_fillets(limb.skeleton, limb.skinned.frusta);
  EXPECT_EQ(fine.triangle_count(),
            crotch_fillet_mesh(limb.crotch, limb.skinned.frusta, limb.crotch.k / 2).triangle_count());
  Skeleton wide = limb.skeleton;
  test::add_chain(wide, {{200, 0, 0}, {200, 1, 0}}, {0.1, 0.1}, std::nullopt);
  const SkinnedSkeleton skinned = skin_skeleton(wide);
  const SkeletonBounds box = skeleton_bounds(wide);
  const double cell = kFilletMinCellPerExtent * glm::length(box.hi - box.lo);
  ASSERT_GT(cell, limb.crotch.k / 2);
  const TriangleMesh coarse = skeleton_fillets(wide, skinned.frusta);
  const std::vector<Crotch> crotches = find_crotches(wide, skinned.frusta);
  ASSERT_EQ(crotches.size(), 1u);
  EXPECT_EQ(coarse.triangle_count(), crotch_fillet_mesh(crotches[0], skinned.frusta, cell).triangle_count());
  EXPECT_LT(coarse.triangle_count(), fine.triangle_count() / 4);
  EXPECT_GT(coarse.triangle_count(), 0u);  // the crease is still covered
}

TEST(CrotchMesh, TheSkeletonsFilletsAreTheSameOnAnyThreadCount) {
  // A trunk with four limbs around it: four crotches, meshed in parallel, appended in order.
  Skeleton sk;
  test::add_chain(sk, {{0, 0, 0}, {0, 1, 0}, {0, 2, 0}, {0, 3, 0}}, {0.3, 0.29, 0.28, 0.26}, std::nullopt);
  for (int i = 0; i < 4; ++i) {
    const double a = 1.7 * i, y = 0.8 + 0.5 * i;
    test::add_chain(sk, {{0, y, 0}, {0.9 * std::cos(a), y + 0.7, 0.9 * std::sin(a)}}, {0.12, 0.1},
                    ChainParent{0, static_cast<uint32_t>(1 + i / 2)});
  }
  const SkinnedSkeleton skinned = skin_skeleton(sk);
  ASSERT_EQ(find_crotches(sk, skinned.frusta).size(), 4u);
  const TriangleMesh one = skeleton_fillets(sk, skinned.frusta, 1);
  const TriangleMesh three = skeleton_fillets(sk, skinned.frusta, 3);
  ASSERT_GT(one.triangle_count(), 400u);
  EXPECT_EQ(one.positions, three.positions);
  EXPECT_EQ(one.indices, three.indices);
  EXPECT_EQ(one.triangle_frustum, three.triangle_frustum);
}

TEST(CrotchMesh, ACellTooSmallOrNotPositiveIsRefused) {
  const LimbCrotch limb;
  EXPECT_THROW(crotch_fillet_mesh(limb.crotch, limb.skinned.frusta, 0.0), std::invalid_argument);
  EXPECT_THROW(crotch_fillet_mesh(limb.crotch, limb.skinned.frusta, -1.0), std::invalid_argument);
  EXPECT_THROW(crotch_fillet_mesh(limb.crotch, limb.skinned.frusta, limb.crotch.radius / 1000), std::invalid_argument);
}

}  // namespace
}  // namespace sylva
