// spline_function.cpp — cpfg's user-defined functions (see spline_function.h).
#include "lsystem/spline_function.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>

#include "core/util/file_io.h"
#include "lsystem/source_text.h"

namespace sylva::lsys {

namespace {

// The knot sequence of cpfg's open uniform cubic B-spline over n + 1 points (splinefun.cpp Uk).
int knot(int j, int n) {
  constexpr int t = 4;
  if (j < t) return 0;
  if (j > n) return n - t + 2;
  return j - t + 1;
}

// The Cox–de Boor basis N(k, order, u) on that knot sequence, as cpfg evaluates it.
double basis(int k, int order, double u, int n) {
  if (order == 1) return knot(k, n) <= u && u < knot(k + 1, n) ? 1.0 : 0.0;
  double sum = 0;
  if (int div = knot(k + order - 1, n) - knot(k, n); div != 0) sum = (u - knot(k, n)) / div * basis(k, order - 1, u, n);
  if (int div = knot(k + order, n) - knot(k + 1, n); div != 0)
    sum += (knot(k + order, n) - u) / div * basis(k + 1, order - 1, u, n);
  return sum;
}

// A function file's lines, read one at a time with their numbers, for located errors.
class Lines {
 public:
  Lines(std::string path, const std::string& text) : path_(std::move(path)) {
    detail::for_each_physical_line(text, [&](uint32_t, std::string_view line, bool) { lines_.emplace_back(line); });
  }
  bool done() const { return next_ >= lines_.size(); }
  const std::string& peek() const { return lines_[next_]; }
  const std::string& take() { return lines_[next_++]; }
  uint32_t number() const { return static_cast<uint32_t>(next_); }  // of the line last taken
  Diagnostic error(std::string message) const {
    const uint32_t n = std::max<uint32_t>(number(), 1);
    Diagnostic d = diagnostic_at(path_, {n, 1}, std::move(message));
    if (n <= lines_.size()) set_source_line(d, lines_[n - 1]);
    return d;
  }
  Diagnostic at_end(std::string message) const {
    return diagnostic_at(path_, {static_cast<uint32_t>(lines_.size()) + 1, 1}, std::move(message));
  }

