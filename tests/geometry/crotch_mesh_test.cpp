// Tests of core/geometry/crotch_mesh.h: the fillet's triangles lie on the blended surface,
// face out, cover what the marcher sees of the fillet, add nothing where the blend does
// not, and cost few triangles.
#include "core/geometry/crotch_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <limits>
#include <random>

namespace sylva {
namespace {

using glm::dvec3;

Joint joint_at(dvec3 p, double radius) { return Joint{{p.x, p.y, p.z}, radius, 0}; }

void add_chain(Skeleton& sk, const std::vector<dvec3>& points, const std::vector<double>& radii,
               std::optional<ChainParent> parent) {
  Chain ch{static_cast<uint32_t>(sk.joints.size()), static_cast<uint32_t>(points.size()), parent};
  for (size_t i = 0; i < points.size(); ++i) sk.joints.push_back(joint_at(points[i], radii[i]));
  sk.chains.push_back(ch);
}

// crotch_test's: a trunk of radius 0.3 with, from its middle joint, a limb at 45° (radius
// 0.15) and a twig at 60° on the other side (under a quarter of the trunk's: no crotch).
Skeleton limb_on_trunk() {
  Skeleton sk;
  add_chain(sk, {{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {0.3, 0.3, 0.28}, std::nullopt);
  const double s = std::sqrt(0.5);
  add_chain(sk, {{0, 1, 0}, {1.2 * s, 1 + 1.2 * s, 0}}, {0.15, 0.12}, ChainParent{0, 1});
  add_chain(sk, {{0, 1, 0}, {-0.8 * std::sin(1.047), 1 + 0.8 * std::cos(1.047), 0}}, {0.05, 0.04}, ChainParent{0, 1});
  return sk;
}

struct LimbCrotch {
  Skeleton skeleton = limb_on_trunk();
  SkinnedSkeleton skinned = skin_skeleton(skeleton);
  Crotch crotch = find_crotches(skeleton, skinned.frusta).at(0);
};

dvec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return glm::normalize(dvec3(n(rng), n(rng), n(rng)));
}

// Distance from p to the triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
double point_triangle_distance(const dvec3& p, const dvec3& a, const dvec3& b, const dvec3& c) {
  const dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return glm::length(p - a);
  const dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return glm::length(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + d1 / (d1 - d3) * ab));
  const dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return glm::length(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + d2 / (d2 - d6) * ac));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    return glm::length(p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b)));
  }
  const double denom = 1 / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

double distance_to_mesh(const TriangleMesh& mesh, const dvec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* i = &mesh.indices[3 * t];
    best = std::min(best, point_triangle_distance(p, mesh.positions[i[0]], mesh.positions[i[1]], mesh.positions[i[2]]));
  }
  return best;
}

TEST(CrotchMesh, PointTriangleDistanceOfTheTestIsRight) {
  const dvec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_NEAR(point_triangle_distance({0.2, 0.2, 0.5}, a, b, c), 0.5, 1e-15);  // over the face
  EXPECT_NEAR(point_triangle_distance({-1, -1, 0}, a, b, c), std::sqrt(2.0), 1e-15);  // vertex a
  EXPECT_NEAR(point_triangle_distance({0.5, -2, 0}, a, b, c), 2, 1e-15);  // edge ab
  EXPECT_NEAR(point_triangle_distance({1, 1, 0}, a, b, c), std::sqrt(0.5), 1e-15);  // edge bc
  EXPECT_NEAR(point_triangle_distance({3, 0, 0}, a, b, c), 2, 1e-15);  // vertex b
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
  const Skeleton sk = limb_on_trunk();
  const SkinnedSkeleton skinned = skin_skeleton(sk);
  const std::vector<Crotch> crotches = find_crotches(sk, skinned.frusta, CrotchOptions{0.0, 0.25});
  ASSERT_EQ(crotches.size(), 1u);
  EXPECT_EQ(crotches[0].k, 0);
  const TriangleMesh mesh = crotch_fillet_mesh(crotches[0], skinned.frusta, 0.025);
  EXPECT_EQ(mesh.triangle_count(), 0u);
  EXPECT_TRUE(mesh.positions.empty());
}

TEST(CrotchMesh, ACellTooSmallOrNotPositiveIsRefused) {
  const LimbCrotch limb;
  EXPECT_THROW(crotch_fillet_mesh(limb.crotch, limb.skinned.frusta, 0.0), std::invalid_argument);
  EXPECT_THROW(crotch_fillet_mesh(limb.crotch, limb.skinned.frusta, -1.0), std::invalid_argument);
  EXPECT_THROW(crotch_fillet_mesh(limb.crotch, limb.skinned.frusta, limb.crotch.radius / 1000), std::invalid_argument);
}

}  // namespace
}  // namespace sylva
