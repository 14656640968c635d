// cpfg_surface.cpp — cpfg's predefined surfaces (see cpfg_surface.h).
#include "lsystem/cpfg_surface.h"

#include <algorithm>
#include <charconv>
#include <optional>
#include <cmath>

#include "core/util/file_io.h"
#include "lsystem/source_text.h"

namespace sylva::lsys {

namespace {

struct Token {
  std::string text;
  uint32_t line = 0, column = 0;
};

// The file's words, `KEY:value` split after its colon (the files write `X: 0.1`, and
// sometimes `X:0.1`).
std::vector<Token> words_of(const std::string& text) {
  std::vector<Token> out;
  detail::for_each_physical_line(text, [&](uint32_t line_no, std::string_view line, bool) {
    size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && detail::is_space(line[i])) ++i;
      const size_t start = i;
      while (i < line.size() && !detail::is_space(line[i])) ++i;
      if (i == start) continue;
      std::string_view w = line.substr(start, i - start);
      const size_t colon = w.find(':');
      if (colon != std::string_view::npos && colon + 1 < w.size() && colon > 0) {
        out.push_back({std::string(w.substr(0, colon + 1)), line_no, static_cast<uint32_t>(start + 1)});
        out.push_back({std::string(w.substr(colon + 1)), line_no, static_cast<uint32_t>(start + colon + 2)});
      } else {
        out.push_back({std::string(w), line_no, static_cast<uint32_t>(start + 1)});
      }
    }
  });
  return out;
}

class Reader {
 public:
  Reader(std::string path, std::vector<Token> words) : path_(std::move(path)), words_(std::move(words)) {}
  bool done() const { return next_ >= words_.size(); }
  const std::string& peek() const { return words_[next_].text; }
  Diagnostic error(std::string message) const {
    if (done()) {
      const uint32_t line = words_.empty() ? 1 : words_.back().line;
      return diagnostic_at(path_, {line, 1}, std::move(message) + ", found the end of the file");
    }
    return diagnostic_at(path_, {words_[next_].line, words_[next_].column}, std::move(message));
  }
  // The next word, which must be `word`.
  Status expect(std::string_view word) {
    if (done() || words_[next_].text != word) return error("expected '" + std::string(word) + "'");
    ++next_;
    return {};
  }
  Expected<double> number() {
    if (done()) return error("expected a number");
    const std::string& w = words_[next_].text;
    double v = 0;
    const char* first = w.data() + (!w.empty() && w[0] == '+' ? 1 : 0);
    auto [ptr, ec] = std::from_chars(first, w.data() + w.size(), v);
    if (ec != std::errc() || ptr != w.data() + w.size() || !std::isfinite(v)) return error("expected a number");
    ++next_;
    return v;
  }
  // `key` followed by a number.
  Expected<double> field(std::string_view key) {
    if (Status s = expect(key); !s) return std::move(s.error());
    return number();
  }
  Status skip_word() {
    if (done()) return error("expected a word");
    ++next_;
    return {};
  }

 private:
  std::string path_;
  std::vector<Token> words_;
  size_t next_ = 0;
};

using Vec = std::array<double, 3>;

Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

std::optional<Vec> normalized(const Vec& v) {
  const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(l > 0) || !std::isfinite(l)) return std::nullopt;
  return Vec{v[0] / l, v[1] / l, v[2] / l};
}

// "X: x Y: y Z: z" after `words` (e.g. "CONTACT", "POINT").
Expected<Vec> labelled_point(Reader& r, std::initializer_list<std::string_view> words) {
  for (std::string_view w : words)
    if (Status s = r.expect(w); !s) return std::move(s.error());
  Vec v{};
  const char* keys[] = {"X:", "Y:", "Z:"};
  for (int k = 0; k < 3; ++k) {
    auto x = r.field(keys[k]);
    if (!x) return std::move(x.error());
    v[static_cast<size_t>(k)] = *x;
  }
  return v;
}

