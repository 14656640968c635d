// mesh_accel_test.cpp — the polygon baseline (GS meshes in Embree) against the analytic
// frusta: depth converges with the level within the sagitta bound, uv and ids agree, a
// render agrees pixel for pixel on hit/miss, far offsets cost nothing.
#include "core/cpu/mesh_accel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>
#include <vector>

#include "core/cpu/bvh.h"
#include "core/cpu/frustum_tracer.h"
#include "core/cpu/render_cpu.h"
#include "core/cpu/texture.h"
#include "core/util/math.h"
#include "tests/support/plants.h"

namespace sylva {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Skeleton chain_of(std::vector<std::array<double, 4>> joints) {
  Skeleton sk;
  for (const auto& j : joints) sk.joints.push_back(Joint{{j[0], j[1], j[2]}, j[3], 0});
  sk.chains.push_back(Chain{0, static_cast<uint32_t>(joints.size()), std::nullopt});
  return sk;
}

// Analytic and mesh tracers over the same frusta (one plant).
struct Pair {
  SkinnedSkeleton skinned;
  std::vector<uint32_t> plants;
  std::unique_ptr<FrustumTracer> exact;
  std::unique_ptr<MeshTracer> mesh;
  Bvh bvh;
  // The exact nearest hit with its frustum (sylva's own BVH: the reference).
  BvhHit reference(const Ray& ray) const { return intersect_nearest(bvh, skinned.frusta, ray, 0, kInf); }
  Pair(const Skeleton& sk, int level, const glm::dvec3& offset = glm::dvec3(0)) {
    Skeleton moved = sk;
    for (Joint& j : moved.joints)
      for (int k = 0; k < 3; ++k) j.position_m[k] += offset[k];
    skinned = skin_skeleton(moved);
    plants.assign(skinned.frusta.size(), 0);
    exact = std::make_unique<FrustumTracer>(skinned.frusta, plants);
    TessellateOptions o;
    o.level = level;
    mesh = std::make_unique<MeshTracer>(tessellate(skinned, o), skinned.frusta, plants, level);
    bvh = build_bvh(skinned.frusta);
  }
};

// Rays from a ring of eyes 3 m from the y axis toward points near it, heights y0..y1.
std::vector<Ray> ring_rays(double y0, double y1, const glm::dvec3& offset = glm::dvec3(0)) {
  std::vector<Ray> rays;
  for (int a = 0; a < 97; ++a)
    for (int h = 0; h < 9; ++h)
      for (int l = 0; l < 11; ++l) {
        const double angle = 2 * kPi * (a + 0.37) / 97;
        const glm::dvec3 out(std::cos(angle), 0, std::sin(angle)), side(-std::sin(angle), 0, std::cos(angle));
        const double y = y0 + (y1 - y0) * (h + 0.5) / 9;
        const glm::dvec3 eye = 3.0 * out + glm::dvec3(0, y + 0.4 * (l % 3 - 1), 0);
        const glm::dvec3 target = glm::dvec3(0, y, 0) + (0.09 * (l - 5)) * side;
        rays.push_back({eye + offset, target - eye});
      }
  return rays;
}

struct DepthError {
  double max_error = 0;   // metres along the ray, over rays both hit on the side
  double worst_ratio = 0; // max error / its bound
  int compared = 0;
};

// Compares the mesh with the exact frusta along `rays`. The bound for a ray meeting the
// cone at P with incidence θ: the inscribed facets lie at most s = r_max(1 − cos(π/n))
// from P, their normals within π/n of P's normal, so the ray reaches the facet plane under
// P within s / cos(θ + π/n) (the mesh without caps is convex: P is outside only the
// facet(s) under it, so that crossing is where the ray enters the mesh).
DepthError depth_error(const Pair& pair, const std::vector<Ray>& rays, int columns, double r_max) {
  DepthError e;
  const double sagitta = r_max * (1 - std::cos(kPi / columns));
  for (const Ray& ray : rays) {
    const BvhHit ref = pair.reference(ray);
    if (!ref.hit_any() || ref.hit.kind != FrustumHitKind::side) continue;
    const SurfaceHit got = pair.mesh->nearest(ray, 0, kInf);
    const double len = glm::length(ray.direction);
    const double cos_theta = -glm::dot(ray.direction, ref.hit.normal) / len;
    const double angle = std::acos(std::clamp(cos_theta, -1.0, 1.0)) + kPi / columns;
    if (angle > 80 * kPi / 180) continue;
    EXPECT_TRUE(got.hit()) << "a ray this steep must meet the inscribed mesh";
    if (!got.hit()) continue;
    const double error = std::abs(got.t - ref.hit.t) * len;
    const double bound = sagitta / std::cos(angle);
    e.max_error = std::max(e.max_error, error);
    e.worst_ratio = std::max(e.worst_ratio, error / bound);
    ++e.compared;
  }
  return e;
}

TEST(MeshTracer, CylinderDepthConvergesWithTheLevelWithinTheSagittaBound) {
  const Skeleton cylinder = chain_of({{0, 0, 0, 0.5}, {0, 2, 0, 0.5}});
  std::vector<double> errors;
  for (int m = 0; m <= 4; ++m) {
    Pair pair(cylinder, m);
    TessellateOptions o;
    o.level = m;
    const DepthError e = depth_error(pair, ring_rays(0.2, 1.8), tessellation_columns(o), 0.5);
    EXPECT_GT(e.compared, 4000) << "level " << m;
    EXPECT_LE(e.worst_ratio, 1 + 1e-9) << "level " << m << ": max error " << e.max_error;
    errors.push_back(e.max_error);
  }
  EXPECT_LT(errors[4], errors[0]);
  for (int m = 1; m <= 4; ++m) EXPECT_LT(errors[m], errors[m - 1]) << "level " << m;
  // The sagitta falls fourfold per level; so does the worst depth error, roughly.
  EXPECT_LT(errors[4], errors[0] / 50);
}

TEST(MeshTracer, ConeDepthConvergesWithTheLevelWithinTheSagittaBound) {
  const Skeleton cone = chain_of({{0, 0, 0, 0.6}, {0, 2, 0, 0.2}});
  double first = 0, last = 0;
  for (int m = 0; m <= 4; ++m) {
    Pair pair(cone, m);
    TessellateOptions o;
    o.level = m;
    const DepthError e = depth_error(pair, ring_rays(0.2, 1.8), tessellation_columns(o), 0.6);
    EXPECT_GT(e.compared, 3000) << "level " << m;
    EXPECT_LE(e.worst_ratio, 1 + 1e-9) << "level " << m << ": max error " << e.max_error;
    if (m == 0) first = e.max_error;
    last = e.max_error;
  }
  EXPECT_LT(last, first / 50);
}

TEST(MeshTracer, UvIdsAndNormalsAgreeWithTheAnalyticHitAwayFromSeamsAndJoints) {
  // A straight chain of two frusta (u is continuous across the joint) and a bent one.
  for (const Skeleton& sk : {chain_of({{0, 0, 0, 0.5}, {0, 1, 0, 0.4}, {0, 2, 0, 0.3}}),
                             chain_of({{0, 0, 0, 0.5}, {0, 1, 0, 0.45}, {0.3, 2, 0.1, 0.35}})}) {
    const int m = 3;
    Pair pair(sk, m);
    const int n = 8 << m;
    const bool straight = sk.joints[2].position_m[0] == 0;
    int compared = 0;
    for (const Ray& ray : ring_rays(0.1, 1.9)) {
      const BvhHit ref = pair.reference(ray);
      const SurfaceHit got = pair.mesh->nearest(ray, 0, kInf);
      if (!ref.hit_any() || ref.hit.kind != FrustumHitKind::side || !got.hit()) continue;
      const SurfaceHit exact = describe_frustum_hit(ray, pair.skinned.frusta[ref.frustum], ref.hit);
      const double cos_theta = -glm::dot(glm::normalize(ray.direction), exact.geometric_normal);
      if (cos_theta < 0.5) continue;
      // Away from the seam (u = 0) and from the joint (the cut at y ≈ 1).
      const double seam = std::min(exact.u, 1 - exact.u);
      if (seam < 1.0 / n || std::abs(exact.position.y - 1) < 0.05) continue;
      ++compared;
      EXPECT_EQ(got.frustum, ref.frustum);
      EXPECT_EQ(got.chain, exact.chain);
      EXPECT_EQ(got.segment, exact.segment);
      EXPECT_EQ(got.material, exact.material);
      EXPECT_EQ(got.plant, 0u);
      // u: linear across a facet against the angle, at a point up to the sagitta away:
      // within 3% of a column (measured 2.8%). Above the bent joint the mesh keeps the
      // generators through the frustum below's points, labelled u = i/n, while the analytic
      // u is the upper frustum's own angle: within 30% of a column there (measured 26%).
      const double du = std::abs(got.u - exact.u);
      EXPECT_LT(std::min(du, 1 - du), (straight ? 0.03 : 0.3) / n) << "u " << exact.u;
      // v_m: the points differ by the depth error, about the sagitta (0.5·(1 − cos(π/64))).
      EXPECT_NEAR(got.v_m, exact.v_m, straight ? 2e-4 : 1e-3);
      EXPECT_GE(got.u, 0.0);
      EXPECT_LT(got.u, 1.0);
      // Normals: the facet's within π/n of the cone's (above the bent joint the columns,
      // through the frustum below's points, are unevenly spaced: 1.1·π/n measured); the
      // interpolated one closer still.
      EXPECT_GT(glm::dot(got.geometric_normal, exact.geometric_normal),
                straight ? std::cos(kPi / n) - 1e-9 : std::cos(1.25 * kPi / n));
      EXPECT_GT(glm::dot(got.shading_normal, exact.shading_normal), std::cos(0.5 * kPi / n));
      EXPECT_NEAR(glm::length(got.shading_normal), 1, 1e-12);
      // Tangents: one turn is the circumference; one metre of v_m is one metre along a
      // straight chain's generator, and the generator's length over the segment's between
      // tilted cuts (±10% here) on the bent one, where the analytic dp_dv takes 1.
      const double r = std::hypot(exact.position.x, exact.position.z);
      if (straight) {
        // (a facet's dp_du is its row's chord times n: the radius of the row, which differs
        // from the hit's by up to a row's taper, 0.1/8 m of 0.3..0.5 m here)
        EXPECT_NEAR(glm::length(got.dp_du), 2 * kPi * r, 0.045 * 2 * kPi * r);
        EXPECT_NEAR(glm::length(got.dp_dv), 1, 0.01);
      } else {
        EXPECT_NEAR(glm::length(got.dp_dv), 1, 0.12);
      }
      EXPECT_GT(glm::dot(glm::normalize(got.dp_du), glm::normalize(exact.dp_du)), straight ? 0.998 : 0.98);
      EXPECT_GT(glm::dot(glm::normalize(got.dp_dv), glm::normalize(exact.dp_dv)), 0.99);
      // The position is on the ray at t.
      const glm::dvec3 p = ray.origin + got.t * ray.direction;
      EXPECT_LT(glm::length(p - got.position), 1e-12);
    }
    EXPECT_GT(compared, 3000);
  }
}

TEST(MeshTracer, ASeamTriangleInterpolatesUpToOneNotAcrossTheWrap) {
  Pair pair(chain_of({{0, 0, 0, 0.5}, {0, 2, 0, 0.5}}), 0);
  const TriangleMesh& mesh = pair.mesh->mesh();
  // Side triangles (every vertex at one radius from the axis) span one column: their uvs
  // differ by 1/8 at most, so u never wraps inside a triangle.
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    double lo = 2, hi = -1;
    bool side = true;
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = mesh.indices[3 * t + c];
      lo = std::min(lo, mesh.uvs[v].x), hi = std::max(hi, mesh.uvs[v].x);
      side = side && std::abs(std::hypot(mesh.positions[v].x, mesh.positions[v].z) - 0.5) < 1e-12;
    }
    if (side) {
      EXPECT_LE(hi - lo, 1.0 / 8 + 1e-12) << "triangle " << t;
    }
  }
  // A ray hitting just before the seam reports u just below 1; after it, just above 0.
  const AxisFrame frame = axis_frame(pair.skinned.frusta[0].shape.axis);
  const double u_offset = pair.skinned.frusta[0].u_offset;
  for (double u : {0.995, 0.005}) {
    const double raw = 2 * kPi * (u + u_offset);
    const glm::dvec3 radial = std::cos(raw) * frame.e0 + std::sin(raw) * frame.e1;
    const Ray ray{glm::dvec3(0, 1, 0) + 3.0 * radial, -radial};
    const SurfaceHit hit = pair.mesh->nearest(ray, 0, kInf);
    ASSERT_TRUE(hit.hit());
    EXPECT_NEAR(hit.u, u, 1e-3);
  }
}

