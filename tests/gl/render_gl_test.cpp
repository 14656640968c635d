// render_gl_test.cpp — the GL ray caster against the CPU reference (render_gl.h): the
// same scene through render_gl and render_cpu, compared pixel by pixel. Tolerances: hit/miss
// agreement >= 99.5 % of pixels, median relative depth error <= 1e-4, mean absolute beauty
// difference <= 1/255 on the sRGB-encoded values a PNG holds (stricter than linear). On a
// failure the two images and their difference are written to the test's temporary folder.
#include "core/gl/render_gl.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <filesystem>

#include "core/gl/gl_program.h"
#include "core/scene/scene_json.h"
#include "tests/support/plants.h"
#include "tests/support/test_scenes.h"
#include "tests/support/gl_checks.h"

namespace sylva {
namespace {

using gl_test::Agreement;

using gl_test::chain_of;

// Renders `scene` on both backends (depth AOV) and checks the tolerances.
Agreement expect_matches_cpu(const std::string& name, const Scene& scene) {
  RenderOptions options;
  options.aovs = kAovDepth;
  return gl_test::expect_matches_cpu(name, scene, options);
}

TEST(RenderGl, SingleSegmentMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  expect_matches_cpu("single_segment", gl_test::scene_around(chain_of({{{0, 0, 0}, 0.3, 0}, {{0, 2, 0}, 0.2, 0}})));
}

TEST(RenderGl, BentJointMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  // 40° at the middle joint: a mitred joint, one shared cutting plane.
  const double a = 40 * 3.14159265358979 / 180;
  expect_matches_cpu("bent_joint", gl_test::scene_around(chain_of({{{0, 0, 0}, 0.25, 0},
                                                                   {{0, 1.5, 0}, 0.22, 0},
                                                                   {{1.5 * std::sin(a), 1.5 + 1.5 * std::cos(a), 0}, 0.18, 0}})));
}

TEST(RenderGl, SharpBendWithAKnuckleMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  // 150°: split into capped legs and a knuckle ball.
  expect_matches_cpu("sharp_bend", gl_test::scene_around(chain_of({{{0, 0, 0}, 0.2, 0},
                                                                   {{0, 1.5, 0}, 0.2, 0},
                                                                   {{0.75, 1.5 - 1.3, 0.1}, 0.2, 0}})));
}

TEST(RenderGl, BranchMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  Skeleton sk;
  sk.joints = {{{0, 0, 0}, 0.25, 0}, {{0, 1.2, 0}, 0.2, 0}, {{0, 2.4, 0}, 0.15, 0},
               {{0, 1.2, 0}, 0.1, 1},  {{0.8, 2.0, 0.3}, 0.06, 1}};
  sk.chains = {{0, 3, std::nullopt}, {3, 2, ChainParent{0, 1}}};
  expect_matches_cpu("branch", gl_test::scene_around(sk));
}

TEST(RenderGl, TipMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  // A cone ending in a point (radius 0): eq. 8 falls back to the exact normal there.
  expect_matches_cpu("tip", gl_test::scene_around(chain_of({{{0, 0, 0}, 0.3, 0}, {{0, 1, 0}, 0.2, 0}, {{0.2, 2, 0}, 0.0, 1}})));
}

TEST(RenderGl, SaguaroMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  expect_matches_cpu("saguaro", gl_test::scene_around(test::grow_preset("saguaro")));
}

TEST(RenderGl, ElmMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  expect_matches_cpu("elm", gl_test::scene_around(test::grow_preset("elm")));
}

// ---- Stiff cases (the skinning issue's): no NaN, and still the CPU's picture ----------

TEST(RenderGl, AMillionMetresFromTheOriginMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  Skeleton sk = chain_of({{{0, 0, 0}, 0.05, 0}, {{0, 0.4, 0}, 0.04, 0}, {{0.1, 0.8, 0}, 0.02, 1}});
  Scene scene = gl_test::scene_around(sk);
  const glm::dvec3 offset(1e6, 0, -1e6);
  scene.plants.front().position = offset;
  scene.camera.eye += offset;
  scene.camera.target += offset;
  const Agreement a = expect_matches_cpu("million_metres", scene);
  EXPECT_EQ(a.nan_pixels, 0u);
}

TEST(RenderGl, GrazingViewsHaveNoNaNAndMatchTheCpu) {
  SYLVA_REQUIRE_GL();
  // Looking along a long thin horizontal cylinder, and nearly along its silhouette.
  Skeleton sk = chain_of({{{0, 1, 0}, 0.1, 0}, {{0, 1, -6}, 0.1, 0}});
  for (const auto& [name, eye] : {std::pair{"grazing_axis", glm::dvec3(0.02, 1.01, 3)},
                                  std::pair{"grazing_silhouette", glm::dvec3(0.1001, 1.3, 3)}}) {
    Scene scene = gl_test::scene_around(sk);
    scene.camera.eye = eye;
    scene.camera.target = {eye.x, eye.y - 0.05, -6};
    scene.camera.fov_y_deg = 30;
    const Agreement a = expect_matches_cpu(name, scene);
    EXPECT_EQ(a.nan_pixels, 0u) << name;
  }
}

TEST(RenderGl, EyeInsideABoundingPyramidStillSeesTheSurface) {
  SYLVA_REQUIRE_GL();
  // The eye inside a thick segment's pyramid but outside the cone: its front faces are
  // behind the eye; the back-face pass (EYE_INSIDE) must draw it.
  Skeleton sk = chain_of({{{0, 0, 0}, 1.0, 0}, {{0, 4, 0}, 1.0, 0}});
  Scene scene = gl_test::scene_around(sk);
  // The pyramid's square cross-section spans |x|, |z| <= 1 here (axis_frame of +Y is x, −z).
  scene.camera.eye = {0.9, 2, 0.9};  // outside the cylinder (r = 1.27 > 1), inside the square
  scene.camera.target = {0, 2.5, -3};
  scene.camera.fov_y_deg = 60;
  expect_matches_cpu("eye_inside_pyramid", scene);
  const RenderResult gl = gl_test::gl_render(scene, {});
  bool drawn_from_inside = false;
  for (const RenderPass& p : gl.passes) drawn_from_inside |= p.detail.find("1 around the eye") != std::string::npos;
  EXPECT_TRUE(drawn_from_inside) << "the EYE_INSIDE pass did not run";
}

TEST(RenderGl, AovsFollowTheCpuConventions) {
  SYLVA_REQUIRE_GL();
  Scene scene = gl_test::scene_around(chain_of({{{0, 0, 0}, 0.3, 0}, {{0, 2, 0}, 0.2, 2}}), 64, 48);
  RenderOptions options;
  options.aovs = kAovDepth | kAovNormal | kAovUv | kAovId;
  const RenderResult cpu = gl_test::cpu_render(scene, options);
  const RenderResult gl = gl_test::gl_render(scene, options);
  ASSERT_EQ(gl.image.normal.size(), cpu.image.normal.size());
  ASSERT_EQ(gl.image.uv.size(), cpu.image.uv.size());
  ASSERT_EQ(gl.image.id.size(), cpu.image.id.size());
  int both = 0;
  for (size_t p = 0; p < gl.image.depth.size(); ++p) {
    const bool gl_hit = !std::isinf(gl.image.depth[p]), cpu_hit = !std::isinf(cpu.image.depth[p]);
    if (!gl_hit) {
      EXPECT_EQ(gl.image.id[p * 3 + 1], -1.0f);
      EXPECT_EQ(gl.image.normal[p * 3], 0.0f);
      continue;
    }
    if (!cpu_hit) continue;
    ++both;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(gl.image.normal[p * 3 + k], cpu.image.normal[p * 3 + k], 1e-4) << p;
      EXPECT_EQ(gl.image.id[p * 3 + k], cpu.image.id[p * 3 + k]) << p;
    }
    // u in turns wraps at 1: compare on the circle.
    const double du = std::abs(gl.image.uv[p * 2] - cpu.image.uv[p * 2]);
    EXPECT_LT(std::min(du, 1 - du), 1e-4) << p;
    EXPECT_NEAR(gl.image.uv[p * 2 + 1], cpu.image.uv[p * 2 + 1], 1e-4) << p;
  }
  EXPECT_GT(both, 100);
}

TEST(RenderGl, MoreSamplesConvergeToTheCpu) {
  SYLVA_REQUIRE_GL();
  // --spp 16: both average 16 stratified positions and (disc sun) 16 sun directions.
  Scene scene = gl_test::scene_around(test::grow_preset("saguaro"), 128, 96);
  RenderOptions options;
  options.spp = 16;
  options.aovs = kAovDepth;
  const RenderResult cpu = gl_test::cpu_render(scene, options);
  const RenderResult gl = gl_test::gl_render(scene, options);
  const Agreement a = gl_test::compare(gl.image, cpu.image);
  std::printf("[ agreement ] saguaro 16 spp 128x96: %s\n", a.describe().c_str());
  EXPECT_LE(a.beauty_mad_srgb, 1.0 / 255) << a.describe() << "\n  images: "
                                          << gl_test::write_diff_images("saguaro_16spp", gl.image, cpu.image);
  EXPECT_GE(a.hit_miss, 0.995);  // AOVs at the pixel centres, as the CPU's
}

TEST(RenderGl, ScenesTheGlBackendCannotDrawAreNamed) {
  Scene scene = gl_test::scene_around(chain_of({{{0, 0, 0}, 0.3, 0}, {{0, 2, 0}, 0.2, 0}}));
  EXPECT_FALSE(gl_unsupported(scene, {}));
  scene.plants.front().bark.albedo_texture = "bark.png";
  scene.plants.front().bark.height_texture = "bark_height.png";
  EXPECT_FALSE(gl_unsupported(scene, {})) << "bark textures and relief are drawn";
  // More distinct images than texture units to bind them to.
  const ScenePlant plant = scene.plants.front();
  for (int i = 0; i < 9; ++i) {
    scene.plants.push_back(plant);
    scene.plants.back().bark.albedo_texture = "bark" + std::to_string(i) + ".png";
    scene.plants.back().bark.height_texture = "height" + std::to_string(i) + ".png";
  }
  ASSERT_TRUE(gl_unsupported(scene, {}));
  EXPECT_NE(gl_unsupported(scene, {})->find("16 distinct bark images"), std::string::npos);
  RenderOptions no_relief;
  no_relief.geometry.relief = false;  // the height maps are then not uploaded
  EXPECT_FALSE(gl_unsupported(scene, no_relief));
}

// ---- Bark: relief mapping (Bhagvat et al. 2009 sec. 3) and albedo textures ------------------------

std::string texture_path(const std::string& name) { return std::string(SYLVA_SOURCE_DIR) + "/presets/textures/" + name; }

// A 2 m segment tapering from 0.3 to 0.2 m, relief-mapped with the cactus ribs (8 around,
// 4 cm deep) where `height`, textured with `albedo` where given.
Scene bark_segment(const char* albedo, const char* height, uint32_t width = 256, uint32_t height_px = 192) {
  Scene scene = gl_test::scene_around(chain_of({{{0, 0, 0}, 0.3, 0}, {{0, 2, 0}, 0.2, 0}}), width, height_px);
  Bark& bark = scene.plants.front().bark;
  if (albedo) bark.albedo_texture = texture_path(albedo);
  if (height) bark.height_texture = texture_path(height);
  bark.relief_depth_m = 0.04;
  bark.u_repeat = 8;
  bark.v_per_metre = 4;
  return scene;
}

// The variants a render built ("programs" passes), for --verbose.
std::string program_names(const RenderResult& r) {
  std::string names;
  for (const RenderPass& p : r.passes)
    if (p.name == "programs") names += p.detail + "; ";
  return names;
}

TEST(RenderGl, ReliefMappedSegmentMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  const Scene scene = bark_segment(nullptr, "cactus_height.png");
  expect_matches_cpu("relief_segment", scene);
  const std::string names = program_names(gl_test::gl_render(scene, {}));
  EXPECT_NE(names.find("frusta[GBUFFER_PASS RELIEF TEXTURE_UNITS=1]"), std::string::npos) << names;
  EXPECT_NE(names.find("frusta[SHADOW_PASS RELIEF]"), std::string::npos) << names;
}

TEST(RenderGl, ReliefShowsInTheSilhouetteAndTheShading) {
  SYLVA_REQUIRE_GL();
  // The relief is really drawn: against the same segment without relief, pixels appear
  // (the shell's ribs beyond the cone) and disappear (grooves), and both backends agree
  // on which.
  RenderOptions options;
  options.aovs = kAovDepth;
  const Scene relief = bark_segment(nullptr, "cactus_height.png");
  Scene plain = relief;
  plain.plants.front().bark.height_texture.reset();
  const RenderResult gl_relief = gl_test::gl_render(relief, options), gl_plain = gl_test::gl_render(plain, options);
  const RenderResult cpu_relief = gl_test::cpu_render(relief, options);
  size_t changed = 0, changed_on_cpu_too = 0, beauty_changed = 0;
  for (size_t p = 0; p < gl_relief.image.depth.size(); ++p) {
    const bool hit = !std::isinf(gl_relief.image.depth[p]), plain_hit = !std::isinf(gl_plain.image.depth[p]);
    if (hit != plain_hit) {
      ++changed;
      changed_on_cpu_too += hit == !std::isinf(cpu_relief.image.depth[p]);
    }
    beauty_changed += std::abs(gl_relief.image.beauty[p * 4] - gl_plain.image.beauty[p * 4]) > 0.02f;
  }
  std::printf("[ relief ] %zu silhouette pixels changed (%zu as on the CPU), %zu beauty pixels changed\n", changed,
              changed_on_cpu_too, beauty_changed);
  EXPECT_GT(changed, 50u);
  EXPECT_GE(changed_on_cpu_too, changed * 9 / 10);
  EXPECT_GT(beauty_changed, 500u);
}

TEST(RenderGl, BarkTexturedSegmentMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  const Scene scene = bark_segment("bark.png", nullptr);
  expect_matches_cpu("bark_segment", scene);
  const std::string names = program_names(gl_test::gl_render(scene, {}));
  EXPECT_NE(names.find("frusta[GBUFFER_PASS BARK TEXTURE_UNITS=1]"), std::string::npos) << names;
  EXPECT_EQ(names.find("RELIEF"), std::string::npos) << names;
}

TEST(RenderGl, CloseUpBarkTextureMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  // Magnified texels and a grazing footprint toward the silhouette.
  Scene scene = bark_segment("bark.png", nullptr);
  scene.camera.eye = {0.9, 1.0, 0.9};
  scene.camera.target = {0, 1.1, 0};
  scene.camera.fov_y_deg = 40;
  expect_matches_cpu("bark_close_up", scene);
}

TEST(RenderGl, ReliefAndBarkTogetherMatchTheCpu) {
  SYLVA_REQUIRE_GL();
  const Scene scene = bark_segment("cactus.png", "cactus_height.png");
  expect_matches_cpu("relief_bark_segment", scene);
  const std::string names = program_names(gl_test::gl_render(scene, {}));
  EXPECT_NE(names.find("frusta[GBUFFER_PASS RELIEF BARK TEXTURE_UNITS=2]"), std::string::npos) << names;
}

TEST(RenderGl, PlantsWithoutBarkCompileNoBarkOrReliefCode) {
  SYLVA_REQUIRE_GL();
  Scene scene = bark_segment(nullptr, nullptr);
  const std::string names = program_names(gl_test::gl_render(scene, {}));
  EXPECT_NE(names.find("frusta[GBUFFER_PASS]"), std::string::npos) << names;
  EXPECT_EQ(names.find("RELIEF"), std::string::npos) << names;
  EXPECT_EQ(names.find("BARK"), std::string::npos) << names;
  // A height map with the relief switched off: no relief code either.
  scene = bark_segment(nullptr, "cactus_height.png");
  RenderOptions options;
  options.geometry.relief = false;
  EXPECT_EQ(program_names(gl_test::gl_render(scene, options)).find("RELIEF"), std::string::npos);
}

// The programs a renderer built itself ("programs" setup pass, and any a frame added).
std::string built_by(GlRenderer& renderer, const Scene& scene) {
  std::string names;
  for (const RenderPass& p : renderer.setup_passes())
    if (p.name == "programs") names += p.detail;
  const RenderResult r = renderer.render(scene);
  for (const RenderPass& p : r.passes)
    if (p.name == "programs") names += "; " + p.detail;
  return names;
}

TEST(RenderGl, RenderersSharingAProgramCacheBuildEachVariantOnce) {
  SYLVA_REQUIRE_GL();
  // The studio makes a renderer per regrown plant on one context: the second renderer of
  // the same kind of plant builds nothing, one of another kind only its own variants, and
  // a shared program draws the same picture as a renderer's own.
  const Scene relief = bark_segment(nullptr, "cactus_height.png");
  const Scene plain = bark_segment(nullptr, nullptr);
  auto cache = std::make_shared<GlProgramCache>();
  std::vector<float> first_beauty;
  {
    GlRenderer first(relief, {}, cache);
    EXPECT_NE(built_by(first, relief).find("frusta[GBUFFER_PASS RELIEF TEXTURE_UNITS=1]"), std::string::npos);
    first_beauty = first.render(relief).image.beauty;
  }
  const size_t after_first = cache->size();
  EXPECT_GE(after_first, 3u);  // frusta G-buffer and shadow, shade (and present)
  {
    GlRenderer other(plain, {}, cache);
    const std::string names = built_by(other, plain);
    EXPECT_NE(names.find("frusta[GBUFFER_PASS]"), std::string::npos) << names;
    EXPECT_EQ(names.find("shade["), std::string::npos) << names;  // the shade program is shared
  }
  const size_t after_other = cache->size();
  EXPECT_GT(after_other, after_first);
  GlRenderer again(relief, {}, cache);
  EXPECT_EQ(built_by(again, relief), "");
  EXPECT_EQ(cache->size(), after_other);
  EXPECT_EQ(again.render(relief).image.beauty, first_beauty);
  // Against a renderer with its own programs, at the same frame: the same bytes.
  GlRenderer own(relief, {});
  own.render(relief);
  EXPECT_EQ(own.render(relief).image.beauty, first_beauty);
}

TEST(RenderGl, GrazingReliefHasNoNaNAndMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  // Looking along a long relief-mapped horizontal cylinder, and nearly along its shell's
  // silhouette: the shell interval's roots and the marcher at their most ill-conditioned.
  Skeleton sk = chain_of({{{0, 1, 0}, 0.1, 0}, {{0, 1, -6}, 0.1, 0}});
  for (const auto& [name, eye] : {std::pair{"grazing_relief_axis", glm::dvec3(0.02, 1.01, 3)},
                                  std::pair{"grazing_relief_silhouette", glm::dvec3(0.1401, 1.3, 3)}}) {
    Scene scene = gl_test::scene_around(sk, 192, 144);
    Bark& bark = scene.plants.front().bark;
    bark.height_texture = texture_path("bark_height.png");
    bark.albedo_texture = texture_path("bark.png");
    bark.relief_depth_m = 0.04;
    bark.u_repeat = 3;
    bark.v_per_metre = 2;
    scene.camera.eye = eye;
    scene.camera.target = {eye.x, eye.y - 0.05, -6};
    scene.camera.fov_y_deg = 30;
    const Agreement a = expect_matches_cpu(name, scene);
    EXPECT_EQ(a.nan_pixels, 0u) << name;
  }
}

TEST(RenderGl, BarkCoversTheWoodOnlyAndNeedlesKeepTheirColour) {
  SYLVA_REQUIRE_GL();
  // materials.h: the bark (albedo texture, height map) is material 0's. On the frusta
  // (relief marching) and on the displaced mesh, every needle pixel (material 1) is what
  // it is without a bark while the wood changes, and the barked scene matches the CPU.
  const Scene plain = gl_test::scene_around(test::wood_and_needle(), 128, 96);
  Scene barked = plain;
  Bark& bark = barked.plants.front().bark;
  bark.albedo_texture = texture_path("bark.png");
  bark.height_texture = texture_path("bark_height.png");
  bark.relief_depth_m = 0.04;
  bark.u_repeat = 3;
  for (const GeometryKind kind : {GeometryKind::frusta, GeometryKind::mesh}) {
    RenderOptions o;
    o.aovs = kAovDepth | kAovId;
    o.geometry.kind = kind;
    const RenderResult a = gl_test::gl_render(barked, o), b = gl_test::gl_render(plain, o);
    size_t needle = 0, needle_changed = 0, wood_changed = 0;
    for (size_t p = 0; p < a.image.depth.size(); ++p) {
      if (a.image.id[3 * p + 1] == 1 && b.image.id[3 * p + 1] == 1) {
        ++needle;
        // The RELIEF program variant rounds the exact intersection its own way (float).
        EXPECT_NEAR(a.image.depth[p], b.image.depth[p], 1e-5f * b.image.depth[p]) << p;
        float d = 0;
        for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(a.image.beauty[4 * p + k] - b.image.beauty[4 * p + k]));
        needle_changed += d > 1e-4f;
      } else if (a.image.id[3 * p + 1] == 0) {
        wood_changed += std::abs(a.image.beauty[4 * p] - b.image.beauty[4 * p]) > 0.01f;
      }
    }
    EXPECT_GT(needle, 400u);
    EXPECT_EQ(needle_changed, 0u) << "needle pixels changed by the bark";
    EXPECT_GT(wood_changed, 400u) << "the bark shows on the wood";
  }
  expect_matches_cpu("bark_wood_only", barked);
}

