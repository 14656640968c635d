// plot.cpp — log–log figures (see plot.h).
#include "app/bench/plot.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/util/image_io.h"

namespace sylva {

namespace {

constexpr const char* kFont = "DejaVuSans";
constexpr int kMarginLeft = 78, kMarginRight = 250, kMarginTop = 58, kMarginBottom = 58;

using Colour = std::array<float, 3>;
constexpr Colour kBlack{0, 0, 0}, kGrid{0.88f, 0.88f, 0.88f}, kMinorGrid{0.95f, 0.95f, 0.95f};

bool placeable(const PlotPoint& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && p.x > 0 && p.y > 0;
}

// A log10 range covering whole decades around [lo, hi].
struct Axis {
  double lo = 0, hi = 1;  // log10
  double to_unit(double v) const { return (std::log10(v) - lo) / (hi - lo); }
};

Axis decade_axis(double lo, double hi) {
  if (!(lo <= hi)) return {0, 1};
  Axis a{std::floor(std::log10(lo)), std::ceil(std::log10(hi))};
  if (a.hi - a.lo < 1) a.hi = a.lo + 1;
  return a;
}

std::string decade_label(int k) {
  if (k >= 0 && k <= 4) return std::to_string(static_cast<long>(std::pow(10, k)));
  if (k < 0 && k >= -3) {
    std::string s = "0.";
    for (int i = -1; i > k; --i) s += '0';
    return s + "1";
  }
  return "1e" + std::to_string(k);
}

// Anti-aliased drawing into an RGB float canvas.
class Canvas {
 public:
  Canvas(int w, int h) : w_(w), h_(h), pixels_(static_cast<size_t>(w) * h * 3, 1.0f) {}

  void blend(int x, int y, const Colour& c, float coverage) {
    if (x < 0 || y < 0 || x >= w_ || y >= h_ || coverage <= 0) return;
    coverage = std::min(coverage, 1.0f);
    float* p = &pixels_[(static_cast<size_t>(y) * w_ + x) * 3];
    for (int k = 0; k < 3; ++k) p[k] += (c[k] - p[k]) * coverage;
  }

  // A segment of the given width (pixels) with round ends.
  void line(double x0, double y0, double x1, double y1, double width, const Colour& c) {
    const double r = 0.5 * width;
    const int xa = static_cast<int>(std::floor(std::min(x0, x1) - r - 1)), xb = static_cast<int>(std::ceil(std::max(x0, x1) + r + 1));
    const int ya = static_cast<int>(std::floor(std::min(y0, y1) - r - 1)), yb = static_cast<int>(std::ceil(std::max(y0, y1) + r + 1));
    const double dx = x1 - x0, dy = y1 - y0, len2 = dx * dx + dy * dy;
    for (int y = std::max(ya, 0); y <= std::min(yb, h_ - 1); ++y)
      for (int x = std::max(xa, 0); x <= std::min(xb, w_ - 1); ++x) {
        const double px = x + 0.5 - x0, py = y + 0.5 - y0;
        const double s = len2 > 0 ? std::clamp((px * dx + py * dy) / len2, 0.0, 1.0) : 0.0;
        const double d = std::hypot(px - s * dx, py - s * dy);
        blend(x, y, c, static_cast<float>(r + 0.5 - d));
      }
  }

  void disc(double cx, double cy, double radius, const Colour& c) { line(cx, cy, cx, cy, 2 * radius, c); }

  void rect(int x0, int y0, int x1, int y1, const Colour& c) {
    for (int y = std::max(y0, 0); y < std::min(y1, h_); ++y)
      for (int x = std::max(x0, 0); x < std::min(x1, w_); ++x) blend(x, y, c, 1);
  }

  int width() const { return w_; }
  int height() const { return h_; }
  std::vector<float>& pixels() { return pixels_; }

