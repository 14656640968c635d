// The polygon baseline: frusta as triangle meshes on the analytic surface, watertight
// across joints, with the paper's GS triangle counts.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>

#include "core/geometry/tessellate.h"

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
  // Its 45° and 49° bends are rounded (skin.h): the arcs' pieces are neighbours too.
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.2}, {0, 1, 0, 0.2}, {0.7, 1.7, 0, 0.15}, {0.7, 2.7, 0.4, 0.1}}));
  ASSERT_GT(sk.frusta.size(), 3u);
  ASSERT_EQ(sk.split_joints, 0u);
  for (const Frustum& f : sk.frusta) ASSERT_EQ(f.kind, FrustumKind::segment);
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

// GS+R: H = 0.5 + 0.5 sin(2π·3u), 5 cm deep, on a cylinder of radius 0.5 in two segments.
TEST(Displace, VerticesMoveAlongTheirNormalByTheHeightAtTheirUv) {
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.5}, {0, 1, 0, 0.5}, {0, 2, 0, 0.5}}));
  TessellateOptions o;
  o.level = 2;
  o.caps = false;
  const TriangleMesh mesh = tessellate(sk, o);
  auto height = [](double u, double) { return 0.05 * (0.5 + 0.5 * std::sin(2 * 3.141592653589793 * 3 * u)); };
  const TriangleMesh displaced = displace(mesh, height);
  ASSERT_EQ(displaced.positions.size(), mesh.positions.size());
  EXPECT_EQ(displaced.indices, mesh.indices);
  EXPECT_EQ(displaced.uvs, mesh.uvs);
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::dvec3& p = displaced.positions[v];
    EXPECT_NEAR(std::hypot(p.x, p.z), 0.5 + height(mesh.uvs[v].x, 0), 1e-12) << "vertex " << v;
    EXPECT_NEAR(p.y, mesh.positions[v].y, 1e-12);
    EXPECT_NEAR(glm::length(displaced.normals[v]), 1, 1e-12);
    EXPECT_GT(glm::dot(displaced.normals[v], glm::normalize(glm::dvec3(p.x, 0, p.z))), 0.5);  // outward
  }
}

TEST(Displace, CoincidentVerticesStayTogetherSoNoCrackOpens) {
  // A bent chain (mitred joints), caps, and a height that jumps at the seam (u_repeat 2.5:
  // H(u = 0) != H(u = 1)) and along v: every vertex pair that coincided still does.
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.3}, {0, 1, 0, 0.25}, {0.4, 1.8, 0, 0.2}, {0.5, 2.6, 0.3, 0}}));
  TessellateOptions o;
  o.level = 1;
  const TriangleMesh mesh = tessellate(sk, o);
  auto height = [](double u, double v_m) { return 0.02 * std::fmod(2.5 * u, 1.0) + 0.01 * std::fmod(3 * v_m, 1.0); };
  const TriangleMesh displaced = displace(mesh, height);
  size_t pairs = 0;
  for (size_t a = 0; a < mesh.positions.size(); ++a)
    for (size_t b = a + 1; b < mesh.positions.size(); ++b)
      if (mesh.positions[a] == mesh.positions[b]) {
        ++pairs;
        ASSERT_EQ(displaced.positions[a], displaced.positions[b]) << a << " and " << b;
      }
  EXPECT_GT(pairs, 100u);  // seams, joint rows, rims, the tip
}

TEST(Displace, JointRowsShareTheirUvsExactly) {
  // Displacement is a function of (u, v_m): the rows two frusta share at a joint have the
  // same uvs bit for bit (and the same positions), so they move alike even unwelded.
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.2}, {0, 1, 0, 0.2}, {0.7, 1.7, 0, 0.15}, {0.7, 2.7, 0.4, 0.1}}));
  ASSERT_EQ(sk.split_joints, 0u);
  TessellateOptions o;
  o.level = 2;
  o.caps = false;
  const TriangleMesh mesh = tessellate(sk, o);
  // Displaced, the two rows share one normal too (eq. 8 normals agree at the joint), so
  // the shading shows no seam there.
  const TriangleMesh displaced = displace(mesh, [](double u, double v_m) { return 0.01 * (1 + std::sin(9 * u + v_m)); });
  const int n = tessellation_columns(o), k = tessellation_rows(o);
  const size_t per = static_cast<size_t>(n + 1) * (k + 1);
  for (size_t f = 0; f + 1 < sk.frusta.size(); ++f)
    for (int i = 0; i <= n; ++i) {
      const size_t top = f * per + static_cast<size_t>(k * (n + 1) + i), bottom = (f + 1) * per + static_cast<size_t>(i);
      EXPECT_EQ(mesh.uvs[top], mesh.uvs[bottom]) << "joint " << f + 1 << " column " << i;
      EXPECT_EQ(mesh.positions[top], mesh.positions[bottom]);
      EXPECT_EQ(displaced.positions[top], displaced.positions[bottom]);
      EXPECT_LT(glm::length(displaced.normals[top] - displaced.normals[bottom]), 1e-12);
    }
}

