// gl_update_test.cpp — GlRenderer::update_plants (animation, Bhagvat et al. 2009 sec. 4): moving a
// skeleton and re-uploading its records gives the picture a renderer built on the moved
// scene gives, for the bytes of the records alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/gl/render_gl.h"
#include "core/geometry/skin.h"
#include "tests/support/gl_checks.h"

namespace sylva {
namespace {

Scene two_segment_scene() {
  Skeleton sk;
  sk.joints = {{{0, 0, 0}, 0.3, 0}, {{0, 1, 0}, 0.25, 0}, {{0, 2, 0}, 0.2, 0}};
  sk.chains = {{0, 3, std::nullopt}};
  return gl_test::scene_around(sk, 128, 96);
}

// Bends the top joint sideways by `dx` metres.
void bend(Scene& scene, double dx) { scene.plants[0].skeleton->joints[2].position_m[0] += dx; }

double max_abs_difference(const RenderImage& a, const RenderImage& b) {
  double m = 0;
  for (size_t i = 0; i < a.beauty.size(); ++i) m = std::max(m, static_cast<double>(std::fabs(a.beauty[i] - b.beauty[i])));
  return m;
}

TEST(GlUpdate, ReuploadedRecordsDrawTheMovedSkeleton) {
  SYLVA_REQUIRE_GL();
  Scene scene = two_segment_scene();
  RenderOptions options;
  GlRenderer renderer(scene, options);
  const RenderResult before = renderer.render(scene);
  // 17°: under the 20° from which skinning rounds a bend into an arc of more frusta
  // (docs/joints.md), so the topology stays and only the records move.
  bend(scene, 0.3);
  const uint64_t bytes = renderer.update_plants(scene);
  EXPECT_EQ(bytes, renderer.frusta() * sizeof(GpuSegment));  // the records, nothing else
  const RenderResult after = renderer.render(scene);
  GlRenderer fresh(scene, options);
  const RenderResult expected = fresh.render(scene);
  EXPECT_EQ(max_abs_difference(after.image, expected.image), 0.0);
  EXPECT_GT(max_abs_difference(after.image, before.image), 0.1);  // the bend is visible
}

TEST(GlUpdate, ANewTopologyReallocates) {
  SYLVA_REQUIRE_GL();
  Scene scene = two_segment_scene();
  RenderOptions options;
  GlRenderer renderer(scene, options);
  const uint64_t frusta_before = renderer.frusta();
  scene.plants[0].skeleton->joints.push_back({{0, 3, 0}, 0.1, 0});
  scene.plants[0].skeleton->chains[0].joint_count = 4;
  const uint64_t bytes = renderer.update_plants(scene);
  EXPECT_GT(renderer.frusta(), frusta_before);
  EXPECT_EQ(bytes, renderer.frusta() * (sizeof(GpuSegment) + 16));  // records and ids
  GlRenderer fresh(scene, options);
  EXPECT_EQ(max_abs_difference(renderer.render(scene).image, fresh.render(scene).image), 0.0);
}

TEST(GlUpdate, RefusesADifferentPlantCount) {
  SYLVA_REQUIRE_GL();
  Scene scene = two_segment_scene();
  GlRenderer renderer(scene, RenderOptions{});
  scene.plants.push_back(scene.plants[0]);
  EXPECT_THROW(renderer.update_plants(scene), std::invalid_argument);
}

}  // namespace
}  // namespace sylva
