// plot_test.cpp — the log–log figures of the benchmarks (core/plot.h).
#include "app/bench/plot.h"

#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>

namespace sylva {
namespace {

constexpr int kW = 720, kH = 480;  // PlotOptions defaults

// Whether some pixel within `radius` of (x, y) has colour c (within 0.02).
bool colour_near(const std::vector<float>& img, int width, int x, int y, int radius, const std::array<float, 3>& c) {
  for (int j = y - radius; j <= y + radius; ++j)
    for (int i = x - radius; i <= x + radius; ++i) {
      if (i < 0 || j < 0 || i >= width || j >= kH) continue;
      const float* p = &img[(static_cast<size_t>(j) * width + i) * 3];
      if (std::abs(p[0] - c[0]) < 0.02f && std::abs(p[1] - c[1]) < 0.02f && std::abs(p[2] - c[2]) < 0.02f) return true;
    }
  return false;
}

TEST(Plot, PointsLandWhereTheirDecadesAre) {
  // x spans 1e-3..1e-1, y spans 1e-4..1e-2: the axes are exactly those decades, so the
  // first point sits at the plot area's bottom-left corner and the last at the top-right.
  PlotPanel panel{"t", "x", "y", {{"a", plot_colour(0), {{1e-3, 1e-4}, {1e-2, 1e-3}, {1e-1, 1e-2}}, true}}};
  const std::vector<float> img = draw_loglog_plot({panel});
  ASSERT_EQ(img.size(), static_cast<size_t>(kW) * kH * 3);
  const int left = 78, right = kW - 250, top = 58, bottom = kH - 58;
  EXPECT_TRUE(colour_near(img, kW, left, bottom, 2, plot_colour(0)));
  EXPECT_TRUE(colour_near(img, kW, (left + right) / 2, (top + bottom) / 2, 2, plot_colour(0)));
  EXPECT_TRUE(colour_near(img, kW, right, top, 2, plot_colour(0)));
  // Nothing of the series' colour far from its diagonal (e.g. the top-left corner).
  EXPECT_FALSE(colour_near(img, kW, left + 20, top + 20, 10, plot_colour(0)));
}

TEST(Plot, ZeroAndNonFinitePointsAreLeftOutNotDrawn) {
  PlotPanel panel{"t", "x", "y", {{"a", plot_colour(1), {{1e-2, 1e-2}, {1e-1, 0}, {NAN, 1}, {1, 1}}, true}}};
  const std::vector<float> img = draw_loglog_plot({panel});
  for (float v : img) ASSERT_TRUE(std::isfinite(v));
  const int left = 78, right = kW - 250, top = 58, bottom = kH - 58;
  EXPECT_TRUE(colour_near(img, kW, left, bottom, 2, plot_colour(1)));
  EXPECT_TRUE(colour_near(img, kW, right, top, 2, plot_colour(1)));
}

TEST(Plot, PanelsSitSideBySideAndTheFileIsWritten) {
  PlotPanel a{"depth", "time (s)", "RMSE", {{"a", plot_colour(0), {{1, 1}, {10, 10}}, true}}};
  PlotPanel b{"colour", "time (s)", "RMSE", {{"b", plot_colour(2), {{1, 1}, {10, 10}}, true}}};
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "sylva_plot_test.png";
  std::filesystem::remove(path);
  ASSERT_TRUE(write_loglog_plot({a, b}, path.string()).ok());
  auto in = OIIO::ImageInput::open(path.string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 2 * kW);
  EXPECT_EQ(in->spec().height, kH);
  std::vector<float> img(static_cast<size_t>(2 * kW) * kH * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, img.data()));
  // The second panel's series is in the right half, with its own colour.
  EXPECT_TRUE(colour_near(img, 2 * kW, kW + 78, kH - 58, 3, plot_colour(2)));
  EXPECT_FALSE(colour_near(img, 2 * kW, 78, kH - 58, 3, plot_colour(2)));
  // Text was rendered: the title area is not blank.
  int dark = 0;
  for (int y = 5; y < 30; ++y)
    for (int x = 0; x < kW; ++x) dark += img[(static_cast<size_t>(y) * 2 * kW + x) * 3] < 0.5f;
  EXPECT_GT(dark, 20);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace sylva