TEST(Displace, NormalsComeFromTheDisplacedSurfaceAndCreasesStay) {
  // A constant height on a cylinder with caps: side normals stay radial (angle-weighted
  // face normals of a regular prism), cap normals stay axial: the rim crease is kept.
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.5}, {0, 2, 0, 0.5}}));
  const TriangleMesh mesh = tessellate(sk, TessellateOptions{});
  const TriangleMesh displaced = displace(mesh, [](double, double) { return 0.1; });
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::dvec3 n = displaced.normals[v], original = mesh.normals[v];
    if (std::abs(original.y) > 0.5) {  // a cap vertex
      EXPECT_NEAR(n.y, original.y, 1e-12);
    } else {
      const glm::dvec3 p = displaced.positions[v];
      EXPECT_NEAR(glm::dot(n, glm::normalize(glm::dvec3(p.x, 0, p.z))), 1, 1e-12) << "vertex " << v;
      EXPECT_NEAR(std::hypot(p.x, p.z), 0.6, 1e-12);
    }
  }
}

TEST(Tessellate, AppendMeshShiftsIndicesAndFrusta) {
  SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.2}, {0, 1, 0, 0.2}}));
  const TriangleMesh part = tessellate(sk, TessellateOptions{});
  TriangleMesh all = part;
  append_mesh(all, part, 7);
  ASSERT_EQ(all.triangle_count(), 2 * part.triangle_count());
  EXPECT_EQ(all.positions.size(), 2 * part.positions.size());
  EXPECT_EQ(all.indices[part.indices.size()], part.indices[0] + part.positions.size());
  EXPECT_EQ(all.triangle_frustum.back(), 7u);
}

}  // namespace
}  // namespace sylva

namespace sylva {
namespace {

TEST(TessellateLimits, TheSizeBoundsWhatTessellateTakes) {
  const SkinnedSkeleton s = skin_skeleton(chain_of({{0, 0, 0, 0.3}, {0, 1, 0, 0.2}, {0.2, 2, 0, 0.1}}));
  for (int level : {0, 2}) {
    TessellateOptions o;
    o.level = level;
    const MeshSize size = tessellation_size(s.frusta.size(), o);
    const TriangleMesh m = tessellate(s, o);
    EXPECT_GE(size.vertices, m.positions.size());
    EXPECT_GE(size.triangles, m.triangle_count());
    EXPECT_GE(size.bytes, m.memory_bytes());
    EXPECT_LE(size.bytes, 2 * m.memory_bytes() + 4096);  // an estimate, not a blanket refusal
  }
}

TEST(TessellateLimits, AMeshThatCannotFitIsRefusedBeforeAnythingIsAllocated) {
  // The pine's 17,468 segments at level 6 (65,536 triangles each) would take ~53 GiB:
  // refused from the counts, naming the limit; a skinned skeleton of that many frusta
  // is refused by tessellate() itself before it reserves anything.
  TessellateOptions o;
  o.level = 6;
  EXPECT_GT(tessellation_size(17468, o).bytes, kMaxMeshBytes);
  try {
    check_mesh_fits(tessellation_size(17468, o));
    FAIL() << "no MeshTooLarge";
  } catch (const MeshTooLarge& e) {
    EXPECT_NE(std::string(e.what()).find("more than the limit of 8 GiB for a mesh"), std::string::npos) << e.what();
  }
  SkinnedSkeleton many;
  many.frusta.resize(17468);
  EXPECT_THROW(tessellate(many, o), MeshTooLarge);
  // What fits alone may not fit beside meshes already built for the same picture.
  TessellateOptions small;
  EXPECT_NO_THROW(check_mesh_fits(tessellation_size(17468, small)));
  EXPECT_THROW(check_mesh_fits(tessellation_size(17468, small), kMaxMeshBytes), MeshTooLarge);
  // --segments-around 4096 over a million frusta does not wrap the count.
  o.level = 6;
  o.segments_around = 4096;
  EXPECT_GT(tessellation_size(1'000'000, o).bytes, kMaxMeshBytes);
}

}  // namespace
}  // namespace sylva
