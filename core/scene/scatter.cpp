// scatter.cpp — see scatter.h.
#include "core/scene/scatter.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <unordered_map>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/util/random.h"

namespace sylva {

namespace {

// Whether the rightward ray from p crosses edge ab (the even–odd rule's test).
bool crosses(glm::dvec2 a, glm::dvec2 b, glm::dvec2 p) {
  return (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x;
}

}  // namespace

bool inside_polygon(const std::vector<glm::dvec2>& poly, glm::dvec2 p) {
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++)
    if (crosses(poly[i], poly[j], p)) in = !in;
  return in;
}

PolygonBands::PolygonBands(const std::vector<glm::dvec2>& polygon) : polygon_(polygon) {
  const size_t n = polygon.size();
  if (n == 0) return;
  lo_ = hi_ = polygon.front().y;
  for (const glm::dvec2& q : polygon) lo_ = std::min(lo_, q.y), hi_ = std::max(hi_, q.y);
  double spans = 0;
  for (size_t i = 0, j = n - 1; i < n; j = i++) spans += std::abs(polygon[i].y - polygon[j].y);
  const double height = hi_ - lo_;
  // As many bands as edges, fewer where edges are tall (a comb's teeth cross every band):
  // the entries, Σ (bands an edge crosses), stay within about 9 per edge.
  double bands = static_cast<double>(n);
  if (spans > 0) bands = std::min(bands, 8.0 * static_cast<double>(n) * height / spans);
  bands_ = height > 0 ? static_cast<uint32_t>(std::clamp(bands, 1.0, static_cast<double>(n))) : 1;
  scale_ = height > 0 ? bands_ / height : 0;
  first_.assign(size_t{bands_} + 1, 0);
  auto each_band = [&](auto&& visit) {
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
      const double y0 = polygon[i].y, y1 = polygon[j].y;
      if (y0 == y1) continue;  // never crossed by a horizontal ray
      for (uint32_t b = band(std::min(y0, y1)), last = band(std::max(y0, y1)); b <= last; ++b) visit(b, i);
    }
  };
  each_band([&](uint32_t b, size_t) { ++first_[b + 1]; });
  for (uint32_t b = 0; b < bands_; ++b) first_[b + 1] += first_[b];
  edges_.resize(first_[bands_]);
  std::vector<uint32_t> fill(first_.begin(), first_.end() - 1);
  each_band([&](uint32_t b, size_t i) { edges_[fill[b]++] = static_cast<uint32_t>(i); });
}

uint32_t PolygonBands::band(double y) const {
  return static_cast<uint32_t>(std::clamp(std::floor((y - lo_) * scale_), 0.0, double(bands_ - 1)));
}

bool PolygonBands::inside(glm::dvec2 p) const {
  if (polygon_.empty() || p.y < lo_ || p.y >= hi_) return false;  // no edge straddles p.y
  // An edge straddles p.y when its lower end is at or below p.y and its upper end above,
  // so (band is monotone) it is listed in p.y's band: the same crossings as the full walk.
  const uint32_t b = band(p.y);
  const size_t n = polygon_.size();
  bool in = false;
  for (uint32_t k = first_[b]; k < first_[b + 1]; ++k) {
    const size_t i = edges_[k], j = i == 0 ? n - 1 : i - 1;
    if (crosses(polygon_[i], polygon_[j], p)) in = !in;
  }
  return in;
}

double PolygonBands::mean_band_edges() const {
  return bands_ > 0 ? static_cast<double>(edges_.size()) / bands_ : 0;
}

double scatter_area_m2(const SceneScatter& s) {
  if (s.disc_centre) return std::numbers::pi * s.disc_radius * s.disc_radius;
  double twice = 0;
  for (size_t i = 0, j = s.polygon.size() - 1; i < s.polygon.size(); j = i++)
    twice += s.polygon[j].x * s.polygon[i].y - s.polygon[i].x * s.polygon[j].y;
  return std::abs(twice) / 2;
}

double scatter_weighted_area_m2(const SceneScatter& s) {
  if (!s.disc_centre || !(s.disc_fade > 0)) return scatter_area_m2(s);
  const double r = s.disc_radius, f = s.disc_fade;
  return std::numbers::pi * (r * r - r * f + f * f / 3);
}

double scatter_rim_weight(const SceneScatter& s, glm::dvec2 xz) {
  if (!s.disc_centre || !(s.disc_fade > 0)) return 1;
  const double inside_m = s.disc_radius - glm::length(xz - *s.disc_centre);
  return std::clamp(inside_m / s.disc_fade, 0.0, 1.0);
}

