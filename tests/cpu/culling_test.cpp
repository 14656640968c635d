// culling_test.cpp — a plant that can affect no pixel is left out (docs/spec/scene.md), and only
// such a plant: not one whose shadow falls into the view, never one in view, and leaving
// plants out changes no pixel.
#include "core/scene/culling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <glm/geometric.hpp>

#include "core/cpu/render_cpu.h"
#include "core/geometry/tessellate.h"
#include "tests/support/plants.h"

namespace sylva {
namespace {

Skeleton pole() {  // a vertical pole, 3 m tall, radius 0.2
  Skeleton sk;
  sk.joints = {{{0, 0, 0}, 0.2, 0}, {{0, 1.5, 0}, 0.2, 0}, {{0, 3, 0}, 0.15, 0}};
  sk.chains = {{0, 3, std::nullopt}};
  return sk;
}

// Camera at z = 10 looking down −z at the origin; ground y = 0; a hard sun.
Scene scene_with(const std::vector<glm::dvec3>& positions, const glm::dvec3& sun_direction) {
  Scene s;
  s.width = 64;
  s.height = 48;
  s.camera.eye = {0, 1.5, 10};
  s.camera.target = {0, 1.5, 0};
  s.camera.fov_y_deg = 40;
  s.sun.direction = glm::normalize(sun_direction);
  s.sun.angular_radius_deg = 0;
  for (const glm::dvec3& p : positions) {
    ScenePlant plant;
    plant.skeleton = pole();
    plant.position = p;
    s.plants.push_back(plant);
  }
  return s;
}

bool culled(const Scene& s, size_t plant) {
  return plant_is_culled(s, view_frustum(s), plant_box(place_plant(s.plants[plant]), SkinOptions{}));
}

std::string culling_detail(const RenderResult& r) {
  for (const RenderPass& p : r.passes)
    if (p.name == "culling") return p.detail;
  return "<no culling pass>";
}

TEST(Culling, APlantBehindTheCameraIsCulled) {
  // The sun stands beyond the view: shadows fall toward +z, further behind the camera.
  const Scene s = scene_with({{0, 0, 20}}, {0, 1, -1});
  EXPECT_TRUE(culled(s, 0));
}

TEST(Culling, APlantInViewIsKept) {
  const Scene s = scene_with({{0, 0, 0}, {4, 0, -30}}, {0.4, 1, 0.2});
  EXPECT_FALSE(culled(s, 0));
  EXPECT_FALSE(culled(s, 1));
}

TEST(Culling, APlantOutsideTheViewWhoseLeafReachesIntoItIsKept) {
  // 8 m to the right, the view ±4.9 m wide there, a sun overhead: the pole and its shadow
  // stay outside; a leaf from its top reaching 5 m to the left does not.
  Scene s = scene_with({{8, 0, 0}}, {0, 1, 0});
  ASSERT_TRUE(culled(s, 0));
  s.plants[0].skeleton->leaves = {Leaf{ChainParent{0, 2}, 1, {{0, 2.5, 0}, {-5, 2.5, 0}, {-5, 3, 0}}, std::nullopt}};
  EXPECT_FALSE(culled(s, 0));
  RenderOptions o;
  o.aovs = kAovId;
  const RenderResult r = render_cpu(s, o);
  EXPECT_NE(std::count(r.image.id.begin(), r.image.id.end(), kAovLeafChain), 0);
}

TEST(Culling, APlantOutsideTheViewWhoseShadowFallsIntoItIsKept) {
  // 30 m to the right (the view is ±4.9 m wide there), a low sun from the right: the
  // 3 m pole's shadow reaches 3/0.1 = 30 m to the left, across the view.
  const Scene s = scene_with({{30, 0, 0}}, {1, 0.1, 0});
  ASSERT_TRUE(outside_view(view_frustum(s), plant_box(place_plant(s.plants[0]), SkinOptions{})));
  EXPECT_FALSE(culled(s, 0));
  // The shadow is really there: the picture differs from the empty scene's (at 256×192
  // the 0.4 m wide shadow line 10 m away covers pixel centres).
  Scene wide = s;
  wide.width = 256;
  wide.height = 192;
  Scene empty = wide;
  empty.plants.clear();
  ScenePlant far_away;  // keeps the renderer's plant list non-empty and out of the way
  far_away.skeleton = pole();
  far_away.position = {0, 0, 100};
  empty.plants.push_back(far_away);
  RenderOptions o;
  EXPECT_NE(render_cpu(wide, o).image.beauty, render_cpu(empty, o).image.beauty);
  // A higher sun keeps the shadow out of the view: then it is culled.
  EXPECT_TRUE(culled(scene_with({{30, 0, 0}}, {1, 1, 0}), 0));
}

TEST(Culling, APlantWithoutSunCastsNoShadowAndIsCulledOutsideTheView) {
  Scene s = scene_with({{30, 0, 0}}, {1, 0.1, 0});
  s.sun.radiance = {0, 0, 0};
  EXPECT_TRUE(culled(s, 0));
}

TEST(Culling, ASunDiscWidensTheShadowConservatively) {
  // The box's shadow (box: x ± 0.42, top 3.32 m) reaches x = 40.5 − 0.42 − 33.2 ≈ 6.9,
  // right of the view (±6.0 m at z = −2.4): culled under a point sun, kept when a wide
  // disc can throw it further.
  Scene s = scene_with({{40.5, 0, -2}}, {1, 0.1, 0});
  EXPECT_TRUE(culled(s, 0));
  s.sun.angular_radius_deg = 3;
  EXPECT_FALSE(culled(s, 0));
}

TEST(Culling, ASunOnTheHorizonShadowsWithoutEndOnlyAwayFromTheLight) {
  // Shadows along −l = +x, away from the view: culled; toward it: kept.
  EXPECT_TRUE(culled(scene_with({{30, 0, 0}}, {-1, 0, 0}), 0));
  EXPECT_FALSE(culled(scene_with({{30, 0, 0}}, {1, 0, 0}), 0));
  EXPECT_FALSE(culled(scene_with({{30, 0, 0}}, {1, 0.01, 0}), 0));
}

TEST(Culling, RenderingWithAndWithoutCullingGivesIdenticalImages) {
  // One plant in view, one behind the camera, one far to the side with its shadow in view.
  const Scene s = scene_with({{0, 0, 0}, {0.5, 0, 25}, {30, 0, -3}}, {1, 0.1, 0.3});
  ASSERT_FALSE(culled(s, 0));
  ASSERT_TRUE(culled(s, 1));
  ASSERT_FALSE(culled(s, 2));
  RenderOptions on, off;
  on.aovs = off.aovs = kAovDepth | kAovNormal | kAovUv | kAovId;
  off.geometry.cull = false;
  const RenderResult a = render_cpu(s, on), b = render_cpu(s, off);
  EXPECT_EQ(a.image.beauty, b.image.beauty);
  EXPECT_EQ(a.image.depth, b.image.depth);
  EXPECT_EQ(a.image.normal, b.image.normal);
  EXPECT_EQ(a.image.uv, b.image.uv);
  EXPECT_EQ(a.image.id, b.image.id);
  EXPECT_EQ(culling_detail(a), "1 of 3 plants culled");
  EXPECT_EQ(culling_detail(b), "<no culling pass>");
  EXPECT_LT(a.frusta, b.frusta);
  // The mesh geometry culls the same way.
  on.geometry.kind = off.geometry.kind = GeometryKind::mesh;
  const RenderResult c = render_cpu(s, on), d = render_cpu(s, off);
  EXPECT_EQ(culling_detail(c), "1 of 3 plants culled");
  size_t differ = 0;
  for (size_t p = 0; p < c.image.depth.size(); ++p) differ += c.image.depth[p] != d.image.depth[p];
  EXPECT_EQ(differ, 0u);
}

TEST(Culling, ThePlantBoxHoldsTheWholeSkinnedSurfaceOfEveryPreset) {
  // Mitred cuts reach beyond the joints' spheres, knuckles too: every tessellated vertex
  // (on the analytic surface, 64 around every cut curve) lies in plant_box.
  for (const char* name : {"saguaro", "elm", "pine", "aloe_vera", "coconut_palm", "cactus", "abop_1_24a"}) {
    ScenePlant plant;
    plant.skeleton = test::grow_preset(name);
    plant.position = {5, 1, -2};
    plant.rotate_y_deg = 30;
    plant.scale = 1.7;
    const Skeleton placed = place_plant(plant);
    const Aabb box = plant_box(placed, SkinOptions{});
    TessellateOptions o;
    o.segments_around = 64;
    const TriangleMesh mesh = tessellate(skin_skeleton(placed), o);
    size_t outside = 0;
    for (const glm::dvec3& p : mesh.positions)
      outside += glm::any(glm::lessThan(p, box.lo)) || glm::any(glm::greaterThan(p, box.hi));
    EXPECT_EQ(outside, 0u) << name;
  }
  // A sharp bend: split, capped and closed by a knuckle ball.
  Skeleton bent;
  bent.joints = {{{0, 0, 0}, 0.3, 0}, {{0, 1, 0}, 0.3, 0}, {{0.2, 0.1, 0}, 0.3, 0}};
  bent.chains = {{0, 3, std::nullopt}};
  const SkinnedSkeleton skinned = skin_skeleton(bent);
  ASSERT_EQ(skinned.split_joints, 1u);
  const Aabb box = plant_box(bent, SkinOptions{});
  TessellateOptions o;
  o.segments_around = 64;
  for (const glm::dvec3& p : tessellate(skinned, o).positions) {
    EXPECT_FALSE(glm::any(glm::lessThan(p, box.lo)));
    EXPECT_FALSE(glm::any(glm::greaterThan(p, box.hi)));
  }
}

TEST(Culling, TheViewFrustumPassesThroughTheImageCorners) {
  const Scene s = scene_with({}, {0, 1, 0});
  const ViewFrustum view = view_frustum(s);
  for (const auto& [x, y] : {std::pair{0.0, 0.0}, {64.0, 0.0}, {0.0, 48.0}, {64.0, 48.0}}) {
    const Ray r = camera_ray(s, x, y);
    int on = 0;
    for (int k = 0; k < 4; ++k) {
      const double d = glm::dot(view.planes[k].normal, r.origin + 7.0 * r.direction) - view.planes[k].offset;
      EXPECT_GE(d, -1e-12);
      on += std::abs(d) < 1e-12;
    }
    EXPECT_EQ(on, 2) << x << "," << y;  // a corner ray lies on two side planes
  }
  // Just inside and just outside a box's reach.
  EXPECT_FALSE(outside_view(view, Aabb{{-0.1, 1, -0.1}, {0.1, 2, 0.1}}));
  EXPECT_TRUE(outside_view(view, Aabb{{-0.1, 1, 10.5}, {0.1, 2, 11}}));  // behind the eye
}

// pixels_per_radian (crotch.h crotch_seen's view): the most pixels a radian spans anywhere
// in the image, measured as the angle between the rays of neighbouring pixel positions —
// nowhere more than it says (a feature it calls under 2 pixels is), and as much at the
// corners, along the diagonal (where a pinhole's pixels subtend the least angle).
TEST(Culling, PixelsPerRadianIsTheMostAnyPixelOfTheImageSpans) {
  for (const auto& [w, h, fov] : {std::tuple{64u, 48u, 40.0}, {1024u, 768u, 35.0}, {200u, 150u, 90.0}}) {
    Scene s = scene_with({}, {0, 1, 0});
    s.width = w;
    s.height = h;
    s.camera.fov_y_deg = fov;
    const double said = pixels_per_radian(s);
    auto angle = [&](double x0, double y0, double x1, double y1) {
      const glm::dvec3 a = glm::normalize(camera_ray(s, x0, y0).direction);
      const glm::dvec3 b = glm::normalize(camera_ray(s, x1, y1).direction);
      return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
    };
    double most = 0;
    for (int i = 0; i <= 8; ++i) {
      for (int j = 0; j <= 8; ++j) {
        const double x = std::clamp(w * i / 8.0, 0.5, w - 0.5), y = std::clamp(h * j / 8.0, 0.5, h - 0.5);
        most = std::max({most, 0.01 / angle(x - 0.005, y, x + 0.005, y), 0.01 / angle(x, y - 0.005, x, y + 0.005)});
      }
    }
    const double diagonal = std::hypot(double(w), double(h));  // from the corner toward the centre
    const double corner = 0.01 / angle(0, 0, 0.01 * w / diagonal, 0.01 * h / diagonal);
    EXPECT_LE(most, said * (1 + 1e-6)) << w << "x" << h << " fov " << fov;
    EXPECT_NEAR(corner, said, 1e-3 * said) << w << "x" << h << " fov " << fov;
  }
}

}  // namespace
}  // namespace sylva
