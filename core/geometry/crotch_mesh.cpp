// crotch_mesh.cpp — see crotch_mesh.h.
#include "core/geometry/crotch_mesh.h"
#include "core/geometry/skeleton_bounds.h"
#include "core/util/parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace sylva {

namespace {

using glm::dvec3;

constexpr int kNewtonSteps = 8;
constexpr uint32_t kNone = UINT32_MAX;

// Where F = 0 near `start`: Newton steps along the central-difference gradient. Empty
// (the caller keeps `start`) when it does not settle, or leaves the cell's reach — a kink
// of the bounds can send a step anywhere.
std::optional<dvec3> project(const Crotch& c, std::span<const Frustum> frusta, const dvec3& start, double cell) {
  auto field = [&](const dvec3& p) { return crotch_field(c, frusta, p).value; };
  const double h = 1e-4 * cell;
  const double tolerance = 1e-7 * c.radius;
  dvec3 p = start;
  double f = field(p);
  for (int step = 0; step <= kNewtonSteps; ++step) {
    if (std::abs(f) < tolerance) return p;
    if (step == kNewtonSteps) break;
    const dvec3 g((field(p + dvec3(h, 0, 0)) - field(p - dvec3(h, 0, 0))) / (2 * h),
                  (field(p + dvec3(0, h, 0)) - field(p - dvec3(0, h, 0))) / (2 * h),
                  (field(p + dvec3(0, 0, h)) - field(p - dvec3(0, 0, h))) / (2 * h));
    const double g2 = glm::dot(g, g);
    if (!(g2 > 0)) break;
    p -= (f / g2) * g;
    if (!(glm::length(p - start) <= cell)) break;
    f = field(p);
  }
  return std::nullopt;
}

// The grid: n cells a side, corner (i, j, l) at origin + cell·(i, j, l).
struct Grid {
  int n = 0;
  double cell = 0;
  dvec3 origin{0};
  size_t corner(int i, int j, int l) const {
    const size_t m = size_t(n) + 1;
    return (size_t(l) * m + size_t(j)) * m + size_t(i);
  }
  size_t cell_index(int i, int j, int l) const { return (size_t(l) * size_t(n) + size_t(j)) * size_t(n) + size_t(i); }
  dvec3 at(int i, int j, int l) const { return origin + cell * dvec3(i, j, l); }
};

}  // namespace