TEST(RenderGl, TheScenesMaterialTableMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  // docs/materials.md: the table's albedo and specular weight on the needle (material 1)
  // and the wood (0) under a bark colour, which comes first on the wood.
  Scene scene = gl_test::scene_around(test::wood_and_needle(), 128, 96);
  scene.materials[1] = SceneMaterial{glm::dvec3(0.6, 0.1, 0.5), 0.2};
  scene.materials[0] = SceneMaterial{glm::dvec3(0.1, 0.1, 0.9), 0};
  scene.plants.front().bark.albedo_rgb = glm::dvec3(0.8, 0.7, 0.1);
  RenderOptions o;
  o.aovs = kAovDepth | kAovId;
  const RenderResult gl = gl_test::gl_render(scene, o);
  size_t needle = 0, wood = 0;
  for (size_t p = 0; p < gl.image.depth.size(); ++p) {
    const float* px = &gl.image.beauty[4 * p];
    if (gl.image.id[3 * p + 1] == 1) needle += px[0] > 2 * px[1] && px[2] > 2 * px[1];  // magenta
    if (gl.image.id[3 * p + 1] == 0) wood += px[0] > 4 * px[2] && px[1] > 4 * px[2];    // the bark's yellow
  }
  EXPECT_GT(needle, 400u);
  EXPECT_GT(wood, 400u);
  expect_matches_cpu("material_table", scene);
}

