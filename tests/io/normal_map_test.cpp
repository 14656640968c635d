// normal_map_test.cpp — core/io/normal_map.h: a height map baked into a glTF tangent-space
// normal map. Analytic height fields against their analytic normals, the encoding of a
// flat map, wrap-around at every edge, the bark metric, reading height images and the
// in-memory PNG encoder.
#include "core/io/normal_map.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

namespace sylva {
namespace {

namespace fs = std::filesystem;
const std::string kSource = SYLVA_SOURCE_DIR;

HeightMap make_map(uint32_t width, uint32_t height, double (*h)(double s, double t)) {
  HeightMap map;
  map.width = width;
  map.height = height;
  for (uint32_t j = 0; j < height; ++j)
    for (uint32_t i = 0; i < width; ++i)
      map.values.push_back(static_cast<float>(h((i + 0.5) / width, (j + 0.5) / height)));
  return map;
}

// The decoded 8-bit component.
double decode(uint8_t c) { return c / 255.0 * 2.0 - 1.0; }

TEST(NormalMap, AFlatHeightMapEncodesAsStraightUp) {
  HeightMap map = make_map(8, 4, [](double, double) { return 0.7; });
  const std::vector<glm::dvec3> normals = bake_tangent_normals(map, {0.01, 0.02, 0.05});
  ASSERT_EQ(normals.size(), 32u);
  for (const glm::dvec3& n : normals) EXPECT_EQ(n, glm::dvec3(0, 0, 1));
  const std::vector<uint8_t> rgb = encode_normals_rgb8(normals);
  ASSERT_EQ(rgb.size(), 96u);
  for (size_t i = 0; i < rgb.size(); i += 3) {
    EXPECT_EQ(rgb[i], 128);  // 0.5 (127.5 rounds up)
    EXPECT_EQ(rgb[i + 1], 128);
    EXPECT_EQ(rgb[i + 2], 255);
  }
}

TEST(NormalMap, ASineRidgeAroundTheStemMatchesTheAnalyticNormal) {
  // h = 0.5 + 0.5 sin(2π·2·s): dh/dx_s = 0.5·2π·2·cos(2π·2·s) / (width·texel_s).
  const uint32_t w = 64, h = 8;
  const NormalMapMetric metric{0.01, 0.02, 0.05};
  HeightMap map = make_map(w, h, [](double s, double) { return 0.5 + 0.5 * std::sin(2 * std::numbers::pi * 2 * s); });
  const std::vector<glm::dvec3> normals = bake_tangent_normals(map, metric);
  const std::vector<uint8_t> rgb = encode_normals_rgb8(normals);
  double largest_slope = 0;
  for (uint32_t j = 0; j < h; ++j)
    for (uint32_t i = 0; i < w; ++i) {
      const double s = (i + 0.5) / w;
      const double slope = metric.depth_m * 0.5 * 2 * std::numbers::pi * 2 * std::cos(2 * std::numbers::pi * 2 * s) /
                           (w * metric.texel_s_m);
      largest_slope = std::max(largest_slope, std::abs(slope));
      const glm::dvec3 expected = glm::dvec3(-slope, 0, 1) / std::sqrt(slope * slope + 1);
      const size_t k = size_t{j} * w + i;
      // Central differences: relative slope error (2π·2/64)²/6 ≈ 0.6 %.
      EXPECT_NEAR(normals[k].x, expected.x, 3e-3) << i;
      EXPECT_NEAR(normals[k].y, 0.0, 1e-12) << i;
      EXPECT_NEAR(normals[k].z, expected.z, 3e-3) << i;
      EXPECT_NEAR(decode(rgb[3 * k]), expected.x, 3e-3 + 1.0 / 255) << i;
      EXPECT_NEAR(decode(rgb[3 * k + 1]), 0.0, 1.0 / 255) << i;
      EXPECT_NEAR(decode(rgb[3 * k + 2]), expected.z, 3e-3 + 1.0 / 255) << i;
    }
  EXPECT_GT(largest_slope, 0.4);  // a real tilt (about 26°), not a near-flat field
}

TEST(NormalMap, HeightRisingAlongTTiltsTheNormalTowardDecreasingTWhichIsPlusY) {
  // h = 0.5 + 0.5 sin(2π·t): the relief rises toward +t where cos > 0, so its normal leans
  // toward −t̂, which glTF's +Y (up in the image, toward row 0) is.
  const uint32_t w = 4, h = 128;
  const NormalMapMetric metric{0.01, 0.002, 0.01};
  HeightMap map = make_map(w, h, [](double, double t) { return 0.5 + 0.5 * std::sin(2 * std::numbers::pi * t); });
  const std::vector<glm::dvec3> normals = bake_tangent_normals(map, metric);
  for (uint32_t j = 0; j < h; ++j) {
    const double t = (j + 0.5) / h;
    const double slope = metric.depth_m * 0.5 * 2 * std::numbers::pi * std::cos(2 * std::numbers::pi * t) / (h * metric.texel_t_m);
    const glm::dvec3 expected = glm::dvec3(0, slope, 1) / std::sqrt(slope * slope + 1);
    EXPECT_NEAR(normals[size_t{j} * w + 1].x, 0.0, 1e-12) << j;
    EXPECT_NEAR(normals[size_t{j} * w + 1].y, expected.y, 1e-4) << j;
    EXPECT_NEAR(normals[size_t{j} * w + 1].z, expected.z, 1e-4) << j;
  }
  EXPECT_GT(normals[1].y, 0.1);  // row 0: t ≈ 0, rising
}

TEST(NormalMap, DifferencesWrapAroundAtEveryEdge) {
  // A single raised column 0 and a single raised row 0 on a 6 × 5 map.
  HeightMap map;
  map.width = 6;
  map.height = 5;
  map.values.assign(30, 0.0f);
  for (uint32_t j = 0; j < 5; ++j) map.values[j * 6] = 1.0f;  // column 0
  const NormalMapMetric metric{0.5, 0.25, 1.0};
  std::vector<glm::dvec3> n = bake_tangent_normals(map, metric);
  // Column 5's right neighbour is column 0: h rises to the right, x < 0; column 1's left
  // neighbour is column 0: x > 0. The slope is depth·1/(2·texel_s) = 1.
  const double x = 1 / std::sqrt(2.0);
  EXPECT_NEAR(n[2 * 6 + 5].x, -x, 1e-12);
  EXPECT_NEAR(n[2 * 6 + 1].x, x, 1e-12);
  EXPECT_NEAR(n[2 * 6 + 0].x, 0, 1e-12);
  EXPECT_NEAR(n[2 * 6 + 3].x, 0, 1e-12);

  map.values.assign(30, 0.0f);
  for (uint32_t i = 0; i < 6; ++i) map.values[i] = 1.0f;  // row 0
  n = bake_tangent_normals(map, metric);
  // Row 4's lower neighbour (increasing t) is row 0: h rises toward +t, y > 0; row 1's
  // upper neighbour is row 0: h falls toward +t, y < 0. Slope 1/(2·0.25) = 2.
  const double y = 2 / std::sqrt(5.0);
  EXPECT_NEAR(n[4 * 6 + 2].y, y, 1e-12);
  EXPECT_NEAR(n[1 * 6 + 2].y, -y, 1e-12);
  EXPECT_NEAR(n[0 * 6 + 2].y, 0, 1e-12);
}

TEST(NormalMap, BarkMetricMeasuresTexelsOnTheReferenceStem) {
  const NormalMapMetric m = bark_normal_map_metric(512, 256, 0.1, 2, 4, 0.02);
  EXPECT_DOUBLE_EQ(m.texel_s_m, 2 * std::numbers::pi * 0.1 / (2 * 512));
  EXPECT_DOUBLE_EQ(m.texel_t_m, 1.0 / (4 * 256));
  EXPECT_EQ(m.depth_m, 0.02);
}

TEST(NormalMap, ReadsTheBundledSixteenBitHeightMap) {
  Expected<HeightMap> r = read_height_map(kSource + "/presets/textures/bark_height.png");
  ASSERT_TRUE(r.ok()) << r.error().format();
  EXPECT_EQ(r->width, 512u);
  EXPECT_EQ(r->height, 512u);
  float lo = 1, hi = 0;
  for (float v : r->values) lo = std::min(lo, v), hi = std::max(hi, v);
  EXPECT_EQ(lo, 0.0f);  // scripts/make_textures.py spans the full range
  EXPECT_EQ(hi, 1.0f);
  // 16 bits survive: more distinct values than an 8-bit file could hold.
  std::vector<float> sorted = r->values;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_GT(std::unique(sorted.begin(), sorted.end()) - sorted.begin(), 256);
}

TEST(NormalMap, AMissingOrBrokenHeightMapIsAnErrorNamingTheFile) {
  const std::string missing = kSource + "/presets/textures/no_such_height.png";
  Expected<HeightMap> r = read_height_map(missing);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().file, missing);
  EXPECT_NE(r.error().format().find(missing), std::string::npos) << r.error().format();