 private:
  std::string path_;
  std::vector<std::string> lines_;
  size_t next_ = 0;
};

// The numbers of `text` after `key` (which it must start with, spaces before it allowed).
std::optional<std::vector<double>> numbers_after(const std::string& text, std::string_view key) {
  size_t i = 0;
  while (i < text.size() && detail::is_space(text[i])) ++i;
  if (text.compare(i, key.size(), key) != 0) return std::nullopt;
  i += key.size();
  std::vector<double> out;
  while (true) {
    while (i < text.size() && detail::is_space(text[i])) ++i;
    if (i == text.size()) return out;
    const char* first = text.data() + i + (text[i] == '+' ? 1 : 0);
    double v = 0;
    auto [ptr, ec] = std::from_chars(first, text.data() + text.size(), v);
    if (ec != std::errc() || !std::isfinite(v)) return std::nullopt;
    i = static_cast<size_t>(ptr - text.data());
    if (i < text.size() && !detail::is_space(text[i])) return std::nullopt;
    out.push_back(v);
  }
}

Expected<std::string> next_field(Lines& lines, std::string_view key, const char* what) {
  if (lines.done()) return lines.at_end(std::string("expected '") + std::string(key) + "' (" + what + ")");
  const std::string& line = lines.take();
  size_t i = 0;
  while (i < line.size() && detail::is_space(line[i])) ++i;
  if (line.compare(i, key.size(), key) != 0)
    return lines.error(std::string("expected '") + std::string(key) + "' (" + what + ")");
  return line;
}

// "points: n" and the n lines after it ("x y", and in format 1.1 "x y multiplicity").
Status read_points(Lines& lines, bool multiplicity, SplineFunction& f) {
  auto header = next_field(lines, "points:", "the number of control points");
  if (!header) return std::move(header.error());
  auto count = numbers_after(*header, "points:");
  if (!count || count->size() != 1 || (*count)[0] != std::floor((*count)[0]) || (*count)[0] < 4 || (*count)[0] > 1e6)
    return lines.error("'points:' needs a whole number of control points, at least 4 (cpfg's cubic B-spline)");
  const auto n = static_cast<size_t>((*count)[0]);
  for (size_t k = 0; k < n; ++k) {
    if (lines.done()) return lines.at_end("expected " + std::to_string(n) + " control points, found " + std::to_string(k));
    const std::string& line = lines.take();
    auto xy = numbers_after(line, "");
    if (!xy || xy->size() < 2 || xy->size() > (multiplicity ? 3u : 2u))
      return lines.error(multiplicity ? "expected a control point 'x y' or 'x y multiplicity'" : "expected a control point 'x y'");
    int repeat = 1;
    if (xy->size() == 3) {
      const double m = (*xy)[2];
      if (m != std::floor(m) || m < 1 || m > 16) return lines.error("a control point's multiplicity is a whole number from 1 to 16");
      repeat = static_cast<int>(m);
    }
    for (int r = 0; r < repeat; ++r) f.x.push_back((*xy)[0]), f.y.push_back((*xy)[1]);
  }
  return {};
}

Status set_samples(Lines& lines, double samples, SplineFunction& f) {
  if (samples != std::floor(samples) || samples < 0 || samples > kMaxFunctionSamples)
    return lines.error("the number of samples is a whole number from 0 to " + std::to_string(kMaxFunctionSamples));
  const int s = static_cast<int>(samples);
  if (s <= 2) return {};
  f.table.resize(static_cast<size_t>(s));
  for (int i = 0; i < s; ++i) f.table[static_cast<size_t>(i)] = f.exact(static_cast<double>(i) / (s - 1));
  return {};
}

// One function of format 1.1, after its `fver 1 1` line.
Status read_fver_1_1(Lines& lines, SplineFunction& f) {
  auto name = next_field(lines, "name:", "the function's name");
  if (!name) return std::move(name.error());
  {
    std::string n = name->substr(name->find("name:") + 5);
    const size_t a = n.find_first_not_of(" \t"), b = n.find_last_not_of(" \t");
    if (a == std::string::npos) return lines.error("'name:' needs the function's name");
    f.name = n.substr(a, b - a + 1);
  }
  auto samples_line = next_field(lines, "samples:", "the number of precomputed values");
  if (!samples_line) return std::move(samples_line.error());
  auto samples = numbers_after(*samples_line, "samples:");
  if (!samples || samples->size() != 1) return lines.error("'samples:' needs one number");
  // What vlab's editor adds and cpfg skips: a background image (two lines), markers, flip.
  if (!lines.done() && !lines.peek().empty() && lines.peek()[0] == 'b') {
    lines.take();
    if (!lines.done()) lines.take();
  }
  if (!lines.done() && !lines.peek().empty() && lines.peek()[0] == 'm') {
    auto markers = numbers_after(lines.take(), "markers:");
    if (!markers || markers->size() != 1 || (*markers)[0] < 0 || (*markers)[0] > 1e6) return lines.error("'markers:' needs a count");
    for (int k = 0; k < static_cast<int>((*markers)[0]) && !lines.done(); ++k) lines.take();
  }
  while (!lines.done() && lines.peek().find("points:") == std::string::npos) lines.take();  // flip: and the like
  if (Status s = read_points(lines, true, f); !s) return s;
  return set_samples(lines, (*samples)[0], f);
}

}  // namespace

void SplineFunction::point(double d, double* px, double* py) const {
  const int n = static_cast<int>(x.size()) - 1;
  const double u = d * (n - 4 + 2);
  double sx = 0, sy = 0;
  for (int k = 0; k <= n; ++k) {
    const double w = basis(k, 4, u, n);
    sx += x[static_cast<size_t>(k)] * w;
    sy += y[static_cast<size_t>(k)] * w;
  }
  *px = sx, *py = sy;
}

double SplineFunction::exact(double v) const {
  v = std::clamp(v, 0.0, 1.0);
  // cpfg's bisection on the parameter until the curve's x is within 0.001 of v. cpfg loops
  // until then; a curve whose x never comes that close (it does not span [0, 1], or turns
  // back) stops here after the parameter stops changing, at the closest point found.
  double low = 0, high = 1, px = 0, py = 0;
  for (int k = 0; k < 64; ++k) {
    const double check = (low + high) / 2;
    point(check, &px, &py);
    if (px > v) high = check;
    else low = check;
    if (std::fabs(px - v) <= 0.001) break;
  }
  return py;
}

double SplineFunction::value(double v) const {
  v = std::clamp(v, 0.0, 1.0);
  if (table.size() <= 2) return exact(v);
  const double index = v * static_cast<double>(table.size() - 1);
  const auto i = static_cast<size_t>(std::floor(index));
  if (i + 1 >= table.size()) return table.back();
  const double w = index - static_cast<double>(i);
  return (1 - w) * table[i] + w * table[i + 1];
}

Expected<SplineFunction> read_function_file(const std::string& path, int view_samples) {
  Expected<std::string> text = read_text_file(path);
  if (!text) return std::move(text.error());
  Lines lines(path, *text);
  SplineFunction f;
  if (lines.done()) return lines.at_end("an empty function file (expected 'fver 1 1' or 'range: 0 1')");
  const std::string& first = lines.take();
  if (auto range = numbers_after(first, "range:")) {
    // The older format: no name (cpfg names it by its file), the view file's samples.
    if (range->size() != 2) return lines.error("'range:' needs two numbers");
    f.name = path;
    if (Status s = read_points(lines, false, f); !s) return std::move(s.error());
    if (Status s = set_samples(lines, view_samples, f); !s) return std::move(s.error());
    return f;
  }
  auto version = numbers_after(first, "fver");
  if (!version || version->size() != 2) return lines.error("expected 'fver 1 1' or 'range: 0 1' (a vlab function file)");
  if ((*version)[0] != 1 || (*version)[1] != 1)
    return lines.error("this function file format is not supported (cpfg reads 'fver 1 1')");
  if (Status s = read_fver_1_1(lines, f); !s) return std::move(s.error());
  return f;
}

Expected<std::vector<SplineFunction>> read_function_set(const std::string& path) {
  Expected<std::string> text = read_text_file(path);
  if (!text) return std::move(text.error());
  Lines lines(path, *text);
  if (lines.done()) return lines.at_end("an empty function set (expected 'funcgalleryver 1 1')");
  auto version = numbers_after(lines.take(), "funcgalleryver");
  if (!version || version->size() != 2 || (*version)[0] != 1 || (*version)[1] != 1)
    return lines.error("expected 'funcgalleryver 1 1' (a vlab function set)");
  auto items_line = next_field(lines, "items:", "the number of functions");
  if (!items_line) return std::move(items_line.error());
  auto items = numbers_after(*items_line, "items:");
  if (!items || items->size() != 1 || (*items)[0] != std::floor((*items)[0]) || (*items)[0] < 1 || (*items)[0] > 1000)
    return lines.error("'items:' needs the number of functions, 1 to 1000");
  std::vector<SplineFunction> out;
  for (int k = 0; k < static_cast<int>((*items)[0]); ++k) {
    auto head = next_field(lines, "fver", "the next function");
    if (!head) return std::move(head.error());
    auto v = numbers_after(*head, "fver");
    if (!v || v->size() != 2 || (*v)[0] != 1 || (*v)[1] != 1) return lines.error("expected 'fver 1 1' (cpfg reads format 1.1)");
    SplineFunction f;
    if (Status s = read_fver_1_1(lines, f); !s) return std::move(s.error());
    out.push_back(std::move(f));
  }
  return out;
}

namespace {

// cpfg's uniform cubic B-spline basis on the integer knots (curveXYZ.cpp's Bi4).
double uniform_basis(int i, double t, int order) {
  if (order == 1) return (i <= t && t < i + 1) ? 1.0 : 0.0;
  const double k = order - 1;
  return (t - i) / k * uniform_basis(i, t, order - 1) + (i + order - t) / k * uniform_basis(i + 1, t, order - 1);
}

// Its endpoint-interpolating basis over n control points (Nk4 with uk: 0 0 0 0 1 ... n−3 n−3 n−3 n−3).
double endpoint_knot(int k, int n) { return k < 4 ? 0.0 : (k > n - 1 ? n - 3.0 : k - 3.0); }
double endpoint_basis(int k, double u, int order, int n) {
  if (order == 1) return (endpoint_knot(k, n) <= u && u < endpoint_knot(k + 1, n)) ? 1.0 : 0.0;
  double out = 0;
  const double a = endpoint_knot(k + order - 1, n) - endpoint_knot(k, n);
  const double b = endpoint_knot(k + order, n) - endpoint_knot(k + 1, n);
  if (a != 0) out += (u - endpoint_knot(k, n)) / a * endpoint_basis(k, u, order - 1, n);
  if (b != 0) out += (endpoint_knot(k + order, n) - u) / b * endpoint_basis(k + 1, u, order - 1, n);
  return out;
}

}  // namespace

std::array<double, 3> CpfgCurve::point(double u) const {
  std::array<double, 3> p{0, 0, 0};
  const int n = static_cast<int>(control.size());
  if (n < 4) return p;
  auto add = [&](int i, double w) {
    for (int c = 0; c < 3; ++c) p[c] += w * control[static_cast<size_t>(i)][c];
  };
  if (type == Type::kBezier) {
    // Segments of 4 points sharing their ends, each an endpoint B-spline of 4 (a Bézier).
    const int segments = 1 + (n - 4) / 3;
    const int c = static_cast<int>(u / (1.000001 / segments));
    const int i = c * 3;
    const double t = (u - c * (1.0 / segments)) * segments / 1.000001;
    for (int k = 0; k < 4 && i + k < n; ++k) add(i + k, endpoint_basis(k, t, 4, 4));
    return p;
  }
  if (type == Type::kBSplineEndpoint) {
    const double t = u * (n - 3.000001);
    for (int k = 0; k < n; ++k) add(k, endpoint_basis(k, t, 4, n));
    return p;
  }
  const int i = 3 + static_cast<int>(u * (n - 3.000001));
  const double t = 3.0 + u * (n - 3.000001);
  for (int k = i - 3; k <= i; ++k) add(k, uniform_basis(k, t, 4));
  return p;
}

std::array<double, 3> CpfgCurve::at_length(double s) const {
  s = std::clamp(s, 0.0, 1.0);
  // The last sample at or below s (curveXYZ.cpp's bisection), then the parameter between it
  // and the next in proportion.
  size_t lo = 0, hi = lengths.size() - 1;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    (lengths[mid] > s ? hi : lo) = mid;
  }
  const double span = lengths[hi] - lengths[lo];
  const double u = (static_cast<double>(lo) + (span > 0 ? (s - lengths[lo]) / span : 0.0)) /
                   static_cast<double>(lengths.size() - 1);
  return point(u);
}