TEST(MeshTracer, FarOffsetsLoseNothing) {
  const Skeleton cylinder = chain_of({{0, 0, 0, 0.5}, {0, 2, 0, 0.5}});
  const glm::dvec3 offset(1e6, 0, -1e6);
  Pair near(cylinder, 2), far(cylinder, 2, offset);
  const std::vector<Ray> near_rays = ring_rays(0.2, 1.8), far_rays = ring_rays(0.2, 1.8, offset);
  int compared = 0;
  for (size_t i = 0; i < near_rays.size(); ++i) {
    const SurfaceHit a = near.mesh->nearest(near_rays[i], 0, kInf), b = far.mesh->nearest(far_rays[i], 0, kInf);
    ASSERT_EQ(a.hit(), b.hit()) << "ray " << i;
    if (!a.hit()) continue;
    ++compared;
    // Double arithmetic on coordinates of 10^6: ~1e-10 m, far below the geometry's error.
    EXPECT_NEAR(a.t * glm::length(near_rays[i].direction), b.t * glm::length(far_rays[i].direction), 1e-8);
    EXPECT_EQ(a.frustum, b.frustum);
    EXPECT_NEAR(a.u, b.u, 1e-8);
  }
  EXPECT_GT(compared, 4000);
  TessellateOptions o;
  o.level = 2;
  const DepthError e = depth_error(far, far_rays, tessellation_columns(o), 0.5);
  EXPECT_LE(e.worst_ratio, 1 + 1e-9);
}

