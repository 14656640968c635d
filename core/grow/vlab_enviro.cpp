// vlab_enviro.cpp — vlab's honda81 and chiba, built in (vlab_enviro.h).
#include "core/grow/vlab_enviro.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "core/util/random.h"

namespace sylva {

std::vector<double> honda81_answers(const lsys::Grammar::Honda81& spec, std::span<const Honda81Query> queries) {
  const double r2 = spec.radius * spec.radius;
  const double cell = spec.radius > 0 ? spec.radius : 1.0;
  auto key_of = [&](const glm::dvec3& p, int dx, int dy, int dz) {
    // Clamped: a tiny radius over a far position must not overflow the cast.
    auto c = [&](double v, int d) { return static_cast<int64_t>(std::clamp(std::floor(v / cell), -4e18, 4e18)) + d; };
    const uint64_t a = static_cast<uint64_t>(c(p.x, dx)), b = static_cast<uint64_t>(c(p.y, dy)),
                   z = static_cast<uint64_t>(c(p.z, dz));
    return mix_pair(mix_pair(a, b), z);
  };
  // In 2D honda81 compares x and z: the grid and the distances then see (x, z, 0).
  std::vector<glm::dvec3> at(queries.size());
  for (size_t i = 0; i < queries.size(); ++i) {
    const glm::dvec3& p = queries[i].position;
    at[i] = spec.three_d ? p : glm::dvec3(p.x, p.z, 0);
  }
  std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
  for (size_t i = 0; i < queries.size(); ++i) grid[key_of(at[i], 0, 0, 0)].push_back(static_cast<uint32_t>(i));
  std::vector<double> answers(queries.size(), 1.0);
  for (size_t i = 0; i < queries.size(); ++i) {
    const Honda81Query& a = queries[i];
    for (int dx = -1; dx <= 1 && answers[i] == 1.0; ++dx)
      for (int dy = -1; dy <= 1 && answers[i] == 1.0; ++dy)
        for (int dz = -1; dz <= 1 && answers[i] == 1.0; ++dz) {
          auto it = grid.find(key_of(at[i], dx, dy, dz));
          if (it == grid.end()) continue;
          for (uint32_t j : it->second) {
            const Honda81Query& b = queries[j];
            if (j == i || b.index != a.index || a.vigor > b.vigor) continue;
            const glm::dvec3 d = at[i] - at[j];
            if (d.x * d.x + d.y * d.y + d.z * d.z <= r2) {
              answers[i] = 0.0;
              break;
            }
          }
        }
  }
  return answers;
}

namespace {

using Triangle = std::array<glm::dvec3, 3>;

// Jon Leech's sphere (chiba's sphere.c): the octahedron, each triangle's vertices reversed,
// cut `level - 1` times into four with the new vertices on the unit sphere, in its order.
std::vector<Triangle> leech_sphere(int level) {
  const glm::dvec3 xp(1, 0, 0), xm(-1, 0, 0), yp(0, 1, 0), ym(0, -1, 0), zp(0, 0, 1), zm(0, 0, -1);
  std::vector<Triangle> tris = {{xp, zp, yp}, {yp, zp, xm}, {xm, zp, ym}, {ym, zp, xp},
                                {xp, yp, zm}, {yp, xm, zm}, {xm, ym, zm}, {ym, xp, zm}};
  for (Triangle& t : tris) std::swap(t[0], t[2]);
  for (int l = 1; l < level; ++l) {
    std::vector<Triangle> next;
    next.reserve(tris.size() * 4);
    for (const Triangle& t : tris) {
      const glm::dvec3 a = glm::normalize((t[0] + t[2]) * 0.5);
      const glm::dvec3 b = glm::normalize((t[0] + t[1]) * 0.5);
      const glm::dvec3 c = glm::normalize((t[1] + t[2]) * 0.5);
      next.push_back({t[0], b, a});
      next.push_back({b, t[1], c});
      next.push_back({a, b, c});
      next.push_back({a, c, t[2]});
    }
    tris = std::move(next);
  }
  return tris;
}

}  // namespace

std::vector<ChibaSample> chiba_samples(const lsys::Grammar::Chiba& spec) {
  std::vector<ChibaSample> out;
  if (!spec.sources.empty()) {
    double total = 0;
    for (const auto& s : spec.sources) total += s.intensity;
    for (const auto& s : spec.sources)
      out.push_back({glm::normalize(glm::dvec3(s.direction[0], s.direction[1], s.direction[2])), s.intensity / total});
    return out;
  }
  // The closest 8 * 4^k at or above the samples asked for (chiba's GenerateSamples).
  const int level = std::clamp(
      static_cast<int>(std::ceil(std::log(spec.samples / 8.0) / std::log(4.0))) + 1, 1, lsys::Grammar::Chiba::kMaxLevel);
  for (const Triangle& t : leech_sphere(level)) out.push_back({glm::normalize((t[0] + t[1] + t[2]) / 3.0), 0.0});
  if (spec.cie_sky) {
    // The CIE overcast sky of chiba's OvercastSky, over the upper samples only.
    double total = 0;
    for (ChibaSample& s : out) {
      if (s.direction.y <= 0) continue;
      const double c = s.direction.y / std::sqrt(s.direction.x * s.direction.x + s.direction.y * s.direction.y);
      s.intensity = (1 + c) / 3.0 * (8.6 * c + 0.123) / 0.203;
      total += s.intensity;
    }
    for (ChibaSample& s : out) s.intensity /= total;
  } else {
    size_t up = 0;
    for (const ChibaSample& s : out) up += s.direction.y >= 0;
    const double ratio = spec.lower_to_upper;
    for (ChibaSample& s : out)
      s.intensity = s.direction.y >= 0 ? 1.0 / static_cast<double>(up) / (1.0 + ratio)
                                       : ratio / static_cast<double>(out.size() - up) / (1.0 + ratio);
  }
  return out;
}

double chiba_dimming(const lsys::Grammar::Chiba& spec, const glm::dvec3& from, double own_radius,
                     const glm::dvec3& direction, const ChibaBall& other) {
  const glm::dvec3 v = from - other.centre;
  const double along = glm::dot(direction, v);  // -(distance to the point nearest the centre)
  // The centre's squared distance from the ray's line, without the cancellation of |v|² − along².
  const glm::dvec3 off = v - along * direction;
  const double d2 = glm::dot(off, off);
  const double t = spec.transmittance;
  if (spec.estimate_area) {
    // ComputeCoveredArea: the other ball's disc, seen along the ray, over this ball's disc.
    if (along > 0) return 1;  // its centre lies behind
    const double reach = other.radius + own_radius;
    if (!(d2 < reach * reach)) return 1;
    const double r1 = std::max(other.radius, own_radius), r2 = std::min(other.radius, own_radius);
    const double d = std::sqrt(d2);
    double area;
    if (d + r2 <= r1) {
      area = std::numbers::pi * r2 * r2;
    } else {
      // The lens of two circles d apart (d > 0 here, since r2 < r1 + d).
      const double x1 = (r1 * r1 + d2 - r2 * r2) / (2 * d), x2 = (r2 * r2 + d2 - r1 * r1) / (2 * d);
      const double y = std::sqrt(std::max(0.0, r2 * r2 - x2 * x2));
      area = r1 * r1 * std::acos(std::clamp(x1 / r1, -1.0, 1.0)) + r2 * r2 * std::acos(std::clamp(x2 / r2, -1.0, 1.0)) -
             y * d;
    }
    // A ball of radius 0 is a point: covered wholly when the other disc holds it.
    const double own = std::numbers::pi * own_radius * own_radius;
    const double share = own > 0 ? std::clamp(area / own, 0.0, 1.0) : 1.0;
    return 1 - (1 - t) * share;
  }
  // IsClusterIntersection: the length of the ray inside the ball widened by the beam.
  const double widened = other.radius + own_radius * spec.beam_radius;
  const double disc = widened * widened - d2;
  if (!(disc >= 0)) return 1;
  const double half = std::sqrt(disc);
  if (!(-along + half > 0)) return 1;  // the ball lies behind
  const double length = -along - half >= 0 ? 2 * half : -along + half;
  if (!(length > 0)) return 1;
  return std::pow(t, length / (2.0 * widened));
}

std::vector<ChibaAnswer> chiba_answers(const lsys::Grammar::Chiba& spec, std::span<const ChibaBall> balls) {
  const std::vector<ChibaSample> samples = chiba_samples(spec);
  const size_t n = balls.size();
  std::vector<ChibaAnswer> answers(n);
  if (n == 0) return answers;
  // A ball can dim a ray that passes within its radius plus the beam (at most the largest
  // radius times beam_radius), or with the area estimate plus the asking ball's radius:
  // register it in every cell that widened box overlaps.
  double largest = 0;
  for (const ChibaBall& b : balls) largest = std::max(largest, b.radius);
  const double widen = largest * (spec.estimate_area ? 1.0 : spec.beam_radius);
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const ChibaBall& b : balls) {
    const double r = b.radius + widen;
    lo = glm::min(lo, b.centre - r);
    hi = glm::max(hi, b.centre + r);
  }
  // About one ball per cell, cubic cells, at most 128 a side.
  const glm::dvec3 extent = glm::max(hi - lo, glm::dvec3(1e-300));
  const double volume = std::max(extent.x * extent.y * extent.z, 1e-300);
  const double edge = std::cbrt(volume / static_cast<double>(n));
  int dims[3];
  glm::dvec3 cell;
  for (int a = 0; a < 3; ++a) {
    dims[a] = std::clamp(static_cast<int>(std::ceil(extent[a] / std::max(edge, 1e-300))), 1, 128);
    cell[a] = extent[a] / dims[a];
  }
  auto index_of = [&](double v, int a) {
    return std::clamp(static_cast<int>(std::floor((v - lo[a]) / cell[a])), 0, dims[a] - 1);
  };
  const size_t cells = static_cast<size_t>(dims[0]) * dims[1] * dims[2];
  std::vector<uint32_t> start(cells + 1, 0), items;
  auto for_cells = [&](const ChibaBall& b, auto&& visit) {
    const double r = b.radius + widen;
    int a0[3], a1[3];
    for (int a = 0; a < 3; ++a) {
      // A hair wider than the box, so a ray grazing a cell face still finds the ball.
      const double pad = 1e-9 * (std::abs(b.centre[a]) + r + cell[a]);
      a0[a] = index_of(b.centre[a] - r - pad, a);
      a1[a] = index_of(b.centre[a] + r + pad, a);
    }
    for (int z = a0[2]; z <= a1[2]; ++z)
      for (int y = a0[1]; y <= a1[1]; ++y)
        for (int x = a0[0]; x <= a1[0]; ++x) visit((static_cast<size_t>(z) * dims[1] + y) * dims[0] + x);
  };
  for (const ChibaBall& b : balls) for_cells(b, [&](size_t c) { ++start[c + 1]; });
  for (size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
  items.resize(start[cells]);
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t j = 0; j < n; ++j) for_cells(balls[j], [&](size_t c) { items[fill[c]++] = static_cast<uint32_t>(j); });
  }
  std::vector<uint64_t> seen(n, 0);
  uint64_t ray = 0;
  for (size_t i = 0; i < n; ++i) {
    const ChibaBall& own = balls[i];
    double sum = 0;
    glm::dvec3 toward(0.0);
    for (const ChibaSample& s : samples) {
      if (s.intensity == 0) continue;
      ++ray;
      seen[i] = ray;  // a ball does not dim its own light
      double reduction = 1;
      // Amanatides & Woo: the cells the ray from the centre crosses, in order.
      int at[3], step[3];
      double next[3], delta[3];
      for (int a = 0; a < 3; ++a) {
        at[a] = index_of(own.centre[a], a);
        const double dir = s.direction[a];
        if (dir > 0) {
          step[a] = 1;
          next[a] = (lo[a] + (at[a] + 1) * cell[a] - own.centre[a]) / dir;
          delta[a] = cell[a] / dir;
        } else if (dir < 0) {
          step[a] = -1;
          next[a] = (lo[a] + at[a] * cell[a] - own.centre[a]) / dir;
          delta[a] = -cell[a] / dir;
        } else {
          step[a] = 0;
          next[a] = delta[a] = std::numeric_limits<double>::infinity();
        }
      }
      for (;;) {
        const size_t c = (static_cast<size_t>(at[2]) * dims[1] + at[1]) * dims[0] + at[0];
        for (uint32_t k = start[c]; k < start[c + 1]; ++k) {
          const uint32_t j = items[k];
          if (seen[j] == ray) continue;
          seen[j] = ray;
          reduction *= chiba_dimming(spec, own.centre, own.radius, s.direction, balls[j]);
        }
        const int a = next[0] <= next[1] ? (next[0] <= next[2] ? 0 : 2) : (next[1] <= next[2] ? 1 : 2);
        if (step[a] == 0) break;
        at[a] += step[a];
        if (at[a] < 0 || at[a] >= dims[a]) break;
        next[a] += delta[a];
      }
      const double light = s.intensity * reduction;
      sum += light;
      toward += light * s.direction;
    }
    answers[i].light = sum;
    const double len = glm::length(toward);
    answers[i].brightest = len > 0 ? toward / len : glm::dvec3(0.0);
  }
  return answers;
}

}  // namespace sylva