TriangleMesh crotch_fillet_mesh(const Crotch& crotch, std::span<const Frustum> frusta, double cell_m) {
  if (!(cell_m > 0)) throw std::invalid_argument("crotch_fillet_mesh: cell_m must be > 0");
  TriangleMesh mesh;
  if (!(crotch.k > 0) || !(crotch.radius > 0)) return mesh;
  const double half_cells = std::ceil(crotch.radius / cell_m) + 1;  // a cell past the rim: the rim's edges have 4 cells
  if (!(2 * half_cells + 1 <= kMaxCrotchGridCells)) {
    throw std::invalid_argument("crotch_fillet_mesh: a cell of " + std::to_string(cell_m) + " m makes over " +
                                std::to_string(kMaxCrotchGridCells) + " cells a side for a crotch of radius " +
                                std::to_string(crotch.radius) + " m");
  }
  Grid grid;
  grid.n = 2 * static_cast<int>(half_cells) + 1;
  grid.cell = cell_m;
  grid.origin = crotch.centre - (0.5 * grid.n * cell_m) * dvec3(1);
  const int n = grid.n;

  std::vector<double> value((size_t(n) + 1) * (size_t(n) + 1) * (size_t(n) + 1));
  for (int l = 0; l <= n; ++l) {
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) value[grid.corner(i, j, l)] = crotch_field(crotch, frusta, grid.at(i, j, l)).value;
    }
  }
  auto outside = [&](int i, int j, int l) { return value[grid.corner(i, j, l)] > 0; };

  // One vertex a sign-changing cell; whether it is off the exact union (on the fillet
  // proper), and, where the blend acts, which group's surface it is nearer.
  std::vector<uint32_t> cell_vertex(size_t(n) * size_t(n) * size_t(n), kNone);
  std::vector<std::array<int, 3>> active;  // the sign-changing cells, in grid order
  std::vector<dvec3> points;
  std::vector<char> on_fillet, blended_parent, blended_lateral;
  const double off_union = 1e-6 * crotch.radius;
  static constexpr std::array<std::array<int, 3>, 8> kCorner{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                                              {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}}};
  static constexpr std::array<std::array<int, 2>, 12> kEdge{
      {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3}, {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};
  for (int l = 0; l < n; ++l) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        int outsides = 0;
        for (const auto& d : kCorner) outsides += outside(i + d[0], j + d[1], l + d[2]);
        if (outsides == 0 || outsides == 8) continue;
        std::array<double, 8> f;
        std::array<dvec3, 8> p;
        for (int v = 0; v < 8; ++v) {
          const auto& d = kCorner[v];
          f[v] = value[grid.corner(i + d[0], j + d[1], l + d[2])];
          p[v] = grid.at(i + d[0], j + d[1], l + d[2]);
        }
        dvec3 sum(0);
        int crossings = 0;
        for (const auto& e : kEdge) {
          const double fa = f[e[0]], fb = f[e[1]];
          if ((fa > 0) == (fb > 0)) continue;
          sum += p[e[0]] + (fa / (fa - fb)) * (p[e[1]] - p[e[0]]);
          ++crossings;
        }
        const dvec3 mean = sum / double(crossings);
        const dvec3 q = project(crotch, frusta, mean, cell_m).value_or(mean);
        const CrotchSample s = crotch_field(crotch, frusta, q);
        cell_vertex[grid.cell_index(i, j, l)] = static_cast<uint32_t>(points.size());
        active.push_back({i, j, l});
        points.push_back(q);
        on_fillet.push_back(s.k > 0 && std::min(s.parent, s.lateral) > off_union);
        blended_parent.push_back(s.k > 0 && s.parent <= s.lateral);
        blended_lateral.push_back(s.k > 0 && s.lateral < s.parent);
      }
    }
  }

  // Quads round sign-changing edges, wound so that their normal points along the edge
  // toward F > 0: the four cells in counter-clockwise order about the edge's axis.
  // A sign-changing edge from corner x along an axis lies in the cell whose lower corner is
  // x: the active cells, in grid order, list every such edge in the order of a walk over
  // all corners.
  std::vector<std::array<uint32_t, 3>> triangles;
  for (int axis = 0; axis < 3; ++axis) {
    const int b = (axis + 1) % 3, c = (axis + 2) % 3;  // (b, c, axis) right-handed
    for (const std::array<int, 3>& x : active) {
      if (x[b] < 1 || x[c] < 1) continue;
      std::array<int, 3> y = x;
      ++y[axis];
      const bool lo_out = outside(x[0], x[1], x[2]), hi_out = outside(y[0], y[1], y[2]);
      if (lo_out == hi_out) continue;
      std::array<uint32_t, 4> quad;
      static constexpr std::array<std::array<int, 2>, 4> kAround{{{-1, -1}, {0, -1}, {0, 0}, {-1, 0}}};
      // Kept where the fillet is: a vertex off the exact union, or vertices on both
      // groups' surfaces where the blend acts — a fillet narrower than a cell can have
      // no vertex of its own, and dropping the quad across it would leave the crease.
      bool off = false, parent_side = false, lateral_side = false;
      for (int q = 0; q < 4; ++q) {
        std::array<int, 3> cc = x;
        cc[b] += kAround[q][0];
        cc[c] += kAround[q][1];
        quad[q] = cell_vertex[grid.cell_index(cc[0], cc[1], cc[2])];
        off = off || on_fillet[quad[q]];
        parent_side = parent_side || blended_parent[quad[q]];
        lateral_side = lateral_side || blended_lateral[quad[q]];
      }
      if (!off && !(parent_side && lateral_side)) continue;
      if (lo_out) std::swap(quad[1], quad[3]);  // outside lies toward −axis
      const bool split02 = glm::length(points[quad[0]] - points[quad[2]]) <=
                           glm::length(points[quad[1]] - points[quad[3]]);
      const std::array<std::array<uint32_t, 3>, 2> pair =
          split02 ? std::array<std::array<uint32_t, 3>, 2>{{{quad[0], quad[1], quad[2]}, {quad[0], quad[2], quad[3]}}}
                  : std::array<std::array<uint32_t, 3>, 2>{{{quad[0], quad[1], quad[3]}, {quad[1], quad[2], quad[3]}}};
      for (const auto& t : pair) {
        const dvec3 cross = glm::cross(points[t[1]] - points[t[0]], points[t[2]] - points[t[0]]);
        if (glm::dot(cross, cross) > 0) triangles.push_back(t);
      }
    }
  }

  // Vertices as the triangles use them: one output vertex per (grid vertex, group, u past
  // the seam), in order of first use.
  std::vector<CrotchShade> shade(points.size());
  std::vector<char> shaded(points.size(), 0);
  std::vector<std::array<uint32_t, 4>> output(points.size(), {kNone, kNone, kNone, kNone});
  for (const auto& t : triangles) {
    const dvec3 centroid = (points[t[0]] + points[t[1]] + points[t[2]]) / 3.0;
    const CrotchShade at_centroid = crotch_shade(crotch, frusta, centroid);
    const bool parent = at_centroid.h >= 0.5;
    std::array<double, 3> u;
    for (int k = 0; k < 3; ++k) {
      if (!shaded[t[k]]) shade[t[k]] = crotch_shade(crotch, frusta, points[t[k]]), shaded[t[k]] = 1;
      u[k] = (parent ? shade[t[k]].parent_uv : shade[t[k]].lateral_uv).u;
    }
    const bool wraps = std::max({u[0], u[1], u[2]}) - std::min({u[0], u[1], u[2]}) > 0.5;
    for (int k = 0; k < 3; ++k) {
      const bool past_seam = wraps && u[k] < 0.5;
      uint32_t& slot = output[t[k]][(parent ? 2 : 0) + (past_seam ? 1 : 0)];
      if (slot == kNone) {
        const CrotchShade& s = shade[t[k]];
        const SurfaceUV& uv = parent ? s.parent_uv : s.lateral_uv;
        slot = static_cast<uint32_t>(mesh.positions.size());
        mesh.positions.push_back(points[t[k]]);
        mesh.normals.push_back(s.normal);
        mesh.uvs.emplace_back(uv.u + (past_seam ? 1.0 : 0.0), uv.v_m);
      }
      mesh.indices.push_back(slot);
    }
    mesh.triangle_frustum.push_back(parent ? at_centroid.parent_frustum : at_centroid.lateral_frustum);
  }
  return mesh;
}