TEST(RenderGl, TheTablesImageOnSegmentsMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  // docs/materials.md: an entry with an albedo image and u_repeat / v_per_metre lays the
  // image on its segments (the needle, material 1) on both geometries and both backends;
  // table entry 0's image gives way to the plant's bark colour on the wood.
  Scene plain = gl_test::scene_around(test::wood_and_needle(), 128, 96);
  plain.plants.front().bark.albedo_rgb = glm::dvec3(0.8, 0.7, 0.1);
  Scene textured = plain;
  textured.materials[1].albedo_image = texture_path("tiles.png");
  textured.materials[1].segment_repeat = SceneMaterial::Repeat{2, 1.5};
  textured.materials[0].albedo_image = texture_path("bark.png");
  textured.materials[0].segment_repeat = SceneMaterial::Repeat{};
  for (const GeometryKind kind : {GeometryKind::frusta, GeometryKind::mesh}) {
    RenderOptions o;
    o.aovs = kAovDepth | kAovId;
    o.geometry.kind = kind;
    const RenderResult a = gl_test::gl_render(textured, o), b = gl_test::gl_render(plain, o);
    size_t needle = 0, needle_changed = 0, wood = 0, wood_changed = 0;
    double lo = 1e9, hi = 0;  // the needle's luminance range
    for (size_t p = 0; p < a.image.depth.size(); ++p) {
      const float* pa = &a.image.beauty[4 * p];
      float d = 0;
      for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(pa[k] - b.image.beauty[4 * p + k]));
      if (a.image.id[3 * p + 1] == 1) {
        ++needle;
        needle_changed += d > 0.01f;
        lo = std::min(lo, double(pa[1])), hi = std::max(hi, double(pa[1]));
      } else if (a.image.id[3 * p + 1] == 0) {
        ++wood;
        wood_changed += d > 1e-4f;
      }
    }
    EXPECT_GT(needle, 400u);
    EXPECT_GT(needle_changed, needle / 2) << "the image shows on the needle";
    EXPECT_GT(hi, 2 * lo) << "the tiles' pattern, not one colour";
    EXPECT_GT(wood, 400u);
    EXPECT_EQ(wood_changed, 0u) << "the bark colour comes before the table's image";
    RenderOptions compared;
    compared.aovs = kAovDepth;
    compared.geometry.kind = kind;
    gl_test::expect_matches_cpu(kind == GeometryKind::mesh ? "segment_image_mesh" : "segment_image", textured, compared);
  }
}