double bernstein(int i, double u) {
  const double w = 1 - u;
  switch (i) {
    case 0: return w * w * w;
    case 1: return 3 * u * w * w;
    case 2: return 3 * u * u * w;
    default: return u * u * u;
  }
}

}  // namespace

Expected<CpfgSurface> read_cpfg_surface(const std::string& path, char id, double size, int s_cells, int t_cells) {
  Expected<std::string> text = read_text_file(path);
  if (!text) return std::move(text.error());
  Reader r(path, words_of(*text));
  // The bounding box: three pairs of extremes (cpfg reads and keeps them for textures).
  for (int k = 0; k < 6; ++k)
    if (auto v = r.number(); !v) return std::move(v.error());
  // PRECISION S: s T: t, else cpfg's half of S_COUNT; the view file's counts win. As cpfg's
  // initialize_patch, a missing t takes the file's s (patches.c sets t_precision = s_temp).
  int file_s = kMaxSurfaceCells / 2;
  if (!r.done() && r.peek() == "PRECISION") {
    if (Status s = r.expect("PRECISION"); !s) return std::move(s.error());
    auto s = r.field("S:");
    if (!s) return std::move(s.error());
    auto t = r.field("T:");
    if (!t) return std::move(t.error());
    file_s = static_cast<int>(std::clamp(*s, -1e9, 1e9));
  }
  CpfgSurface out;
  out.id = id;
  out.s_cells = std::clamp(s_cells > 0 ? s_cells : file_s, 1, kMaxSurfaceCells);
  out.t_cells = std::clamp(t_cells > 0 ? t_cells : file_s, 1, kMaxSurfaceCells);
  auto contact = labelled_point(r, {"CONTACT", "POINT"});
  if (!contact) return std::move(contact.error());
  if (auto end = labelled_point(r, {"END", "POINT"}); !end) return std::move(end.error());
  auto heading_in = labelled_point(r, {"HEADING"});
  if (!heading_in) return std::move(heading_in.error());
  auto up_in = labelled_point(r, {"UP"});
  if (!up_in) return std::move(up_in.error());
  auto max_dimension = r.field("SIZE:");
  if (!max_dimension) return std::move(max_dimension.error());
  if (*max_dimension == 0) return r.error("a surface's SIZE must not be 0 (the surface is scaled by size / SIZE)");
  // The surface's frame, as cpfg's determine_transform: left = H × U, up = left × H.
  auto heading = normalized(*heading_in);
  auto up0 = normalized(*up_in);
  if (!heading || !up0) return r.error("a surface's HEADING and UP must not be 0");
  auto left = normalized(cross(*heading, *up0));
  if (!left) return r.error("a surface's HEADING and UP must not be parallel");
  const Vec up = cross(*left, *heading);
  const double scale = size / *max_dimension;
  while (!r.done()) {
    if (out.patches.size() >= 10000) return r.error("more than 10000 patches in one surface");
    if (Status s = r.skip_word(); !s) return std::move(s.error());  // the patch's name
    for (std::string_view w : {"TOP", "COLOR:"})
      if (Status s = r.expect(w); !s) return std::move(s.error());
    if (auto v = r.number(); !v) return std::move(v.error());
    if (auto v = r.field("DIFFUSE:"); !v) return std::move(v.error());
    for (std::string_view w : {"BOTTOM", "COLOR:"})
      if (Status s = r.expect(w); !s) return std::move(s.error());
    if (auto v = r.number(); !v) return std::move(v.error());
    if (auto v = r.field("DIFFUSE:"); !v) return std::move(v.error());
    // The neighbours' names (cpfg averages normals across them; sylva's leaves are flat).
    for (std::string_view key : {"AL:", "A:", "AR:", "L:", "R:", "BL:", "B:", "BR:"}) {
      if (Status s = r.expect(key); !s) return std::move(s.error());
      if (Status s = r.skip_word(); !s) return std::move(s.error());
    }
    Vec control[4][4];
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        Vec p{};
        for (int k = 0; k < 3; ++k) {
          auto v = r.number();
          if (!v) return std::move(v.error());
          p[static_cast<size_t>(k)] = (*v - (*contact)[static_cast<size_t>(k)]) * scale;
        }
        for (int k = 0; k < 3; ++k)
          control[i][j][static_cast<size_t>(k)] = p[0] * (*left)[static_cast<size_t>(k)] +
                                                  p[1] * (*heading)[static_cast<size_t>(k)] + p[2] * up[static_cast<size_t>(k)];
      }
    std::vector<Vec> grid;
    grid.reserve(static_cast<size_t>((out.s_cells + 1) * (out.t_cells + 1)));
    for (int s = 0; s <= out.s_cells; ++s) {
      const double u = static_cast<double>(s) / out.s_cells;
      for (int t = 0; t <= out.t_cells; ++t) {
        const double v = static_cast<double>(t) / out.t_cells;
        Vec q{0, 0, 0};
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j) {
            const double w = bernstein(i, u) * bernstein(j, v);
            for (int k = 0; k < 3; ++k) q[static_cast<size_t>(k)] += w * control[i][j][static_cast<size_t>(k)];
          }
        grid.push_back(q);
      }
    }
    out.patches.push_back(std::move(grid));
  }
  if (out.patches.empty()) return r.error("a surface needs at least one patch");
  return out;
}