Expected<std::vector<ScatterPlacement>> place_scatter(const SceneScatter& s) {
  glm::dvec2 lo, hi;
  if (s.disc_centre) {
    lo = *s.disc_centre - glm::dvec2(s.disc_radius);
    hi = *s.disc_centre + glm::dvec2(s.disc_radius);
  } else {
    lo = hi = s.polygon.front();
    for (const glm::dvec2& p : s.polygon) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  }
  const std::optional<PolygonBands> bands =
      s.disc_centre ? std::nullopt : std::optional<PolygonBands>(std::in_place, s.polygon);
  const uint64_t max_darts = 30 * s.count + 1000;
  if (bands && static_cast<double>(max_darts) * bands->mean_band_edges() > kMaxScatterEdgeTests) {
    char why[300];
    std::snprintf(why, sizeof why,
                  "the polygon's %zu corners cross each other's height so often (%.0f edges in a band on average) "
                  "that placing %llu plants would test about %.3g edges, more than the limit of %.3g; simplify "
                  "the polygon or lower the count",
                  s.polygon.size(), bands->mean_band_edges(), static_cast<unsigned long long>(s.count),
                  static_cast<double>(max_darts) * bands->mean_band_edges(), kMaxScatterEdgeTests);
    return file_diagnostic("", why);
  }
  auto inside = [&](glm::dvec2 p) {
    if (s.disc_centre) {
      const glm::dvec2 d = p - *s.disc_centre;
      return glm::dot(d, d) <= s.disc_radius * s.disc_radius;
    }
    return bands->inside(p);
  };
  Rng darts(s.seed), attributes(s.seed ^ 0x5ca77e5eed5ca77eull), rim(s.seed ^ 0x0f4de0f4de0f4de0ull);
  std::vector<ScatterPlacement> out;
  out.reserve(static_cast<size_t>(s.count));
  // The spacing grid: cells min_spacing wide, keyed by their integer coordinates.
  const double cell = s.min_spacing;
  std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
  auto key = [](int64_t i, int64_t j) { return (static_cast<uint64_t>(i) << 32) ^ static_cast<uint64_t>(j & 0xffffffff); };
  auto cell_of = [&](glm::dvec2 p) {
    return std::pair<int64_t, int64_t>{static_cast<int64_t>(std::floor((p.x - lo.x) / cell)),
                                       static_cast<int64_t>(std::floor((p.y - lo.y) / cell))};
  };
  for (uint64_t dart = 0; dart < max_darts && out.size() < s.count; ++dart) {
    const glm::dvec2 p(lo.x + darts.next_double() * (hi.x - lo.x), lo.y + darts.next_double() * (hi.y - lo.y));
    if (!inside(p)) continue;
    if (const double w = scatter_rim_weight(s, p); w < 1 && !(rim.next_double() < w)) continue;
    if (cell > 0) {
      const auto [ci, cj] = cell_of(p);
      bool free = true;
      for (int64_t di = -1; di <= 1 && free; ++di)
        for (int64_t dj = -1; dj <= 1 && free; ++dj) {
          auto found = grid.find(key(ci + di, cj + dj));
          if (found == grid.end()) continue;
          for (uint32_t k : found->second) {
            const glm::dvec2 d = out[k].xz - p;
            if (glm::dot(d, d) < cell * cell) {
              free = false;
              break;
            }
          }
        }
      if (!free) continue;
      grid[key(ci, cj)].push_back(static_cast<uint32_t>(out.size()));
    }
    ScatterPlacement placed;
    placed.xz = p;
    placed.rotate_y_deg = s.rotate_min_deg + attributes.next_double() * (s.rotate_max_deg - s.rotate_min_deg);
    placed.scale = s.scale_min + attributes.next_double() * (s.scale_max - s.scale_min);
    if (s.plant_seeds) {
      const auto [first, last] = *s.plant_seeds;
      const uint64_t span = last - first;  // the whole 2^64 range: any draw
      placed.plant_seed = span == UINT64_MAX ? attributes.next_u64() : first + attributes.below(span + 1);
    } else {
      placed.plant_seed = attributes.next_u64();
    }
    out.push_back(placed);
  }
  if (out.size() < s.count) {
    char why[200];
    std::snprintf(why, sizeof why,
                  "only %zu of the %llu plants fit %g m apart in the area of %g m^2 (after %llu tries); lower count, "
                  "density or min_spacing, or widen the area",
                  out.size(), static_cast<unsigned long long>(s.count), s.min_spacing, scatter_area_m2(s),
                  static_cast<unsigned long long>(max_darts));
    return file_diagnostic("", why);
  }
  return out;
}

}  // namespace sylva