TriangleMesh skeleton_fillets(const Skeleton& skeleton, std::span<const Frustum> frusta, unsigned threads) {
  return crotch_fillets(find_crotches(skeleton, frusta), skeleton, frusta, threads);
}

TriangleMesh asset_fillets(const Skeleton& skeleton, std::span<const Frustum> frusta, unsigned threads) {
  std::vector<Crotch> crotches = find_crotches(skeleton, frusta);
  const SkeletonBounds box = skeleton_bounds(skeleton);
  const double least_k = kFilletMinPixels / kFilletAssetPixels * glm::length(box.hi - box.lo);
  std::erase_if(crotches, [&](const Crotch& c) { return !(c.k >= least_k); });
  return crotch_fillets(crotches, skeleton, frusta, threads, 1.0);
}

TriangleMesh crotch_fillets(std::span<const Crotch> crotches, const Skeleton& skeleton,
                            std::span<const Frustum> frusta, unsigned threads, double cell_per_k) {
  TriangleMesh out;
  if (crotches.empty()) return out;
  const SkeletonBounds box = skeleton_bounds(skeleton);
  const double min_cell = kFilletMinCellPerExtent * glm::length(box.hi - box.lo);
  std::vector<TriangleMesh> meshes(crotches.size());
  parallel_for(crotches.size(), threads, nullptr, [&](size_t i, unsigned) {
    const Crotch& c = crotches[i];
    if (c.k > 0) meshes[i] = crotch_fillet_mesh(c, frusta, std::max(c.k * cell_per_k, min_cell));
  });
  for (const TriangleMesh& m : meshes) append_mesh(out, m, 0);
  return out;
}

}  // namespace sylva