TEST(MeshTracer, AShadowRayLeavingTheSurfaceNeverFindsTheTriangleItLeft) {
  // The renderer offsets a shadow ray by 1e-7·max(1, |p|) along the geometric normal; the
  // float traversal alone could find the triangle again, the double range filter cannot.
  for (const glm::dvec3& offset : {glm::dvec3(0), glm::dvec3(3e4, 0, 0)}) {
    Pair pair(chain_of({{0, 0, 0, 0.5}, {0, 2, 0, 0.5}}), 3, offset);
    int tested = 0;
    for (const Ray& ray : ring_rays(0.2, 1.8, offset)) {
      const SurfaceHit hit = pair.mesh->nearest(ray, 0, kInf);
      if (!hit.hit()) continue;
      const glm::dvec3 p = hit.position;
      const double scale = std::max({1.0, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
      // Leaving at a grazing 80° from the normal, toward the side.
      const glm::dvec3 tangent = glm::normalize(glm::cross(hit.geometric_normal, glm::dvec3(0, 1, 0)));
      const glm::dvec3 out = std::cos(1.4) * hit.geometric_normal + std::sin(1.4) * tangent;
      EXPECT_FALSE(pair.mesh->any({p + (1e-7 * scale) * hit.geometric_normal, out}, 0, kInf));
      ++tested;
    }
    EXPECT_GT(tested, 4000);
  }
}

TEST(MeshTracer, AnyAndNearestRespectTheRange) {
  Pair pair(chain_of({{0, 0, 0, 0.5}, {0, 2, 0, 0.5}}), 2);
  const Ray ray{{0, 1, 5}, {0, 0, -1}};  // meets the mesh at z ≈ 0.5 and z ≈ −0.5
  const SurfaceHit first = pair.mesh->nearest(ray, 0, kInf);
  ASSERT_TRUE(first.hit());
  EXPECT_NEAR(first.t, 4.5, 1e-12);  // a column passes through (0, y, ±0.5): exact there
  const SurfaceHit second = pair.mesh->nearest(ray, first.t, kInf);
  ASSERT_TRUE(second.hit());
  EXPECT_GT(second.t, 5.0);
  EXPECT_GT(glm::dot(second.geometric_normal, ray.direction), 0);  // outward normal: seen from inside
  EXPECT_TRUE(pair.mesh->any(ray, 0, kInf));
  EXPECT_FALSE(pair.mesh->any(ray, 0, 4.4));
  EXPECT_FALSE(pair.mesh->nearest(ray, 0, 4.4).hit());
  EXPECT_TRUE(pair.mesh->any(ray, 4.6, kInf));
}

TEST(MeshTracer, DescribesItselfAndCountsItsMemory) {
  Pair pair(chain_of({{0, 0, 0, 0.5}, {0, 2, 0, 0.5}}), 1);
  const size_t triangles = pair.mesh->mesh().triangle_count();
  EXPECT_EQ(triangles, 64u + 2u * 16u);
  EXPECT_EQ(pair.mesh->describe(), "Embree triangles, 96 triangles (GS 1)");
  EXPECT_GT(pair.mesh->memory_bytes(), pair.mesh->mesh().memory_bytes());
  const std::vector<uint32_t> plants(pair.skinned.frusta.size(), 0);
  MeshTracer displaced(pair.mesh->mesh(), pair.skinned.frusta, plants, 2, true);
  EXPECT_EQ(displaced.describe(), "Embree triangles, 96 triangles (GS+R 2)");
  MeshTracer empty(TriangleMesh{}, {}, {}, 0);
  EXPECT_FALSE(empty.nearest({{0, 0, 0}, {1, 0, 0}}, 0, kInf).hit());
  EXPECT_FALSE(empty.any({{0, 0, 0}, {1, 0, 0}}, 0, kInf));
}

Scene saguaro_scene(uint32_t width, uint32_t height) {
  return default_scene_for(test::grow_preset("saguaro"), width, height);
}

TEST(MeshTracer, SaguaroRenderAtLevelThreeAgreesWithTheAnalyticOnHitAndMiss) {
  const Scene scene = saguaro_scene(160, 120);
  RenderOptions exact, mesh;
  exact.aovs = mesh.aovs = kAovDepth | kAovId;
  mesh.geometry.kind = GeometryKind::mesh;
  mesh.geometry.mesh_level = 3;
  const RenderResult a = render_cpu(scene, exact), b = render_cpu(scene, mesh);
  size_t either = 0, disagree = 0, both = 0, same_id = 0;
  for (size_t p = 0; p < a.image.depth.size(); ++p) {
    const bool ha = std::isfinite(a.image.depth[p]), hb = std::isfinite(b.image.depth[p]);
    either += ha || hb;
    disagree += ha != hb;
    if (ha && hb) {
      ++both;
      same_id += a.image.id[3 * p + 1] == b.image.id[3 * p + 1] && a.image.id[3 * p + 2] == b.image.id[3 * p + 2];
    }
  }
  ASSERT_GT(either, 1000u);
  EXPECT_LE(static_cast<double>(disagree), 0.01 * static_cast<double>(either)) << disagree << " of " << either;
  EXPECT_GE(static_cast<double>(same_id), 0.98 * static_cast<double>(both));
  // The passes say what was built.
  bool tessellated = false, described = false;
  for (const RenderPass& pass : b.passes) {
    tessellated = tessellated || (pass.name == "tessellate" && pass.detail.find("GS 3") != std::string::npos);
    described = described || (pass.name == "accel build" && pass.detail.find("Embree triangles") != std::string::npos);
  }
  EXPECT_TRUE(tessellated);
  EXPECT_TRUE(described);
}

// GS+R: the saguaro with the bundled ribbed cactus height map (20 ribs, 2 cm deep).
Scene ribbed_saguaro_scene(uint32_t width, uint32_t height) {
  Scene scene = saguaro_scene(width, height);
  Bark& bark = scene.plants[0].bark;
  bark.height_texture = std::string(SYLVA_SOURCE_DIR) + "/presets/textures/cactus_height.png";
  bark.relief_depth_m = 0.02;
  bark.u_repeat = 20;
  bark.v_per_metre = 13;
  return scene;
}

TEST(MeshTracer, HeightFunctionIsTheReliefDepthTimesTheReliefField) {
  Scene scene = ribbed_saguaro_scene(16, 12);
  scene.plants.push_back(scene.plants[0]);
  scene.plants[1].bark = Bark{};  // no height map
  Expected<std::unique_ptr<SceneTextures>> opened = SceneTextures::open(scene);
  ASSERT_TRUE(opened.ok()) << opened.error().format();
  const HeightFn height = height_function_for(**opened, 0);
  ASSERT_TRUE(height);
  EXPECT_FALSE(height_function_for(**opened, 1));
  const ReliefMap map = (*opened)->relief_map(0);
  for (double u : {0.0, 0.013, 0.025, 0.4, 0.999})
    for (double v_m : {0.0, 0.3, 2.71}) {
      const double h = std::clamp(map.field->height(u * 20, v_m * 13), 0.0, 1.0);
      EXPECT_EQ(height(u, v_m), 0.02 * h) << u << ", " << v_m;
    }
  // One rib per 1/20 turn: groove (s = 0) low, crest (s = 0.5) high.
  EXPECT_LT(height(0.0, 0.1), 0.004);
  EXPECT_GT(height(0.025, 0.1), 0.016);
}

TEST(MeshTracer, DisplacedSaguaroAgreesWithTheReliefMappedFrusta) {
  const Scene scene = ribbed_saguaro_scene(160, 120);
  RenderOptions relief, gsr;
  relief.aovs = gsr.aovs = kAovDepth;
  gsr.geometry.kind = GeometryKind::mesh;
  gsr.geometry.mesh_level = 3;
  const RenderResult a = render_cpu(scene, relief), b = render_cpu(scene, gsr);
  size_t either = 0, disagree = 0;
  for (size_t p = 0; p < a.image.depth.size(); ++p) {
    const bool ha = std::isfinite(a.image.depth[p]), hb = std::isfinite(b.image.depth[p]);
    either += ha || hb;
    disagree += ha != hb;
  }
  EXPECT_LE(static_cast<double>(disagree), 0.01 * static_cast<double>(either)) << disagree << " of " << either;
  bool displaced = false, described = false;
  for (const RenderPass& pass : b.passes) {
    displaced = displaced || (pass.name == "displace" && pass.detail == "1 plants by their height maps");
    described = described || (pass.name == "accel build" && pass.detail.find("(GS+R 3)") != std::string::npos);
  }
  EXPECT_TRUE(displaced);
  EXPECT_TRUE(described);
  // Without displacement the mesh is the plain GS mesh.
  gsr.geometry.displace = false;
  for (const RenderPass& pass : render_cpu(scene, gsr).passes) EXPECT_NE(pass.name, "displace");
}

TEST(MeshTracer, GsrDisplacesTwigsNoDeeperThanTheReliefShell) {
  // A 1 cm twig under a 2 cm relief: relief.h thins the shell to max_depth_per_radius·r
  // (0.5 cm), and the displaced mesh stays inside that shell; a 30 cm stem gets the full 2 cm.
  for (const double radius : {0.01, 0.3}) {
    Scene scene;
    ScenePlant plant;
    plant.skeleton = chain_of({{0, 0, 0, radius}, {0, 1, 0, radius}});
    plant.bark.height_texture = std::string(SYLVA_SOURCE_DIR) + "/presets/textures/cactus_height.png";
    plant.bark.relief_depth_m = 0.02;
    plant.bark.u_repeat = 4;
    scene.plants.push_back(plant);
    scene.camera.eye = {0, 0.5, 3};
    scene.camera.target = {0, 0.5, 0};
    GeometryOptions o;
    o.kind = GeometryKind::mesh;
    o.mesh_level = 2;
    const SceneGeometry g = build_scene_geometry(scene, {}, o);
    const auto* tracer = dynamic_cast<const MeshTracer*>(g.tracer.get());
    ASSERT_NE(tracer, nullptr);
    const double shell = std::min(0.02, o.relief_options.max_depth_per_radius * radius);
    double lifted = 0;
    for (const glm::dvec3& p : tracer->mesh().positions) lifted = std::max(lifted, std::hypot(p.x, p.z) - radius);
    EXPECT_LE(lifted, shell + 1e-12) << "radius " << radius;
    EXPECT_GT(lifted, 0.9 * shell) << "radius " << radius;  // the crests reach it
  }
}

TEST(Displace, AScalePerVertexMultipliesTheHeight) {
  const SkinnedSkeleton sk = skin_skeleton(chain_of({{0, 0, 0, 0.5}, {0, 2, 0, 0.5}}));
  TessellateOptions o;
  o.caps = false;
  const TriangleMesh mesh = tessellate(sk, o);
  std::vector<double> scale(mesh.positions.size());
  for (size_t v = 0; v < scale.size(); ++v) scale[v] = mesh.positions[v].y / 2;  // 0 at the bottom, 1 at the top
  const TriangleMesh displaced = displace(mesh, [](double, double) { return 0.1; }, scale);
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::dvec3& p = displaced.positions[v];
    EXPECT_NEAR(std::hypot(p.x, p.z), 0.5 + 0.1 * scale[v], 1e-12);
  }
}

}  // namespace
}  // namespace sylva
