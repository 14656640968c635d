// gltf_lod.cpp — see gltf_lod.h.
#include "core/io/gltf_lod.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <glm/geometric.hpp>

#include "core/geometry/skin.h"
#include "core/geometry/tessellate.h"

namespace sylva {

namespace {

glm::dvec3 vec(const std::array<double, 3>& v) { return {v[0], v[1], v[2]}; }

// Twice the area vector of a polygon (Newell).
glm::dvec3 newell(const Leaf& leaf) {
  glm::dvec3 n(0);
  for (size_t i = 0; i < leaf.vertices_m.size(); ++i) {
    const glm::dvec3 a = vec(leaf.vertices_m[i]), b = vec(leaf.vertices_m[(i + 1) % leaf.vertices_m.size()]);
    n += glm::cross(a, b);
  }
  return n;
}

double leaf_area(const Leaf& leaf) { return 0.5 * glm::length(newell(leaf)); }

// Which chains each level 1 … `levels` keeps (lod_skeleton's rule): one skin, and one
// tessellation per level for the chains' costs.
std::vector<std::vector<bool>> kept_chains(const Skeleton& sk, uint32_t levels, int level0_columns,
                                           const SkinOptions& skin) {
  const size_t chains = sk.chains.size();
  std::vector<double> size(chains, 0);
  for (size_t c = 0; c < chains; ++c) {
    size[c] = sk.joints[sk.chains[c].first_joint].radius_m;
    if (sk.chains[c].parent) size[c] = std::min(size[c], size[sk.chains[c].parent->chain]);
  }
  std::vector<size_t> by_size(chains);
  std::iota(by_size.begin(), by_size.end(), size_t{0});
  std::stable_sort(by_size.begin(), by_size.end(), [&](size_t a, size_t b) {
    const bool root_a = !sk.chains[a].parent, root_b = !sk.chains[b].parent;
    if (root_a != root_b) return root_a;  // the root chains first, always kept
    return size[a] > size[b];
  });
  // A chain's cost at a level: the triangles of its frusta (collars, rounded bends, domes
  // and caps included) tessellated with that level's columns.
  const SkinnedSkeleton skinned = skin_skeleton(sk, skin);
  auto chain_triangles = [&](int columns) {
    TessellateOptions options;
    options.segments_around = columns;
    std::vector<double> out(chains, 0);
    const TriangleMesh mesh = tessellate(skinned, options);
    for (uint32_t f : mesh.triangle_frustum) out[skinned.frusta[f].chain] += 1;
    return out;
  };
  const std::vector<double> level0 = chain_triangles(level0_columns);
  double estimate = std::accumulate(level0.begin(), level0.end(), 0.0);
  std::vector<bool> kept(chains, true);
  std::vector<std::vector<bool>> out;
  for (uint32_t k = 1; k <= levels; ++k) {
    const double target = estimate / 4;
    const std::vector<double> cost_of = chain_triangles(lod_columns(level0_columns, k));
    std::vector<bool> next(chains, false);
    double used = 0;
    for (size_t c : by_size) {
      if (!kept[c]) continue;
      const double cost = cost_of[c];
      if (sk.chains[c].parent && used + cost > target) break;  // sizes only fall from here
      next[c] = true;
      used += cost;
    }
    kept = std::move(next);
    out.push_back(kept);
    estimate = used;
  }
  return out;
}

}  // namespace

int lod_columns(int level0_columns, uint32_t level) {
  int columns = level0_columns;
  for (uint32_t k = 0; k < level; ++k) columns = std::max(3, columns / 2);
  return columns;
}

namespace {

// `sk` with only the chains `kept` keeps, and its leaves merged for `level`.
Skeleton coarsened(const Skeleton& sk, uint32_t level, const std::vector<bool>& kept) {
  Skeleton out;
  out.source = sk.source;
  out.chains = sk.chains;
  for (size_t c = 0; c < sk.chains.size(); ++c) {
    const Chain& chain = sk.chains[c];
    const uint32_t count = kept[c] ? chain.joint_count : 1;
    out.chains[c].first_joint = static_cast<uint32_t>(out.joints.size());
    out.chains[c].joint_count = count;
    out.joints.insert(out.joints.end(), sk.joints.begin() + chain.first_joint,
                      sk.joints.begin() + chain.first_joint + count);
  }
  // A dropped chain's child hangs from its first joint, the only one it keeps.
  for (Chain& chain : out.chains)
    if (chain.parent && !kept[chain.parent->chain]) chain.parent->joint = 0;
  // Leaves: groups of 4^level merged into their largest, scaled to the group's area.
  const size_t group = size_t{1} << (2 * std::min<uint32_t>(level, 15));
  for (size_t first = 0; first < sk.leaves.size(); first += group) {
    const size_t last = std::min(sk.leaves.size(), first + group);
    size_t largest = first;
    double total = 0, largest_area = -1;
    for (size_t l = first; l < last; ++l) {
      const double area = leaf_area(sk.leaves[l]);
      total += area;
      if (area > largest_area) largest_area = area, largest = l;
    }
    Leaf leaf = sk.leaves[largest];
    if (largest_area > 0) {
      glm::dvec3 centroid(0);
      for (const auto& v : leaf.vertices_m) centroid += vec(v);
      centroid /= static_cast<double>(leaf.vertices_m.size());
      const double scale = std::sqrt(total / largest_area);
      for (auto& v : leaf.vertices_m) {
        const glm::dvec3 p = centroid + scale * (vec(v) - centroid);
        v = {p.x, p.y, p.z};
      }
    }
    // Up to the kept chain this leaf's branch grows from.
    while (leaf.joint && !kept[leaf.joint->chain]) {
      const Chain& chain = sk.chains[leaf.joint->chain];
      leaf.joint = chain.parent;
    }
    out.leaves.push_back(std::move(leaf));
  }
  return out;
}

}  // namespace

std::vector<Skeleton> lod_skeletons(const Skeleton& sk, uint32_t levels, int level0_columns, const SkinOptions& skin) {
  const std::vector<std::vector<bool>> kept = kept_chains(sk, levels, level0_columns, skin);
  std::vector<Skeleton> out;
  out.reserve(levels);
  for (uint32_t k = 1; k <= levels; ++k) out.push_back(coarsened(sk, k, kept[k - 1]));
  return out;
}

Skeleton lod_skeleton(const Skeleton& sk, uint32_t level, int level0_columns, const SkinOptions& skin) {
  if (level == 0) return coarsened(sk, 0, std::vector<bool>(sk.chains.size(), true));
  return coarsened(sk, level, kept_chains(sk, level, level0_columns, skin).back());
}

std::optional<std::vector<ImpostorCard>> impostor_cards(const Skeleton& sk) {
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const Joint& j : sk.joints) {
    const glm::dvec3 p(j.position_m[0], j.position_m[1], j.position_m[2]);
    lo = glm::min(lo, p - glm::dvec3(j.radius_m));
    hi = glm::max(hi, p + glm::dvec3(j.radius_m));
  }
  for (const Leaf& leaf : sk.leaves)
    for (const auto& v : leaf.vertices_m) lo = glm::min(lo, vec(v)), hi = glm::max(hi, vec(v));
  const glm::dvec3 extent = hi - lo;
  if (!(extent.y > 0) || !(extent.x > 0 || extent.z > 0)) return std::nullopt;
  const glm::dvec3 centre = 0.5 * (lo + hi);
  // Facing +Z the image's right is +X; facing +X it is −Z (a camera on that side, up +Y).
  ImpostorCard front{centre, {0, 0, 1}, {1, 0, 0}, 0.5 * std::max(extent.x, 1e-6), 0.5 * extent.y};
  ImpostorCard side{centre, {1, 0, 0}, {0, 0, -1}, 0.5 * std::max(extent.z, 1e-6), 0.5 * extent.y};
  return std::vector<ImpostorCard>{front, side};
}

}  // namespace sylva