// A bundled scene (presets/scenes/) at a small size.
Scene preset_scene(const std::string& name, uint32_t width, uint32_t height) {
  Scene scene = test::grown_preset_scene(name);
  scene.width = width;
  scene.height = height;
  return scene;
}

TEST(RenderGl, SaguaroSceneWithReliefAndBarkMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  expect_matches_cpu("saguaro_scene", preset_scene("saguaro", 256, 192));
}

TEST(RenderGl, PineSceneWithReliefAndBarkMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  // Under the sky alone: the relief and the bark, everything the two backends share.
  Scene scene = preset_scene("pine", 192, 144);
  Scene sky_only = scene;
  sky_only.sun.radiance = {0, 0, 0};
  expect_matches_cpu("pine_scene_sky", sky_only);
  // In the sun, the needles' shadows on the ground come from the shadow map on GL (a texel
  // is wider than a needle), from shadow rays on the CPU: that difference alone is ~2/255
  // here, with or without bark (measured: 2.33/255 without, 2.06/255 with). The relief
  // and bark must add nothing to it; hits and depths are unaffected by shadows.
  RenderOptions options;
  options.aovs = kAovDepth;
  Scene no_bark = scene;
  no_bark.plants.front().bark = Bark{};
  const Agreement plain = gl_test::compare(gl_test::gl_render(no_bark, options).image, gl_test::cpu_render(no_bark, options).image);
  const RenderResult gl = gl_test::gl_render(scene, options), cpu = gl_test::cpu_render(scene, options);
  const Agreement a = gl_test::compare(gl.image, cpu.image);
  std::printf("[ agreement ] pine_scene sunlit: %s\n  (without bark: %s)\n", a.describe().c_str(),
              plain.describe().c_str());
  const bool ok = a.hit_miss >= 0.995 && a.depth_median_rel <= 1e-4 && a.nan_pixels == 0 &&
                  a.beauty_mad_srgb <= plain.beauty_mad_srgb + 0.25 / 255;
  if (!ok)
    ADD_FAILURE() << a.describe() << "\n  images: " << gl_test::write_diff_images("pine_scene", gl.image, cpu.image);
}

