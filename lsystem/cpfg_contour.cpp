// cpfg_contour.cpp — cpfg's contours (see cpfg_contour.h).
#include "lsystem/cpfg_contour.h"

#include <charconv>
#include <cmath>
#include <optional>

#include "core/util/file_io.h"
#include "lsystem/source_text.h"

namespace sylva::lsys {

namespace {

using Point = std::array<double, 3>;

// The uniform cubic B-spline through `p` at parameter t (cpfg's evaluate_spline with its
// m_B_spline): the piece of points floor(t) .. floor(t) + 3, indices past the end wrapping.
Point evaluate(const std::vector<Point>& p, double t) {
  const size_t n = p.size();
  const double f = std::floor(t);
  const double u = t - f, u2 = u * u, u3 = u2 * u;
  const double b[4] = {(1 - u) * (1 - u) * (1 - u) / 6, (3 * u3 - 6 * u2 + 4) / 6, (-3 * u3 + 3 * u2 + 3 * u + 1) / 6,
                       u3 / 6};
  size_t first = static_cast<size_t>(std::max(0.0, f)) % n;
  Point r{0, 0, 0};
  for (int i = 0; i < 4; ++i) {
    for (int c = 0; c < 3; ++c) r[static_cast<size_t>(c)] += b[i] * p[first][static_cast<size_t>(c)];
    first = first + 1 == n ? 0 : first + 1;
  }
  return r;
}

std::optional<std::vector<double>> numbers(std::string_view text) {
  std::vector<double> out;
  size_t i = 0;
  while (true) {
    while (i < text.size() && detail::is_space(text[i])) ++i;
    if (i == text.size()) return out;
    double v = 0;
    const char* first = text.data() + i + (text[i] == '+' ? 1 : 0);
    auto [ptr, ec] = std::from_chars(first, text.data() + text.size(), v);
    if (ec != std::errc() || !std::isfinite(v)) return std::nullopt;
    i = static_cast<size_t>(ptr - text.data());
    out.push_back(v);
  }
}

}  // namespace

std::vector<Point> CpfgContour::sample(int sides) const {
  // cpfg's MakeContour (general.c): 10 points per unit of the parameter give the partial
  // lengths (in x and y), then `sides` steps of equal length along them, the parameter of
  // each found on the line between its two neighbouring partial lengths.
  constexpr int kPerUnit = 10;
  const size_t num = control.size();
  const int segments = closed ? static_cast<int>(num) : static_cast<int>(num) - 3;
  std::vector<double> lengths(static_cast<size_t>(segments * kPerUnit));
  Point last = evaluate(control, 0);
  double total = 0;
  for (int i = 0; i < segments; ++i)
    for (int j = 0; j < kPerUnit; ++j) {
      const Point now = evaluate(control, i + static_cast<double>(j) / kPerUnit);
      total += std::hypot(last[0] - now[0], last[1] - now[1]);
      lengths[static_cast<size_t>(i * kPerUnit + j)] = total;
      last = now;
    }
  const Point start = evaluate(control, 0);
  if (closed) total += std::hypot(last[0] - start[0], last[1] - start[1]);
  const double step = total / sides;
  // A closed contour turned about the origin so that its first point lies on +x.
  double r00 = 1, r01 = 0, r10 = 0, r11 = 1;
  if (closed) {
    const double len = std::hypot(start[0], start[1]);
    if (len * len >= 1e-9) {
      r00 = start[0] / len, r01 = -start[1] / len;
      r10 = -r01, r11 = r00;
    }
  }
  const int count = closed ? sides : sides + 1;
  const int last_index = segments * kPerUnit - 1;
  std::vector<Point> out;
  out.reserve(static_cast<size_t>(sides + 1));
  int j = 0;
  double along = 0;
  for (int i = 0; i < count; ++i) {
    double t = 0;
    if (i > 0) {
      while (lengths[static_cast<size_t>(j)] < along && j < last_index) ++j;
      int j2 = j - 1;
      while (j2 > 0 && lengths[static_cast<size_t>(j)] - lengths[static_cast<size_t>(j2)] <= 1e-10 / step) --j2;
      const double span = lengths[static_cast<size_t>(j)] - lengths[static_cast<size_t>(std::max(j2, 0))];
      t = static_cast<double>(std::max(j2, 0)) / kPerUnit;
      if (span > 0) t += (along - lengths[static_cast<size_t>(std::max(j2, 0))]) / span / kPerUnit;
    }
    const Point p = evaluate(control, t);
    out.push_back({p[0] * r00 + p[1] * r10, p[0] * r01 + p[1] * r11, p[2]});
    along += step;
  }
  if (closed) out.push_back(out.front());
  return out;
}

Expected<CpfgContour> read_cpfg_contour(const std::string& path, int id) {
  Expected<std::string> text = read_text_file(path);
  if (!text) return std::move(text.error());
  std::vector<std::string> lines;
  detail::for_each_physical_line(*text, [&](uint32_t, std::string_view line, bool) { lines.emplace_back(line); });
  auto error = [&](size_t line, std::string message) {
    Diagnostic d = diagnostic_at(path, {static_cast<uint32_t>(line + 1), 1}, std::move(message));
    if (line < lines.size()) set_source_line(d, lines[line]);
    return d;
  };
  CpfgContour c;
  c.id = id;
  if (lines.empty()) return error(0, "an empty contour file");
  size_t at = 0;
  int records = 0;
  if (lines[0].rfind("cver", 0) == 0) {
    auto v = numbers(std::string_view(lines[0]).substr(4));
    if (!v || v->size() != 2 || (*v)[0] != 1 || (*v)[1] < 1 || (*v)[1] > 3)
      return error(0, "this contour format is not supported (cpfg reads 'cver 1 1' to 'cver 1 3')");
    at = 1;
    // name:, points: n total, type: (open|closed[, regular]), samples: (1.3), and what vlab's
    // editor adds before the points (a background image, markers): skipped up to the points.
    for (; at < lines.size(); ++at) {
      std::string_view l = lines[at];
      while (!l.empty() && detail::is_space(l.front())) l.remove_prefix(1);
      if (l.rfind("points:", 0) == 0) {
        auto n = numbers(l.substr(7));
        if (!n || n->size() != 2 || (*n)[0] < 1 || (*n)[0] > 1e5 || (*n)[0] != std::floor((*n)[0]))
          return error(at, "expected 'points: n total'");
        records = static_cast<int>((*n)[0]);
      } else if (l.rfind("type:", 0) == 0) {
        l.remove_prefix(5);
        while (!l.empty() && detail::is_space(l.front())) l.remove_prefix(1);
        if (l.empty() || (l[0] != 'o' && l[0] != 'c')) return error(at, "a contour's type is open or closed ('type: or')");
        c.closed = l[0] == 'c';
      } else if (!l.empty() && (detail::is_digit(l[0]) || l[0] == '-' || l[0] == '+' || l[0] == '.')) {
        break;  // the first point
      }
    }
    if (records == 0) return error(at, "expected 'points: n total' before the points");
    for (int k = 0; k < records; ++k, ++at) {
      if (at >= lines.size()) return error(at, "expected " + std::to_string(records) + " points, found " + std::to_string(k));
      auto p = numbers(lines[at]);
      if (!p || p->size() != 4 || (*p)[3] != std::floor((*p)[3]) || (*p)[3] < 1 || (*p)[3] > 16)
        return error(at, "expected a point 'x y z multiplicity' (multiplicity a whole number from 1 to 16)");
      for (int m = 0; m < static_cast<int>((*p)[3]); ++m) c.control.push_back({(*p)[0], (*p)[1], (*p)[2]});
    }
  } else {
    // The oldest format: "n dim open|closed", then n points of dim coordinates.
    const std::string& head = lines[0];
    auto first_numbers = numbers(head.substr(0, head.find_first_of("oc")));
    if (!first_numbers || first_numbers->size() != 2 || ((*first_numbers)[1] != 2 && (*first_numbers)[1] != 3) ||
        (*first_numbers)[0] < 1 || (*first_numbers)[0] > 1e5)
      return error(0, "expected 'cver 1 3' or 'n dim open|closed' (a vlab contour file)");
    c.closed = head.find("closed") != std::string::npos;
    const int dim = static_cast<int>((*first_numbers)[1]);
    std::vector<double> all;
    for (at = 1; at < lines.size(); ++at) {
      auto p = numbers(lines[at]);
      if (!p) return error(at, "expected the contour's coordinates");
      all.insert(all.end(), p->begin(), p->end());
    }
    const size_t n = static_cast<size_t>((*first_numbers)[0]);
    if (all.size() < n * static_cast<size_t>(dim)) return error(lines.size(), "fewer coordinates than the points it says");
    for (size_t k = 0; k < n; ++k)
      c.control.push_back({all[k * dim], all[k * dim + 1], dim == 3 ? all[k * dim + 2] : 0.0});
  }
  if (c.control.size() < 4) return error(at, "a contour needs at least 4 control points (cpfg's cubic B-spline)");
  return c;
}

}  // namespace sylva::lsys
