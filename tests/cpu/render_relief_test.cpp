// render_relief_test.cpp — relief mapping in the tracer and the renderer: relief plants go
// through the marcher for nearest and shadow rays, other plants stay exact; a scene with a
// height map renders with relief (depth within the shell), one without does no marching.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>

#include "core/cpu/frustum_tracer.h"
#include "core/geometry/relief.h"
#include "core/cpu/render_cpu.h"
#include "tests/support/test_scenes.h"
#include "tests/support/test_textures.h"

namespace sylva {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

class ConstantField final : public HeightField {
 public:
  explicit ConstantField(double h) : h_(h) {}
  double height(double, double) const override { return h_; }
  double gradient_step_s() const override { return 1e-3; }
  double gradient_step_t() const override { return 1e-3; }

 private:
  double h_;
};

// A vertical capped cylinder frustum of radius r around (x, ·, 0), y from 0 to 2.
Frustum cylinder_frustum(double x, double r) {
  Frustum f;
  f.shape.base = {x, 0, 0};
  f.shape.radius0 = f.shape.radius1 = r;
  f.shape.length = 2;
  f.shape.lower = {{0, 1, 0}, 0};
  f.shape.upper = {{0, 1, 0}, 2};
  f.shape.cap_lower = f.shape.cap_upper = true;
  f.v_upper_m = 2;
  return f;
}

TEST(FrustumTracerRelief, ReliefPlantsGoThroughTheMarcherForNearestAndShadowRays) {
  const ConstantField half(0.5);
  const std::vector<Frustum> frusta = {cylinder_frustum(0, 1), cylinder_frustum(5, 1)};
  const std::vector<uint32_t> plants = {0, 1};
  SceneRelief relief;
  relief.plants.resize(2);
  relief.plants[0] = {&half, 0.2, 4, 1};  // plant 0: relief solid of radius 1.1; plant 1 exact
  const FrustumTracer tracer(frusta, plants, relief);
  EXPECT_EQ(tracer.relief_plants(), 1u);
  EXPECT_EQ(tracer.relief_frusta(), 1u);
  EXPECT_NE(tracer.describe().find("1 relief-mapped"), std::string::npos) << tracer.describe();

  // 1.15 from the axis: inside plant 0's shell (1.2), outside its relief (1.1).
  const Ray grazing{{1.15, 1, -5}, {0, 0, 1}};
  EXPECT_FALSE(tracer.nearest(grazing, 0, kInf).hit());
  EXPECT_FALSE(tracer.any(grazing, 0, kInf));
  // 1.05 from it: the relief of radius 1.1, for nearest and any alike.
  const Ray through{{1.05, 1, -5}, {0, 0, 1}};
  const SurfaceHit hit = tracer.nearest(through, 0, kInf);
  ASSERT_TRUE(hit.hit());
  EXPECT_EQ(hit.plant, 0u);
  const ReliefHit direct = intersect_relief(through, frusta[0], relief.plants[0], relief.options, 0, kInf);
  EXPECT_EQ(hit.t, direct.hit.t);
  EXPECT_EQ(hit.u, direct.u);
  EXPECT_EQ(hit.shading_normal, direct.shading_normal);
  EXPECT_NEAR(glm::length(glm::dvec3(hit.position.x, 0, hit.position.z)), 1.1, 1e-4);
  EXPECT_TRUE(tracer.any(through, 0, kInf));
  EXPECT_FALSE(tracer.any(through, 0, 0.5 * hit.t));  // the range is honoured
  // Plant 1 is exact: the same t as intersect_frustum, no shell.
  const Ray exact{{5.95, 1, -5}, {0, 0, 1}};
  const SurfaceHit e = tracer.nearest(exact, 0, kInf);
  ASSERT_TRUE(e.hit());
  EXPECT_EQ(e.plant, 1u);
  EXPECT_EQ(e.t, intersect_frustum(exact, frusta[1].shape, 0, kInf).t);
  EXPECT_FALSE(tracer.any({{6.05, 1, -5}, {0, 0, 1}}, 0, kInf));
}

TEST(FrustumTracerRelief, WithoutReliefTheTracerIsTheExactOne) {
  const std::vector<Frustum> frusta = {cylinder_frustum(0, 1)};
  const std::vector<uint32_t> plants = {0};
  const FrustumTracer tracer(frusta, plants);
  EXPECT_EQ(tracer.relief_frusta(), 0u);
  const Ray ray{{0.3, 1, -5}, {0, 0, 1}};
  EXPECT_EQ(tracer.nearest(ray, 0, kInf).t, intersect_frustum(ray, frusta[0].shape, 0, kInf).t);
}

// The cylinder of render_cpu_test, bark optionally relief-mapped by vertical ribs.
Scene ribbed_cylinder_scene(const std::string& height_path) {
  Scene s = test::scene_around(test::cylinder(0.5, 0, 2), {0, 1, 5}, {0, 1, 0}, 96, 72, -10);
  ScenePlant& plant = s.plants[0];
  if (!height_path.empty()) {
    plant.bark.height_texture = height_path;
    plant.bark.relief_depth_m = 0.05;
    plant.bark.u_repeat = 8;
  }
  return s;
}

std::string pass_detail(const RenderResult& r, const std::string& name) {
  for (const RenderPass& p : r.passes)
    if (p.name == name) return p.detail;
  return "(no pass named " + name + ")";
}

TEST(RenderRelief, HeightMapSceneRendersWithReliefWithinTheShell) {
  test::TempFolder dir;
  const std::string path = dir.file("ribs.exr");
  test::write_gray_float(path, 32, 8, [](uint32_t x, uint32_t) {
    return static_cast<float>(0.5 + 0.5 * std::sin(2 * std::numbers::pi * (x + 0.5) / 32));
  });
  const Scene scene = ribbed_cylinder_scene(path);
  RenderOptions with, without;
  with.aovs = without.aovs = kAovDepth | kAovNormal;
  with.threads = without.threads = 2;
  without.geometry.relief = false;
  const RenderResult a = render_cpu(scene, with), b = render_cpu(scene, without);
  EXPECT_EQ(pass_detail(a, "relief"), "1 plant, 32 linear + 8 bisection steps, v exact");
  EXPECT_EQ(pass_detail(b, "relief"), "none");
  const double d = 0.05, r = 0.5;
  int both = 0, deep = 0, relief_only = 0, plain_only = 0;
  for (uint32_t y = 0; y < scene.height; ++y)
    for (uint32_t x = 0; x < scene.width; ++x) {
      const size_t p = static_cast<size_t>(y) * scene.width + x;
      const bool ha = !std::isinf(a.image.depth[p]), hb = !std::isinf(b.image.depth[p]);
      relief_only += ha && !hb;
      plain_only += hb && !ha;
      if (!ha || !hb) continue;
      const Ray ray = camera_ray(scene, x + 0.5, y + 0.5);
      const glm::dvec3 n(b.image.normal[p * 3], b.image.normal[p * 3 + 1], b.image.normal[p * 3 + 2]);
      const double cos_incidence = std::abs(glm::dot(n, glm::normalize(ray.direction)));
      if (cos_incidence < 0.3) continue;  // the silhouette band
      // The relief lies between the cylinder and its shell: in front of the plain hit by
      // at most the chord between radii r and r + d, d·(1 + d/2r)/cos θ.
      const double delta = static_cast<double>(b.image.depth[p]) - a.image.depth[p];
      EXPECT_GE(delta, -1e-5) << x << "," << y;
      EXPECT_LE(delta, d * (1 + d / (2 * r)) / cos_incidence + 1e-5) << x << "," << y;
      if (cos_incidence > 0.9) {
        EXPECT_LE(delta, d / 0.9 * (1 + d / (2 * r)) + 1e-5);
      }
      deep += delta > d / 4;
      ++both;
    }
  EXPECT_GT(both, 500);
  EXPECT_GT(deep, 50);             // the ribs' valleys are deeper than d/4
  EXPECT_EQ(plain_only, 0);        // the relief solid contains the cylinder
  EXPECT_GT(relief_only, 0);       // the ribs stand out on the silhouette
}

TEST(RenderRelief, SceneWithoutHeightMapDoesNoMarching) {
  const Scene scene = ribbed_cylinder_scene("");
  RenderOptions o;
  o.aovs = kAovDepth;
  o.threads = 2;
  const RenderResult r = render_cpu(scene, o);
  EXPECT_EQ(pass_detail(r, "relief"), "none");
  EXPECT_EQ(pass_detail(r, "textures"), "(no pass named textures)");
  // Relief switched off on a height-map scene renders the exact cylinder, bit for bit.
  test::TempFolder dir;
  const std::string path = dir.file("ribs.exr");
  test::write_gray_float(path, 4, 4, [](uint32_t x, uint32_t) { return x / 4.0f; });
  RenderOptions off = o;
  off.geometry.relief = false;
  const RenderResult plain = render_cpu(ribbed_cylinder_scene(path), off);
  EXPECT_EQ(plain.image.depth, r.image.depth);
  EXPECT_EQ(pass_detail(plain, "relief"), "none");
}

}  // namespace
}  // namespace sylva
