// texture_test.cpp — bark textures (texture.h): the ray-differential footprint against its
// analytic value, sRGB decoding after filtering, height fields read through OpenImageIO,
// errors that name the file, and a textured render.
#include "core/cpu/texture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>

#include "core/cpu/render_cpu.h"
#include "core/util/color.h"
#include "core/util/image_io.h"
#include "tests/support/test_scenes.h"
#include "tests/support/test_textures.h"

namespace sylva {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

using test::cylinder;
using test::scene_around;

TEST(TextureFootprint, PlaneLikeCylinderSeenHeadOnMatchesTheAnalyticFootprint) {
  // A cylinder of radius 50 m seen from 10 m: locally a plane facing the camera. A pixel
  // step moves the hit by D·2·tan(fov/2)/height metres (the image plane at distance D),
  // which is that many metres / (2π R) turns around and as many metres along.
  const double radius = 50, distance = 10;
  Scene s = scene_around(cylinder(radius, -20, 20), {0, 0, radius + distance}, {0, 0, 0}, 640, 480);
  const SceneGeometry g = build_scene_geometry(s, {});
  const Ray ray = camera_ray(s, 320, 240);  // exactly along the view axis
  const SurfaceHit hit = g.tracer->nearest(ray, 0, kInf);
  ASSERT_TRUE(hit.hit());
  const UvFootprint f = uv_footprint(hit, camera_ray(s, 321, 240), camera_ray(s, 320, 241));
  const double metres_per_pixel = distance * 2 * std::tan(20 * std::numbers::pi / 180) / 480;
  EXPECT_NEAR(std::abs(f.du_dx), metres_per_pixel / (2 * std::numbers::pi * radius), 1e-6 * f.du_dx);
  EXPECT_NEAR(f.dv_dx, 0, 1e-9);
  EXPECT_NEAR(f.du_dy, 0, 1e-9);
  EXPECT_NEAR(f.dv_dy, -metres_per_pixel, 1e-6 * metres_per_pixel);  // y runs downward
  // Scaled by u_repeat and v_per_metre this is TextureSystem's dsdx, dtdy.
}

TEST(TextureFootprint, DegenerateCasesGiveTheZeroFootprintNotNaN) {
  SurfaceHit hit;
  hit.t = 1;
  hit.position = {0, 0, 0};
  hit.geometric_normal = {0, 0, 1};
  hit.dp_du = {1, 0, 0};
  hit.dp_dv = {0, 1, 0};
  // Rays parallel to the tangent plane.
  UvFootprint f = uv_footprint(hit, {{0, 0, 1}, {1, 0, 0}}, {{0, 0, 1}, {0, 1, 0}});
  EXPECT_EQ(f.du_dx, 0);
  EXPECT_EQ(f.dv_dy, 0);
  // Degenerate tangents (a tip: dp_du = 0).
  hit.dp_du = {0, 0, 0};
  f = uv_footprint(hit, {{0.1, 0, 1}, {0, 0, -1}}, {{0, 0.1, 1}, {0, 0, -1}});
  EXPECT_EQ(f.du_dx, 0);
  EXPECT_EQ(f.dv_dx, 0);
  EXPECT_FALSE(std::isnan(f.dv_dy));
}

TEST(Texture, HeightTextureIsChannelZeroPeriodicAndATexelApart) {
  test::TempFolder dir;
  const std::string path = dir.file("h.exr");
  test::write_gray_float(path, 4, 2, [](uint32_t x, uint32_t y) { return (x + 4.0f * y) / 8.0f; });
  Scene s;
  s.plants.resize(2);
  s.plants[1].bark.height_texture = path;
  s.plants[1].bark.relief_depth_m = 0.03;
  s.plants[1].bark.u_repeat = 5;
  s.plants[1].bark.v_per_metre = 2;
  Expected<std::unique_ptr<SceneTextures>> opened = SceneTextures::open(s);
  ASSERT_TRUE(opened.ok()) << opened.error().format();
  const SceneTextures& t = **opened;
  EXPECT_FALSE(t.has_height(0));
  ASSERT_TRUE(t.has_height(1));
  EXPECT_FALSE(t.has_albedo(1, 0));
  const ReliefMap map = t.relief_map(1);
  ASSERT_NE(map.field, nullptr);
  EXPECT_EQ(map.depth_m, 0.03);
  EXPECT_EQ(map.u_repeat, 5);
  EXPECT_EQ(map.v_per_metre, 2);
  EXPECT_EQ(map.field->gradient_step_s(), 0.25);
  EXPECT_EQ(map.field->gradient_step_t(), 0.5);
  for (uint32_t y = 0; y < 2; ++y)
    for (uint32_t x = 0; x < 4; ++x) {
      const double s_centre = (x + 0.5) / 4, t_centre = (y + 0.5) / 2;
      const double expected = (x + 4.0 * y) / 8.0;
      EXPECT_NEAR(map.field->height(s_centre, t_centre), expected, 1e-6) << x << "," << y;
      EXPECT_NEAR(map.field->height(s_centre + 3, t_centre - 2), expected, 1e-5) << "periodic";
    }
  // Bilinear between texel centres.
  EXPECT_NEAR(map.field->height(0.25, 0.25), 0.5 * (0.0 + 1.0 / 8), 1e-6);
}

TEST(Texture, HeightSamplerEqualsTheTextureSystemsBilinearFinestLevel) {
  // The marcher's own bilinear sampler against OpenImageIO's lookup at a zero footprint
  // (the finest level, bilinear), at random points, seams included.
  test::TempFolder dir;
  const std::string path = dir.file("h.exr");
  test::write_gray_float(path, 37, 11, [](uint32_t x, uint32_t y) {
    return static_cast<float>(0.5 + 0.5 * std::sin(0.7 * x + 1.3 * y * y));
  });
  Scene s;
  s.plants.resize(1);
  s.plants[0].bark.height_texture = path;
  Expected<std::unique_ptr<SceneTextures>> opened = SceneTextures::open(s);
  ASSERT_TRUE(opened.ok()) << opened.error().format();
  const HeightField& field = *(*opened)->relief_map(0).field;
  uint64_t state = 1;
  auto next = [&] { return static_cast<double>((state = state * 6364136223846793005ull + 1442695040888963407ull) >> 11) * 0x1.0p-53; };
  for (int i = 0; i < 2000; ++i) {
    const double si = 4 * next() - 2, ti = 4 * next() - 2;
    EXPECT_NEAR(field.height(si, ti), field.filtered_height(si, ti, 0, 0), 2e-5) << si << "," << ti;
  }
}

TEST(Texture, PlantsNamingOneFileShareOneHandle) {
  test::TempFolder dir;
  const std::string path = dir.file("a.png");
  test::write_rgb_png(path, 2, 2, [](uint32_t, uint32_t) { return std::array<float, 3>{0.5f, 0.5f, 0.5f}; });
  Scene s;
  s.plants.resize(3);
  s.plants[0].bark.albedo_texture = path;
  s.plants[2].bark.albedo_texture = path;
  s.plants[2].bark.height_texture = path;
  Expected<std::unique_ptr<SceneTextures>> opened = SceneTextures::open(s);
  ASSERT_TRUE(opened.ok()) << opened.error().format();
  EXPECT_EQ((*opened)->file_count(), 1u);
  EXPECT_TRUE((*opened)->has_albedo(0, 0));
  EXPECT_FALSE((*opened)->has_albedo(1, 0));
  EXPECT_FALSE((*opened)->has_albedo(0, 1)) << "the bark is the wood's alone";
  EXPECT_TRUE((*opened)->has_height(2));
}

TEST(Texture, TheTablesImagesCoverTheSegmentsOfTheirMaterialsWithTheirOwnRepeats) {
  // docs/materials.md: an entry with an albedo image and u_repeat / v_per_metre lays the
  // image on its material's segments; material 0's only where the bark names no albedo.
  test::TempFolder dir;
  const std::string a = dir.file("a.png"), b = dir.file("b.png");
  // Ramps: the lookup's filter (OpenImageIO's smart bicubic at magnification) reproduces a
  // linear function between texel centres away from the periodic seam.
  auto ramp = [](uint32_t x, uint32_t y) {
    return std::array<float, 3>{static_cast<float>(x) / 7, static_cast<float>(y) / 7, 0.25f};
  };
  test::write_rgb_png(a, 8, 8, ramp);
  test::write_rgb_png(b, 2, 2, [](uint32_t, uint32_t) { return std::array<float, 3>{1.0f, 1.0f, 1.0f}; });
  Scene s;
  s.materials[0].albedo_image = b;
  s.materials[0].segment_repeat = SceneMaterial::Repeat{};
  s.materials[2].albedo_image = a;
  s.materials[2].segment_repeat = SceneMaterial::Repeat{3, 2};
  s.materials[3].albedo_image = a;  // no repeats: its segments take the mean (leaf_images.h)
  s.plants.resize(3);
  s.plants[0].bark.albedo_rgb = glm::dvec3(0.5);  // its colour, not the table's image
  s.plants[2].bark.albedo_texture = a;
  Expected<std::unique_ptr<SceneTextures>> opened = SceneTextures::open(s);
  ASSERT_TRUE(opened.ok()) << opened.error().format();
  const SceneTextures& t = **opened;
  EXPECT_EQ(t.file_count(), 2u);
  EXPECT_FALSE(t.has_albedo(0, 0));
  EXPECT_TRUE(t.has_albedo(1, 0));
  EXPECT_TRUE(t.has_albedo(2, 0));
  for (uint32_t p = 0; p < 3; ++p) {
    EXPECT_FALSE(t.has_albedo(p, 1));
    EXPECT_TRUE(t.has_albedo(p, 2));
    EXPECT_FALSE(t.has_albedo(p, 3));
    EXPECT_FALSE(t.has_albedo(p, 40)) << "past the table";
  }
  EXPECT_NEAR(t.albedo(1, 0, 0.3, 0.7, {}).x, 1.0, 1e-6);
  // Texel (x, y) of `a` is at s = (x + ½)/8, t = (y + ½)/8 with s = 3u, t = 2 v_m, and again
  // a period later; 8-bit texels are within ½/255 of the ramp.
  auto expected = [&](uint32_t x, uint32_t y, int k) { return srgb_to_linear(ramp(x, y)[k]); };
  for (uint32_t y = 2; y < 6; ++y)
    for (uint32_t x = 2; x < 6; ++x)
      for (int period = 0; period < 2; ++period) {
        const double u = ((x + 0.5) / 8 + period) / 3, v_m = ((y + 0.5) / 8 + period) / 2;
        const glm::dvec3 albedo = t.albedo(0, 2, u, v_m, {});
        EXPECT_NEAR(albedo.x, expected(x, y, 0), 3e-3) << x << "," << y;
        EXPECT_NEAR(albedo.y, expected(x, y, 1), 3e-3) << x << "," << y;
      }
  // Plant 2's wood wears its bark (a, repeats 1), not the table's entry 0 (white).
  const glm::dvec3 wood = t.albedo(2, 0, 3.5 / 8, 4.5 / 8, {});
  EXPECT_NEAR(wood.x, expected(3, 4, 0), 3e-3);
  EXPECT_NEAR(wood.y, expected(3, 4, 1), 3e-3);
}

TEST(Texture, ATextureThatCannotBeOpenedIsAnErrorNamingTheFile) {
  test::TempFolder dir;
  Scene s;
  s.plants.resize(1);
  s.plants[0].bark.albedo_texture = dir.file("missing.png");
  Expected<std::unique_ptr<SceneTextures>> opened = SceneTextures::open(s);
  ASSERT_FALSE(opened.ok());
  EXPECT_EQ(opened.error().file, dir.file("missing.png"));
  EXPECT_NE(opened.error().message.find(dir.file("missing.png")), std::string::npos) << opened.error().message;
  EXPECT_FALSE(check_image_opens(dir.file("missing.png")).ok());
}

TEST(Texture, ConstantAlbedoTextureDecodesSrgb) {
  // An sRGB texture of one colour renders exactly like that colour given as a linear
  // constant: filtering a constant changes nothing, decoding happens after filtering.
  test::TempFolder dir;
  const std::string path = dir.file("bark.png");
  const std::array<float, 3> encoded{128 / 255.0f, 64 / 255.0f, 200 / 255.0f};
  test::write_rgb_png(path, 8, 4, [&](uint32_t, uint32_t) { return encoded; });
  Scene textured = scene_around(cylinder(0.5, 0, 2, 0), {0, 1, 5}, {0, 1, 0}, 64, 48);
  textured.plants[0].bark.albedo_texture = path;
  textured.plants[0].bark.u_repeat = 3;
  Scene constant = scene_around(cylinder(0.5, 0, 2, 0), {0, 1, 5}, {0, 1, 0}, 64, 48);
  constant.plants[0].bark.albedo_rgb =
      glm::dvec3(srgb_to_linear(encoded[0]), srgb_to_linear(encoded[1]), srgb_to_linear(encoded[2]));
  RenderOptions o;
  o.threads = 2;
  const RenderResult a = render_cpu(textured, o), b = render_cpu(constant, o);
  ASSERT_EQ(a.image.beauty.size(), b.image.beauty.size());
  int plant_pixels = 0;
  for (size_t i = 0; i < a.image.beauty.size(); ++i) {
    EXPECT_NEAR(a.image.beauty[i], b.image.beauty[i], 2e-6 + 1e-5 * b.image.beauty[i]) << i;
    plant_pixels += a.image.beauty[i] != b.image.beauty[0];
  }
  EXPECT_GT(plant_pixels, 100);
  bool listed = false;
  for (const RenderPass& p : a.passes) listed = listed || (p.name == "textures" && p.detail == "1 files");
  EXPECT_TRUE(listed);
}

TEST(Texture, CheckerTextureShowsInTheRenderAndItsFootprintBlursWithDistance) {
  // A black/white checker of 8×8 texels: near, neighbouring pixels differ a lot; far away
  // (many texels per pixel), the mipmapped lookup averages them to a grey: the pixels
  // on the plant vary little. (Without the footprint, far pixels would alias.)
  test::TempFolder dir;
  const std::string path = dir.file("checker.png");
  test::write_rgb_png(path, 64, 64, [](uint32_t x, uint32_t y) {
    const float v = ((x / 8 + y / 8) % 2) ? 1.0f : 0.0f;
    return std::array<float, 3>{v, v, v};
  });
  auto spread = [&](double distance, double v_per_metre) {
    // Seen from 20° around the axis: the view axis meets the middle of a square in s.
    const double angle = 20 * std::numbers::pi / 180;
    Scene s = scene_around(cylinder(0.5, -50, 50),
                           (0.5 + distance) * glm::dvec3(std::sin(angle), 0, std::cos(angle)), {0, 0, 0}, 32, 32);
    s.camera.fov_y_deg = 5;
    s.sun.radiance = {0, 0, 0};  // sky light only: albedo × constant on a facing surface
    s.sky = {1, 1, 1};
    s.plants[0].bark.albedo_texture = path;
    s.plants[0].bark.u_repeat = 1;
    s.plants[0].bark.v_per_metre = v_per_metre;
    RenderOptions o;
    o.threads = 2;
    o.aovs = kAovDepth;
    const RenderResult r = render_cpu(s, o);
    float lo = 1e9f, hi = -1e9f;
    for (uint32_t y = 12; y < 20; ++y)
      for (uint32_t x = 14; x < 18; ++x) {
        EXPECT_FALSE(std::isinf(r.image.depth[y * 32 + x]));
        const float v = r.image.beauty[(y * 32 + x) * 4];
        lo = std::min(lo, v), hi = std::max(hi, v);
      }
    return hi - lo;
  };
  // A pixel is 2.7 mm at 1 m; a checker square along t is 8 texels = 1/(8·v_per_metre) m.
  const double near = spread(1, 12);      // squares of ~4 pixels
  const double far = spread(1, 4000);     // ~90 squares per pixel
  EXPECT_GT(near, 0.2);
  EXPECT_LT(far, 0.25 * near);
}

TEST(Texture, BarkCoversTheWoodOnlyAndNeedlesKeepTheirColour) {
  // materials.h: a plant's bark (albedo texture, colour, height map) is material 0's. With
  // every bark key set, each needle pixel (material 1) is what it is without a bark —
  // on the frusta (relief marching) and on the displaced mesh — while the wood changes.
  const std::string textures = std::string(SYLVA_SOURCE_DIR) + "/presets/textures/";
  const Scene plain = scene_around(test::wood_and_needle(), {0, 1, 5}, {0, 1, 0}, 96, 72);
  for (const bool textured : {true, false}) {
    Scene barked = plain;
    Bark& bark = barked.plants[0].bark;
    if (textured) bark.albedo_texture = textures + "bark.png";
    else bark.albedo_rgb = glm::dvec3(0.9, 0.1, 0.1);
    bark.height_texture = textures + "bark_height.png";
    bark.relief_depth_m = 0.04;
    bark.u_repeat = 3;
    for (const GeometryKind kind : {GeometryKind::frusta, GeometryKind::mesh}) {
      RenderOptions o;
      o.threads = 2;
      o.aovs = kAovDepth | kAovId;
      o.geometry.kind = kind;
      o.geometry.displace = true;
      const RenderResult a = render_cpu(barked, o), b = render_cpu(plain, o);
      size_t needle = 0, wood_changed = 0;
      for (size_t p = 0; p < a.image.depth.size(); ++p) {
        if (a.image.id[3 * p + 1] == 1) {
          ++needle;
          ASSERT_EQ(b.image.id[3 * p + 1], 1) << p;
          EXPECT_EQ(a.image.depth[p], b.image.depth[p]) << p;
          for (int k = 0; k < 3; ++k) EXPECT_EQ(a.image.beauty[4 * p + k], b.image.beauty[4 * p + k]) << p;
        } else if (a.image.id[3 * p + 1] == 0) {
          wood_changed += std::abs(a.image.beauty[4 * p] - b.image.beauty[4 * p]) > 0.01f;
        }
      }
      EXPECT_GT(needle, 300u);
      EXPECT_GT(wood_changed, 300u) << "the bark shows on the wood";
    }
  }
}

}  // namespace
}  // namespace sylva
