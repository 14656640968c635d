// gl_mesh_test.cpp — the polygon baseline on the GPU (core/gl/gl_mesh.h) against
// the CPU's mesh path (render_cpu.h, GeometryKind::mesh through Embree): the same scene
// and GeometryOptions through render_gl and render_cpu, compared pixel by pixel with the
// tolerances of render_gl_test.cpp — hit/miss agreement >= 99.5 % of pixels, median
// relative depth error <= 1e-4, mean absolute beauty difference <= 1/255 on sRGB values.
// The shadow map is the mesh's own (a sun shines in every scene here). On a failure the
// two images and their difference are written to the test's temporary folder.
#include "core/gl/gl_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/gl/render_gl.h"
#include "core/scene/scene_json.h"
#include "tests/support/gl_checks.h"
#include "tests/support/plants.h"

namespace sylva {
namespace {

using gl_test::Agreement;

using gl_test::chain_of;

RenderOptions mesh_options(int level, bool displace, uint32_t aovs = kAovDepth) {
  RenderOptions options;
  options.aovs = aovs;
  options.geometry.kind = GeometryKind::mesh;
  options.geometry.mesh_level = level;
  options.geometry.displace = displace;
  return options;
}

// Renders `scene` on both backends with `options` and checks the issue's tolerances;
// `program` (when given) must be the G-buffer variant GL drew with.
Agreement expect_mesh_matches_cpu(const std::string& name, const Scene& scene, const RenderOptions& options,
                                  const std::string& program = "") {
  if (auto why = gl_unsupported(scene, options)) {
    ADD_FAILURE() << name << ": gl_unsupported refuses it: " << *why;
    return {};
  }
  RenderResult gl;
  const std::string label = "mesh_" + name + (options.geometry.displace ? "_GS+R" : "_GS") +
                            std::to_string(options.geometry.mesh_level);
  const Agreement a = gl_test::expect_matches_cpu(label, scene, options, &gl);
  if (!program.empty()) {
    bool drawn = false;
    for (const RenderPass& p : gl.passes) drawn |= p.name == "mesh (GPU)" && p.detail.find(program) != std::string::npos;
    EXPECT_TRUE(drawn) << name << ": no mesh pass with " << program;
  }
  return a;
}

// The bundled ribbed saguaro (presets/scenes), small: a bark albedo texture and a height
// map (GS+R displaces by it).
Scene saguaro_scene(uint32_t width, uint32_t height) {
  Scene scene = test::grown_preset_scene("saguaro");
  scene.width = width;
  scene.height = height;
  return scene;
}

TEST(GlMesh, ASingleSegmentMatchesTheCpuMesh) {
  SYLVA_REQUIRE_GL();
  const Scene scene = gl_test::scene_around(chain_of({{{0, 0, 0}, 0.3, 0}, {{0, 2, 0}, 0.2, 0}}));
  for (int level : {0, 2}) expect_mesh_matches_cpu("single_segment", scene, mesh_options(level, false));
}

TEST(GlMesh, ABentJointMatchesTheCpuMesh) {
  SYLVA_REQUIRE_GL();
  const double a = 40 * 3.14159265358979 / 180;
  expect_mesh_matches_cpu("bent_joint",
                          gl_test::scene_around(chain_of({{{0, 0, 0}, 0.25, 0},
                                                          {{0, 1.5, 0}, 0.22, 0},
                                                          {{1.5 * std::sin(a), 1.5 + 1.5 * std::cos(a), 0}, 0.18, 0}})),
                          mesh_options(2, false));
}

TEST(GlMesh, TheSaguaroSceneWithoutTexturesMatchesTheCpuMesh) {
  SYLVA_REQUIRE_GL();
  Scene scene = saguaro_scene(200, 150);
  scene.plants.front().bark = Bark{};
  expect_mesh_matches_cpu("saguaro_gs2", scene, mesh_options(2, false), "mesh[GBUFFER_PASS]");
}

TEST(GlMesh, TheSaguaroWithItsBarkAlbedoMatchesTheCpuMesh) {
  SYLVA_REQUIRE_GL();
  expect_mesh_matches_cpu("saguaro_gs2_albedo", saguaro_scene(200, 150), mesh_options(2, false),
                          "mesh[GBUFFER_PASS TEXTURE_UNITS=1]");
}

TEST(GlMesh, TheSaguaroDisplacedByItsHeightMapMatchesTheCpuMesh) {
  SYLVA_REQUIRE_GL();
  // GS+R: the ribs of cactus_height.png, 4 cm deep, moved into the triangles.
  const Scene scene = saguaro_scene(200, 150);
  ASSERT_TRUE(scene.plants.front().bark.height_texture);
  expect_mesh_matches_cpu("saguaro_gsr2", scene, mesh_options(2, true), "mesh[GBUFFER_PASS TEXTURE_UNITS=1]");
  // And the displacement is really there: the GS+R picture is not the GS one.
  RenderOptions flat = mesh_options(2, false), ribbed = mesh_options(2, true);
  const Agreement a = gl_test::compare(gl_test::gl_render(scene, ribbed).image, gl_test::gl_render(scene, flat).image);
  EXPECT_GT(a.depth_max_rel, 1e-3) << a.describe();
}

TEST(GlMesh, AMillionMetresFromTheOriginMatchesTheCpuMesh) {
  SYLVA_REQUIRE_GL();
  Scene scene = gl_test::scene_around(chain_of({{{0, 0, 0}, 0.05, 0}, {{0, 0.4, 0}, 0.04, 0}, {{0.1, 0.8, 0}, 0.02, 1}}));
  const glm::dvec3 offset(1e6, 0, -1e6);
  scene.plants.front().position = offset;
  scene.camera.eye += offset;
  scene.camera.target += offset;
  expect_mesh_matches_cpu("million_metres", scene, mesh_options(2, false));
}

TEST(GlMesh, MoreSamplesConvergeToTheCpuMesh) {
  SYLVA_REQUIRE_GL();
  // --spp 9: both average 9 stratified positions and 9 directions on the sun's disc (the
  // shadow map redrawn per pass from the mesh); AOVs at the pixel centres.
  RenderOptions options = mesh_options(2, true);
  options.spp = 9;
  const Scene scene = saguaro_scene(120, 90);
  const RenderResult cpu = gl_test::cpu_render(scene, options);
  const RenderResult gl = gl_test::gl_render(scene, options);
  const Agreement a = gl_test::compare(gl.image, cpu.image);
  std::printf("[ agreement ] saguaro GS+R 2, 9 spp 120x90: %s\n", a.describe().c_str());
  EXPECT_LE(a.beauty_mad_srgb, 1.0 / 255) << a.describe() << "\n  images: "
                                          << gl_test::write_diff_images("mesh_saguaro_9spp", gl.image, cpu.image);
  EXPECT_GE(a.hit_miss, 0.995);
  EXPECT_LE(a.depth_median_rel, 1e-4);
}

TEST(GlMesh, AovsFollowTheCpuMesh) {
  SYLVA_REQUIRE_GL();
  const Scene scene = gl_test::scene_around(chain_of({{{0, 0, 0}, 0.3, 0}, {{0, 2, 0}, 0.2, 2}}), 64, 48);
  const RenderOptions options = mesh_options(1, false, kAovDepth | kAovNormal | kAovUv | kAovId);
  // The rasteriser interpolates from vertices snapped to its sub-pixel grid (1/256 pixel on
  // llvmpipe, as on GPUs), so an attribute moves by what it changes over ~1/256 pixel: the
  // shading normal turns 0.39 rad across a triangle a few pixels wide here (measured: up to
  // 2.3e-4). The CPU's barycentrics are exact. Ids must agree exactly.
  constexpr double kNormalTolerance = 1e-3, kUvTolerance = 5e-4;
  const RenderResult cpu = gl_test::cpu_render(scene, options);
  const RenderResult gl = gl_test::gl_render(scene, options);
  ASSERT_EQ(gl.image.normal.size(), cpu.image.normal.size());
  int both = 0;
  for (size_t p = 0; p < gl.image.depth.size(); ++p) {
    const bool gl_hit = !std::isinf(gl.image.depth[p]), cpu_hit = !std::isinf(cpu.image.depth[p]);
    if (!gl_hit || !cpu_hit) continue;
    ++both;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(gl.image.normal[p * 3 + k], cpu.image.normal[p * 3 + k], kNormalTolerance) << p;
      EXPECT_EQ(gl.image.id[p * 3 + k], cpu.image.id[p * 3 + k]) << p;
    }
    const double du = std::abs(gl.image.uv[p * 2] - cpu.image.uv[p * 2]);
    EXPECT_LT(std::min(du, 1 - du), kUvTolerance) << p;
    EXPECT_NEAR(gl.image.uv[p * 2 + 1], cpu.image.uv[p * 2 + 1], kUvTolerance) << p;
  }
  EXPECT_GT(both, 100);
}

TEST(GlMesh, TheRendererReportsTrianglesBytesAndTheMeshPass) {
  SYLVA_REQUIRE_GL();
  const Scene scene = gl_test::scene_around(chain_of({{{0, 0, 0}, 0.3, 0}, {{0, 2, 0}, 0.2, 0}}), 32, 24);
  const RenderOptions options = mesh_options(1, false);
  EXPECT_FALSE(gl_unsupported(scene, options));
  GlRenderer renderer(scene, options);
  const RenderResult r = renderer.render(scene);
  EXPECT_EQ(r.frusta, 1u);
  // One segment at m = 1: 16·4 side triangles and two capped ends of 16 fan triangles.
  const RenderPass* mesh_pass = nullptr;
  for (const RenderPass& p : r.passes)
    if (p.name == "mesh (GPU)") mesh_pass = &p;
  ASSERT_TRUE(mesh_pass);
  EXPECT_NE(mesh_pass->detail.find("96 triangles (GS 1)"), std::string::npos) << mesh_pass->detail;
  // 3 rows × 17 grid vertices + 2 caps of 18: 36 B each; 96 triangles of 12 B; one 32 B record.
  EXPECT_EQ(r.geometry_bytes, (3u * 17 + 2 * 18) * 36 + 96 * 12 + 32);
  EXPECT_EQ(renderer.uploaded_bytes(), r.geometry_bytes);
  for (const RenderPass& p : r.passes) EXPECT_NE(p.name, "frusta (GPU)");
}

TEST(GlMesh, MovedPlantsAreTessellatedAgain) {
  SYLVA_REQUIRE_GL();
  Scene scene = gl_test::scene_around(chain_of({{{0, 0, 0}, 0.3, 0}, {{0, 2, 0}, 0.2, 0}}), 64, 48);
  const RenderOptions options = mesh_options(1, false);
  GlRenderer renderer(scene, options);
  renderer.render(scene);
  Scene moved = scene;
  double* top = moved.plants.front().skeleton->joints[1].position_m;
  top[0] = 0.4, top[1] = 1.9;
  EXPECT_EQ(renderer.update_plants(moved), renderer.uploaded_bytes());
  const RenderResult updated = renderer.render(moved);
  const RenderResult fresh = gl_test::gl_render(moved, options);
  EXPECT_EQ(updated.image.beauty, fresh.image.beauty);
}

}  // namespace
}  // namespace sylva
