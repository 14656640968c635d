// bvh.cpp — binned SAH BVH over frusta (Wald 2007, "On fast construction of SAH-based
// bounding volume hierarchies", sec. 3: centroid binning, sweep of the bin boundaries).
#include "core/cpu/bvh.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <glm/common.hpp>
#include <limits>

namespace sylva {

namespace {

constexpr int kBins = 16;
constexpr double kTraversalCost = 1.0;     // relative to one ray-frustum test
constexpr double kIntersectionCost = 1.0;  // (the SAH only needs their ratio)

double half_area(const Aabb& box) {
  glm::dvec3 e = box.hi - box.lo;
  if (e.x < 0 || e.y < 0 || e.z < 0) return 0;
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

// Float bounds that contain the double ones.
float round_down(double v) {
  float f = static_cast<float>(v);
  return static_cast<double>(f) > v ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float round_up(double v) {
  float f = static_cast<float>(v);
  return static_cast<double>(f) < v ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

struct BuildItem {
  Aabb box;
  glm::dvec3 centroid;
};

class Builder {
 public:
  Builder(std::vector<BuildItem>& items, Bvh& bvh) : items_(items), bvh_(bvh) {}

  void build(uint32_t begin, uint32_t end, uint32_t depth) {
    const uint32_t node_index = static_cast<uint32_t>(bvh_.nodes.size());
    bvh_.nodes.push_back({});
    bvh_.depth = std::max(bvh_.depth, depth);
    Aabb box = empty_box(), centroids = empty_box();
    for (uint32_t i = begin; i < end; ++i) {
      grow(box, items_[bvh_.order[i]].box);
      grow(centroids, items_[bvh_.order[i]].centroid);
    }
    set_box(node_index, box);
    const uint32_t n = end - begin;
    // Depth cap: the traversal stack holds one entry per level.
    if (n <= 1 || depth + 2 >= kBvhStackSize) return make_leaf(node_index, begin, n);

    uint32_t mid = split(begin, end, box, centroids);
    if (mid == begin || mid == end) return make_leaf(node_index, begin, n);
    build(begin, mid, depth + 1);
    bvh_.nodes[node_index].right_or_first = static_cast<uint32_t>(bvh_.nodes.size());
    bvh_.nodes[node_index].count = 0;
    build(mid, end, depth + 1);
  }

 private:
  void set_box(uint32_t node, const Aabb& box) {
    for (int k = 0; k < 3; ++k) {
      bvh_.nodes[node].lo[k] = round_down(box.lo[k]);
      bvh_.nodes[node].hi[k] = round_up(box.hi[k]);
    }
  }

  void make_leaf(uint32_t node, uint32_t begin, uint32_t n) {
    bvh_.nodes[node].right_or_first = begin;
    bvh_.nodes[node].count = n;
  }

  // Returns the split position in order[begin, end), or begin/end for "make a leaf".
  uint32_t split(uint32_t begin, uint32_t end, const Aabb& box, const Aabb& centroids) {
    const uint32_t n = end - begin;
    glm::dvec3 extent = centroids.hi - centroids.lo;
    int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    auto* order = bvh_.order.data();
    if (!(extent[axis] > 0)) {
      // All centroids coincide: SAH cannot separate them; halve by index if too many.
      return n <= kBvhMaxLeafSize ? begin : begin + n / 2;
    }
    const double lo = centroids.lo[axis];
    const double scale = kBins / extent[axis];
    auto bin_of = [&](uint32_t item) {
      int b = static_cast<int>((items_[item].centroid[axis] - lo) * scale);
      return std::clamp(b, 0, kBins - 1);
    };
    std::array<Aabb, kBins> bin_box;
    std::array<uint32_t, kBins> bin_count{};
    bin_box.fill(empty_box());
    for (uint32_t i = begin; i < end; ++i) {
      int b = bin_of(order[i]);
      grow(bin_box[b], items_[order[i]].box);
      ++bin_count[b];
    }
    // Sweep: area and count of everything right of each boundary.
    std::array<double, kBins> right_area{};
    std::array<uint32_t, kBins> right_count{};
    Aabb acc = empty_box();
    uint32_t count = 0;
    for (int b = kBins - 1; b > 0; --b) {
      grow(acc, bin_box[b]);
      count += bin_count[b];
      right_area[b] = half_area(acc);
      right_count[b] = count;
    }
    acc = empty_box();
    count = 0;
    double best_cost = std::numeric_limits<double>::infinity();
    int best_boundary = -1;
    for (int b = 1; b < kBins; ++b) {
      grow(acc, bin_box[b - 1]);
      count += bin_count[b - 1];
      if (count == 0 || right_count[b] == 0) continue;
      double cost = half_area(acc) * count + right_area[b] * right_count[b];
      if (cost < best_cost) best_cost = cost, best_boundary = b;
    }
    const double parent_area = half_area(box);
    const double split_cost =
        kTraversalCost + kIntersectionCost * (parent_area > 0 ? best_cost / parent_area : n);
    const double leaf_cost = kIntersectionCost * n;
    if (best_boundary < 0) return n <= kBvhMaxLeafSize ? begin : begin + n / 2;
    if (n <= kBvhMaxLeafSize && leaf_cost <= split_cost) return begin;
    auto middle = std::partition(order + begin, order + end,
                                 [&](uint32_t item) { return bin_of(item) < best_boundary; });
    return static_cast<uint32_t>(middle - order);
  }

  std::vector<BuildItem>& items_;
  Bvh& bvh_;
};

// A ray prepared for slab tests: 1/direction, and which axes have direction 0 (tested
// as "origin inside the slab" instead of multiplying 0 by infinity).
struct SlabRay {
  glm::dvec3 origin;
  glm::dvec3 inv_direction;
  bool zero[3];
};

SlabRay prepare(const Ray& ray) {
  SlabRay s;
  s.origin = ray.origin;
  for (int k = 0; k < 3; ++k) {
    s.zero[k] = ray.direction[k] == 0;
    s.inv_direction[k] = s.zero[k] ? 0 : 1.0 / ray.direction[k];
  }
  return s;
}

// Entry parameter of the ray into the node's box within [t_min, t_max], or +inf on a miss.
double slab_entry(const SlabRay& ray, const BvhNode& node, double t_min, double t_max) {
  double t0 = t_min, t1 = t_max;
  for (int k = 0; k < 3; ++k) {
    const double lo = node.lo[k], hi = node.hi[k];
    if (ray.zero[k]) {
      if (ray.origin[k] < lo || ray.origin[k] > hi) return std::numeric_limits<double>::infinity();
      continue;
    }
    double a = (lo - ray.origin[k]) * ray.inv_direction[k];
    double b = (hi - ray.origin[k]) * ray.inv_direction[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  // Slab products are rounded; allow the interval a few ulps of slack so a hit exactly on
  // a face is never culled.
  const double slack = 1e-12 * (std::abs(t1) + std::abs(t0)) + 1e-300;
  return t0 <= t1 + slack ? t0 : std::numeric_limits<double>::infinity();
}

template <bool kAnyHit>
BvhHit traverse(const Bvh& bvh, std::span<const Frustum> frusta, const Ray& ray, double t_min,
                double t_max) {
  BvhHit best;
  if (bvh.nodes.empty()) return best;
  const SlabRay slab = prepare(ray);
  if (slab_entry(slab, bvh.nodes[0], t_min, t_max) == std::numeric_limits<double>::infinity())
    return best;
  uint32_t stack[kBvhStackSize];
  uint32_t top = 0;
  uint32_t node_index = 0;
  double t_best = t_max;
  for (;;) {
    const BvhNode& node = bvh.nodes[node_index];
    if (node.count > 0) {
      for (uint32_t i = node.right_or_first; i < node.right_or_first + node.count; ++i) {
        const uint32_t f = bvh.order[i];
        FrustumHit h = intersect_frustum(ray, frusta[f].shape, t_min, t_best);
        if (h.hit() && h.t < t_best) {
          t_best = h.t;
          best.hit = h;
          best.frustum = f;
          if constexpr (kAnyHit) return best;
        }
      }
    } else {
      const uint32_t left = node_index + 1, right = node.right_or_first;
      double t_left = slab_entry(slab, bvh.nodes[left], t_min, t_best);
      double t_right = slab_entry(slab, bvh.nodes[right], t_min, t_best);
      const double inf = std::numeric_limits<double>::infinity();
      if (t_left != inf && t_right != inf) {
        // Nearer child first; the farther waits on the stack.
        if (t_right < t_left) {
          assert(top < kBvhStackSize);
          stack[top++] = left;
          node_index = right;
        } else {
          assert(top < kBvhStackSize);
          stack[top++] = right;
          node_index = left;
        }
        continue;
      }
      if (t_left != inf) { node_index = left; continue; }
      if (t_right != inf) { node_index = right; continue; }
    }
    // Pop the next node that can still hold a nearer hit.
    for (;;) {
      if (top == 0) return best;
      node_index = stack[--top];
      if (kAnyHit || slab_entry(slab, bvh.nodes[node_index], t_min, t_best) !=
                         std::numeric_limits<double>::infinity())
        break;
    }
  }
}

}  // namespace

Aabb frustum_bounds(const FrustumShape& shape) {
  BoundingPyramid pyramid = bounding_pyramid(shape);
  Aabb box = empty_box();
  for (const glm::dvec3& v : pyramid.vertices) grow(box, v);
  // Caps and knuckles lie inside the pyramid too; the pad covers rounding in its vertices.
  glm::dvec3 extent = box.hi - box.lo;
  double scale = std::max({extent.x, extent.y, extent.z});
  double magnitude = std::max({std::abs(box.lo.x), std::abs(box.lo.y), std::abs(box.lo.z),
                               std::abs(box.hi.x), std::abs(box.hi.y), std::abs(box.hi.z)});
  double pad = 1e-7 * scale + 1e-12 * magnitude;
  box.lo -= glm::dvec3(pad);
  box.hi += glm::dvec3(pad);
  return box;
}

Bvh build_bvh(std::span<const Frustum> frusta) {
  Bvh bvh;
  if (frusta.empty()) return bvh;
  std::vector<BuildItem> items(frusta.size());
  for (size_t i = 0; i < frusta.size(); ++i) {
    items[i].box = frustum_bounds(frusta[i].shape);
    items[i].centroid = 0.5 * (items[i].box.lo + items[i].box.hi);
  }
  bvh.order.resize(frusta.size());
  for (size_t i = 0; i < frusta.size(); ++i) bvh.order[i] = static_cast<uint32_t>(i);
  bvh.nodes.reserve(2 * frusta.size());
  Builder(items, bvh).build(0, static_cast<uint32_t>(frusta.size()), 1);
  return bvh;
}

BvhHit intersect_nearest(const Bvh& bvh, std::span<const Frustum> frusta, const Ray& ray,
                         double t_min, double t_max) {
  return traverse<false>(bvh, frusta, ray, t_min, t_max);
}

bool intersect_any(const Bvh& bvh, std::span<const Frustum> frusta, const Ray& ray,
                   double t_min, double t_max) {
  return traverse<true>(bvh, frusta, ray, t_min, t_max).hit_any();
}

}  // namespace sylva