TEST(RenderGl, ConservativeDepthCanBeSwitchedOffForTiming) {
  SYLVA_REQUIRE_GL();
  const Scene scene = bark_segment(nullptr, "cactus_height.png", 128, 96);
  RenderOptions options;
  options.aovs = kAovDepth;
  GlRenderer renderer(scene, options);
  const RenderResult with = renderer.render(scene);
  renderer.set_conservative_depth(false);
  const RenderResult without = renderer.render(scene);
  std::string passes;
  for (const RenderPass& p : without.passes) passes += p.name + ": " + p.detail + "; ";
  EXPECT_NE(passes.find("frusta[GBUFFER_PASS RELIEF TEXTURE_UNITS=1 NO_CONSERVATIVE_DEPTH]"), std::string::npos)
      << passes;
  EXPECT_NE(passes.find("frusta[SHADOW_PASS RELIEF NO_CONSERVATIVE_DEPTH]"), std::string::npos) << passes;
  // The same picture: only the promise to the depth test differs.
  EXPECT_EQ(with.image.depth, without.image.depth);
  EXPECT_EQ(with.image.beauty, without.image.beauty);
}

}  // namespace
}  // namespace sylva

namespace sylva {
namespace {

TEST(RenderGl, EveryPresetRendersWithoutNaN) {
  SYLVA_REQUIRE_GL();
  int presets = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(SYLVA_SOURCE_DIR) + "/presets")) {
    if (entry.path().extension() != ".lsys") continue;
    const std::string name = entry.path().stem().string();
    Scene scene = gl_test::scene_around(test::grow_preset(name), 96, 72);
    RenderOptions options;
    options.aovs = kAovDepth;
    const RenderResult r = gl_test::gl_render(scene, options);
    size_t nan = 0, hits = 0;
    for (float v : r.image.beauty) nan += std::isnan(v);
    for (float z : r.image.depth) hits += !std::isinf(z), nan += std::isnan(z);
    EXPECT_EQ(nan, 0u) << name;
    EXPECT_GT(hits, 0u) << name << ": nothing drawn";
    ++presets;
  }
  EXPECT_GE(presets, 10);
}

}  // namespace
}  // namespace sylva