Expected<CpfgCurve> read_cpfg_curve(const std::string& path, int samples) {
  Expected<std::string> text = read_text_file(path);
  if (!text) return std::move(text.error());
  Lines lines(path, *text);
  if (lines.done()) return lines.at_end("an empty curve file (expected 'version: 1.4')");
  auto version = numbers_after(lines.take(), "version:");
  if (!version || version->size() != 1)
    return lines.error("expected 'version: 1.4' (a curve file of vlab's cuspy; cpfg's contour functions read that format)");
  CpfgCurve curve;
  size_t count = 0;
  // Fields up to `type:`, which comes last before the points; `points:` among them.
  for (;;) {
    if (lines.done()) return lines.at_end("expected 'type:' before the control points");
    const std::string& line = lines.take();
    if (auto n = numbers_after(line, "points:")) {
      if (n->size() != 1 || (*n)[0] != std::floor((*n)[0]) || (*n)[0] < 4 || (*n)[0] > 1e6)
        return lines.error("'points:' needs a whole number of control points, at least 4");
      count = static_cast<size_t>((*n)[0]);
      continue;
    }
    size_t i = 0;
    while (i < line.size() && detail::is_space(line[i])) ++i;
    if (line.compare(i, 5, "type:") != 0) continue;  // contact, end, heading, up, size, range, dimension
    std::string word = line.substr(i + 5);
    word.erase(0, word.find_first_not_of(" \t"));
    word.erase(word.find_last_not_of(" \t\r") + 1);
    if (word == "bspline") curve.type = CpfgCurve::Type::kBSpline;
    else if (word == "bsplineclosed") curve.type = CpfgCurve::Type::kBSplineClosed;
    else if (word == "bsplineendpoint") curve.type = CpfgCurve::Type::kBSplineEndpoint;
    else if (word == "bsplinephantom") curve.type = CpfgCurve::Type::kBSplinePhantom;
    else if (word == "bezier") curve.type = CpfgCurve::Type::kBezier;
    else return lines.error("a curve's type is bspline, bsplineclosed, bsplineendpoint, bsplinephantom or bezier");
    break;
  }
  if (count == 0) return lines.error("expected 'points:' before 'type:'");
  for (size_t k = 0; k < count; ++k) {
    if (lines.done()) return lines.at_end("expected " + std::to_string(count) + " control points, found " + std::to_string(k));
    auto v = numbers_after(lines.take(), "");
    if (!v || v->size() != 4) return lines.error("expected a control point 'x y z multiplicity'");
    const double m = (*v)[3];
    if (m != std::floor(m) || m < 1 || m > 16) return lines.error("a control point's multiplicity is a whole number from 1 to 16");
    for (int r = 0; r < static_cast<int>(m); ++r) curve.control.push_back({(*v)[0], (*v)[1], (*v)[2]});
  }
  // createPPoints: a closed curve repeats its first three points; a phantom one gets mirrored ends.
  auto& c = curve.control;
  if (curve.type == CpfgCurve::Type::kBSplineClosed)
    for (int k = 0; k < 3; ++k) c.push_back(c[static_cast<size_t>(k)]);
  if (curve.type == CpfgCurve::Type::kBSplinePhantom) {
    std::array<double, 3> first{}, last{};
    const size_t n = c.size();
    for (int a = 0; a < 3; ++a) first[a] = 2 * c[0][a] - c[1][a], last[a] = 2 * c[n - 1][a] - c[n - 2][a];
    c.insert(c.begin(), first);
    c.push_back(last);
  }
  if (samples < 2 || samples > kMaxCurveSamples)
    return file_diagnostic(path, "a curve is measured with 2 to " + std::to_string(kMaxCurveSamples) + " samples");
  // createAPoints: the arc length at each of `samples` points evenly spaced in the parameter.
  curve.lengths.resize(static_cast<size_t>(samples));
  std::array<double, 3> before = curve.point(0);
  for (int i = 1; i < samples; ++i) {
    const std::array<double, 3> p = curve.point(i / static_cast<double>(samples - 1));
    curve.length += std::hypot(p[0] - before[0], p[1] - before[1], p[2] - before[2]);
    curve.lengths[static_cast<size_t>(i)] = curve.length;
    before = p;
  }
  if (!(curve.length > 0)) return file_diagnostic(path, "the curve has no length (its control points coincide)");
  for (double& l : curve.lengths) l /= curve.length;
  return curve;
}

}  // namespace sylva::lsys