  const fs::path broken = fs::temp_directory_path() / ("sylva-broken-" + std::to_string(::getpid()) + ".png");
  std::ofstream(broken, std::ios::binary) << "\x89PNG\r\n\x1a\nnot really";
  r = read_height_map(broken.string());
  fs::remove(broken);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().format().find(broken.string()), std::string::npos) << r.error().format();
}

TEST(NormalMap, PngInMemoryReadsBackExactlyAndIsReproducible) {
  const uint32_t w = 7, h = 3;
  std::vector<uint8_t> rgb;
  for (uint32_t k = 0; k < w * h * 3; ++k) rgb.push_back(static_cast<uint8_t>(k * 37 % 256));
  const std::optional<std::string> png = encode_png_in_memory(w, h, 3, rgb);
  ASSERT_TRUE(png);
  EXPECT_EQ(png->compare(0, 8, "\x89PNG\r\n\x1a\n"), 0);
  EXPECT_EQ(encode_png_in_memory(w, h, 3, rgb), png);
  const fs::path file = fs::temp_directory_path() / ("sylva-png-" + std::to_string(::getpid()) + ".png");
  std::ofstream(file, std::ios::binary) << *png;
  Expected<HeightMap> r = read_height_map(file.string());  // channel 0 = red
  fs::remove(file);
  ASSERT_TRUE(r.ok()) << r.error().format();
  ASSERT_EQ(r->values.size(), size_t{w} * h);
  for (size_t k = 0; k < r->values.size(); ++k) EXPECT_EQ(std::lround(r->values[k] * 255), rgb[3 * k]) << k;
  EXPECT_FALSE(encode_png_in_memory(w, h, 3, {1, 2, 3}));  // wrong size
}

}  // namespace
}  // namespace sylva
