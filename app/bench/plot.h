// plot.h — log–log error-against-time figures as PNG (docs/benchmarks.md, docs/plots/): the
// benchmarks draw their own plots, so a report needs nothing but the sylva binary.
//
// A figure is one or more panels side by side; each panel has log10 axes with a tick and
// a label at every decade its data spans (minor ticks at 2..9), a title, axis labels and a
// legend. Each series is a polyline with a marker at every point (drawn in the order
// given), so a family of settings (e.g. marching steps 8, 16, 32, 64) reads as a curve.
// Points whose x or y is not finite and > 0 cannot be placed on log axes: they are left
// out and the legend entry says how many ("3 at zero error").
//
// Text is rendered by OpenImageIO with the DejaVu Sans font (Debian fonts-dejavu-core,
// installed by scripts/setup.sh). The PNG is written atomically (core/image_io.h).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/util/file_io.h"

namespace sylva {

struct PlotPoint {
  double x = 0;
  double y = 0;
};

struct PlotSeries {
  std::string name;                    // legend text
  std::array<float, 3> colour{0, 0, 0};  // sRGB-encoded, 0..1
  std::vector<PlotPoint> points;
  bool connect = true;                 // draw the polyline through the points
};

struct PlotPanel {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<PlotSeries> series;
};

struct PlotOptions {
  int panel_width = 720;   // pixels per panel (the legend takes 250 at the right)
  int height = 480;        // pixels
};

// A distinct colour for series k (a fixed, colour-blind-friendly cycle).
std::array<float, 3> plot_colour(size_t k);

// Draws the panels side by side into an sRGB RGB float image (width = panels ·
// panel_width), row-major from the top-left. Exposed for tests.
std::vector<float> draw_loglog_plot(const std::vector<PlotPanel>& panels, const PlotOptions& options = {});

// Draws and writes the figure to `path` (PNG, or any format OpenImageIO writes).
Status write_loglog_plot(const std::vector<PlotPanel>& panels, const std::string& path,
                         const PlotOptions& options = {});

}  // namespace sylva