 private:
  int w_, h_;
  std::vector<float> pixels_;
};

struct TextItem {
  int x, y;
  std::string text;
  int size;
  OIIO::ImageBufAlgo::TextAlignX align_x;
  OIIO::ImageBufAlgo::TextAlignY align_y;
};

void draw_panel(Canvas& canvas, int x_offset, const PlotPanel& panel, const PlotOptions& o,
                std::vector<TextItem>& text) {
  using AX = OIIO::ImageBufAlgo::TextAlignX;
  using AY = OIIO::ImageBufAlgo::TextAlignY;
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
  for (const PlotSeries& s : panel.series)
    for (const PlotPoint& p : s.points)
      if (placeable(p)) {
        x_lo = std::min(x_lo, p.x), x_hi = std::max(x_hi, p.x);
        y_lo = std::min(y_lo, p.y), y_hi = std::max(y_hi, p.y);
      }
  const Axis ax = decade_axis(x_lo, x_hi), ay = decade_axis(y_lo, y_hi);
  const int left = x_offset + kMarginLeft, right = x_offset + o.panel_width - kMarginRight;
  const int top = kMarginTop, bottom = o.height - kMarginBottom;
  auto px = [&](double v) { return left + ax.to_unit(v) * (right - left); };
  auto py = [&](double v) { return bottom - ay.to_unit(v) * (bottom - top); };

  // Grid: minor lines at 2..9 × 10^k, major lines and labels at decades.
  for (int k = static_cast<int>(ax.lo); k < static_cast<int>(ax.hi); ++k)
    for (int m = 2; m <= 9; ++m) canvas.line(px(m * std::pow(10, k)), top, px(m * std::pow(10, k)), bottom, 1, kMinorGrid);
  for (int k = static_cast<int>(ay.lo); k < static_cast<int>(ay.hi); ++k)
    for (int m = 2; m <= 9; ++m) canvas.line(left, py(m * std::pow(10, k)), right, py(m * std::pow(10, k)), 1, kMinorGrid);
  for (int k = static_cast<int>(ax.lo); k <= static_cast<int>(ax.hi); ++k) {
    const double x = px(std::pow(10, k));
    canvas.line(x, top, x, bottom, 1, kGrid);
    canvas.line(x, bottom, x, bottom + 5, 1, kBlack);
    text.push_back({static_cast<int>(x), bottom + 8, decade_label(k), 13, AX::Center, AY::Top});
  }
  for (int k = static_cast<int>(ay.lo); k <= static_cast<int>(ay.hi); ++k) {
    const double y = py(std::pow(10, k));
    canvas.line(left, y, right, y, 1, kGrid);
    canvas.line(left - 5, y, left, y, 1, kBlack);
    text.push_back({left - 8, static_cast<int>(y), decade_label(k), 13, AX::Right, AY::Center});
  }
  canvas.line(left, top, left, bottom, 1.2, kBlack);
  canvas.line(left, bottom, right, bottom, 1.2, kBlack);
  canvas.line(right, top, right, bottom, 1, kBlack);
  canvas.line(left, top, right, top, 1, kBlack);
  // The title on the first line, the y axis's label on the second (a long title, centred
  // over the axes, would otherwise run into it).
  text.push_back({(left + right) / 2, 6, panel.title, 16, AX::Center, AY::Top});
  text.push_back({(left + right) / 2, o.height - 8, panel.x_label, 14, AX::Center, AY::Bottom});
  text.push_back({x_offset + 8, top - 8, panel.y_label, 14, AX::Left, AY::Bottom});

  // Series, then the legend at the right.
  int legend_y = top + 6;
  for (const PlotSeries& s : panel.series) {
    bool have_last = false;
    double lx = 0, ly = 0;
    size_t left_out = 0;
    for (const PlotPoint& p : s.points) {
      if (!placeable(p)) {
        ++left_out;
        continue;
      }
      const double x = px(p.x), y = py(p.y);
      if (s.connect && have_last) canvas.line(lx, ly, x, y, 2, s.colour);
      lx = x, ly = y, have_last = true;
    }
    for (const PlotPoint& p : s.points)
      if (placeable(p)) canvas.disc(px(p.x), py(p.y), 3.5, s.colour);
    const int lx0 = right + 14;
    canvas.line(lx0, legend_y + 7, lx0 + 22, legend_y + 7, 2, s.colour);
    canvas.disc(lx0 + 11, legend_y + 7, 3.5, s.colour);
    std::string name = s.name;
    if (left_out) name += " (" + std::to_string(left_out) + " at zero)";
    text.push_back({lx0 + 28, legend_y + 7, name, 12, AX::Left, AY::Center});
    legend_y += 20;
  }
}

}  // namespace

std::array<float, 3> plot_colour(size_t k) {
  // Okabe–Ito, black last.
  static constexpr Colour kCycle[] = {{0.00f, 0.45f, 0.70f}, {0.84f, 0.37f, 0.00f}, {0.00f, 0.62f, 0.45f},
                                      {0.80f, 0.47f, 0.65f}, {0.90f, 0.62f, 0.00f}, {0.34f, 0.71f, 0.91f},
                                      {0.60f, 0.55f, 0.10f}, {0.00f, 0.00f, 0.00f}};
  return kCycle[k % (sizeof kCycle / sizeof kCycle[0])];
}

namespace {

// Draws everything; `text_error` receives a message when text could not be rendered.
std::vector<float> draw(const std::vector<PlotPanel>& panels, const PlotOptions& o, std::string* text_error) {
  const int n = std::max<int>(1, static_cast<int>(panels.size()));
  Canvas canvas(n * o.panel_width, o.height);
  std::vector<TextItem> text;
  for (size_t i = 0; i < panels.size(); ++i)
    draw_panel(canvas, static_cast<int>(i) * o.panel_width, panels[i], o, text);
  OIIO::ImageBuf buf(OIIO::ImageSpec(canvas.width(), canvas.height(), 3, OIIO::TypeDesc::FLOAT),
                     canvas.pixels().data());
  const float black[3] = {0, 0, 0};
  for (const TextItem& t : text) {
    if (t.text.empty()) continue;
    if (!OIIO::ImageBufAlgo::render_text(buf, t.x, t.y, t.text, t.size, kFont, black, t.align_x, t.align_y) &&
        text_error && text_error->empty())
      *text_error = "cannot render text with the font " + std::string(kFont) +
                    " (install fonts-dejavu-core): " + buf.geterror();
  }
  return canvas.pixels();
}

}  // namespace

std::vector<float> draw_loglog_plot(const std::vector<PlotPanel>& panels, const PlotOptions& options) {
  return draw(panels, options, nullptr);
}

Status write_loglog_plot(const std::vector<PlotPanel>& panels, const std::string& path, const PlotOptions& options) {
  std::string text_error;
  const std::vector<float> pixels = draw(panels, options, &text_error);
  if (!text_error.empty()) return file_diagnostic(path, text_error);
  const int n = std::max<int>(1, static_cast<int>(panels.size()));
  return write_image_atomically(path, static_cast<uint32_t>(n * options.panel_width),
                                static_cast<uint32_t>(options.height), {"R", "G", "B"}, pixels,
                                {ChannelFormat::uint8}, true);
}

}  // namespace sylva