Expected<CpfgSurface> read_cpfg_tsurface(const std::string& path, char id, double size) {
  Expected<std::string> text = read_text_file(path);
  if (!text) return std::move(text.error());
  CpfgSurface out;
  out.id = id;
  std::array<std::array<double, 3>, 3> triangle{};
  int vertex = -1;  // the vertex being read; -1: between triangles
  int values = 0;   // the numbers of that vertex read so far
  SourceLoc started{1, 1};
  std::optional<Diagnostic> failure;
  detail::for_each_physical_line(*text, [&](uint32_t line_no, std::string_view line, bool) {
    if (failure) return;
    size_t i = 0;
    while (i < line.size()) {
      auto delimiter = [](char ch) { return detail::is_space(ch) || ch == ',' || ch == ':'; };
      while (i < line.size() && delimiter(line[i])) ++i;
      const size_t start = i;
      while (i < line.size() && !delimiter(line[i])) ++i;
      if (i == start) break;
      const std::string_view word = line.substr(start, i - start);
      const SourceLoc at{line_no, static_cast<uint32_t>(start + 1)};
      if (vertex < 0) {
        if (word.substr(0, 8) != "triangle") continue;  // another word: passed over, as cpfg does
        if (out.triangles.size() >= kMaxTsurfaceTriangles)
          return void(failure = diagnostic_at(path, at, "more than " + std::to_string(kMaxTsurfaceTriangles) + " triangles"));
        vertex = 0;
        values = 0;
        started = at;
        continue;
      }
      double v = 0;
      const char* first = word.data() + (word[0] == '+' ? 1 : 0);
      auto [ptr, ec] = std::from_chars(first, word.data() + word.size(), v);
      if (ec != std::errc() || ptr != word.data() + word.size() || !std::isfinite(v))
        return void(failure = diagnostic_at(path, at, "expected a number: a triangle has three vertices of x y z "
                                                      "(and the normal, the texture's u v)"));
      if (values < 3) triangle[static_cast<size_t>(vertex)][static_cast<size_t>(values)] = v * size;
      if (++values > 8) break;  // the rest of the line is passed over, as cpfg does
    }
    if (vertex >= 0 && values >= 3) {
      values = 0;
      if (++vertex == 3) {
        out.triangles.push_back(triangle);
        vertex = -1;
      }
    }
  });
  if (failure) return std::move(*failure);
  if (vertex >= 0) return diagnostic_at(path, started, "this triangle has fewer than three vertices (x y z on each line)");
  if (out.triangles.empty()) return diagnostic_at(path, {1, 1}, "a tsurface needs at least one 'triangle'");
  return out;
}

}  // namespace sylva::lsys
