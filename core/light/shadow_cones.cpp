// shadow_cones.cpp — shadow cones of Hougs and Day 2001 (Hougs & Day 2001): clustering of shadow
// vectors (sec. 3.2.1–3.2.2), ray–cone intervals, sort and merge (sec. 3.3.1), and a
// hierarchy over the cones (sec. 6.2). See shadow_cones.h for the contract.
#include "core/light/shadow_cones.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <memory>
#include <nanoflann.hpp>

#include "core/geometry/relief.h"
#include "core/geometry/skin.h"
#include "core/geometry/solid_bounds.h"
#include "core/util/math.h"
#include "core/util/parallel.h"

namespace sylva {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- Cones -----------------------------------------------------------------------------

[[maybe_unused]] bool cone_usable(const ShadowCone& c) {
  return std::isfinite(c.length_m) && c.length_m > 0 && std::isfinite(c.radius_base_m) &&
         c.radius_base_m >= 0 && std::isfinite(c.tan_theta) &&
         std::abs(glm::dot(c.axis, c.axis) - 1) < 1e-9;
}

}  // namespace

double ShadowCone::end_s() const {
  // A converging cone ends at its apex r(s) = 0 if that comes before length_m (r(s)
  // becomes negative beyond, which is no solid).
  if (tan_theta < 0 && radius_base_m < length_m * -tan_theta) return radius_base_m / -tan_theta;
  return length_m;
}

bool cone_contains(const ShadowCone& cone, const glm::dvec3& point) {
  const glm::dvec3 q = point - cone.base;
  const double s = glm::dot(q, cone.axis);
  if (!(s >= 0 && s <= cone.end_s())) return false;
  const glm::dvec3 perp = q - s * cone.axis;
  const double r = cone.radius_at(s);
  return r >= 0 && glm::dot(perp, perp) <= r * r;
}

FrustumShape cone_local_shape(const ShadowCone& cone) {
  FrustumShape s;
  s.base = {0, 0, 0};
  s.axis = cone.axis;
  s.length = cone.end_s();
  s.radius0 = cone.radius_base_m;
  // At the apex the radius is 0 up to rounding; never below (frustum_solid_interval
  // rejects a negative radius).
  s.radius1 = std::max(0.0, cone.radius_at(s.length));
  s.lower = {cone.axis, 0};
  s.upper = {cone.axis, s.length};
  s.cap_lower = s.cap_upper = false;  // the solid is closed either way
  return s;
}

namespace {

using solid_bounds::Bounds;

}  // namespace

// frustum_solid_interval (relief.cpp's local_solid_interval) specialised to a cone in its
// own frame: planes s = 0 and s = end perpendicular to the axis through the origin, so the
// slab is two linear bounds with exact offsets, and the ray, already moved into the frame
// by a subtraction exact to half an ulp of its result, is re-centred on the midpoint in
// plain double (measured on one core: 160 ns a test against the general function's 270,
// whose compensated re-centring and plane offsets the cone's own frame makes
// unnecessary; cone tests are most of a camera ray's cone query). The same quadric and
// Bounds::inside_cone, whose root choice it takes by the quick test first (nearly every
// ray); same answers to rounding (the stiff matrix, and the tests against
// frustum_solid_interval).
SolidInterval ShadowConeGeometry::interval(const Ray& ray, double t_min, double t_max) const {
  SolidInterval out;
  const glm::dvec3& d = ray.direction;
  const double dd = glm::dot(d, d);
  if (!(dd > 0)) return out;
  const glm::dvec3 from_base = ray.origin - base;
  const double shift = glm::dot((0.5 * end) * axis - from_base, d) / dd;
  const glm::dvec3 o = from_base + shift * d;
  const double oy = glm::dot(o, axis), dy = glm::dot(d, axis);
  Bounds b;
  if (!b.linear_at_least(dy, -oy, SolidBoundary::lower)) return out;         // s >= 0
  if (!b.linear_at_least(-dy, oy - end, SolidBoundary::upper)) return out;   // s <= end
  const double rho = radius0 + slope * oy, slope_dir_y = slope * dy;
  if (!b.linear_at_least(slope_dir_y, -rho, SolidBoundary::side)) return out;  // r(s) >= 0
  const glm::dvec3 origin_perp = o - oy * axis, dir_perp = d - dy * axis;
  if (!b.inside_cone(origin_perp, dir_perp, rho, slope_dir_y, solid_bounds::SecondRoot::quick_then_bounds)) return out;
  if (!std::isfinite(b.lo) || !std::isfinite(b.hi)) return out;
  out.t_enter = shift + b.lo, out.enter = b.lo_by;
  out.t_exit = shift + b.hi, out.exit = b.hi_by;
  if (!(out.t_enter > t_min)) out.t_enter = t_min, out.enter = SolidBoundary::range;
  if (!(out.t_exit < t_max)) out.t_exit = t_max, out.exit = SolidBoundary::range;
  out.hit = out.t_enter <= out.t_exit && std::isfinite(out.t_enter) && std::isfinite(out.t_exit);
  return out;
}

ShadowConeGeometry cone_geometry(const ShadowCone& cone) {
  ShadowConeGeometry g;
  g.base = cone.base;
  g.axis = cone.axis;
  g.end = cone.end_s();
  g.radius0 = cone.radius_base_m;
  // frustum_shape.h's slope from the end radii (0 at an apex, never below).
  g.slope = (std::max(0.0, cone.radius_at(g.end)) - cone.radius_base_m) / g.end;
  return g;
}

SolidInterval shadow_cone_interval(const Ray& ray, const ShadowCone& cone, double t_min,
                                   double t_max) {
  return cone_geometry(cone).interval(ray, t_min, t_max);
}

void sort_and_merge(std::vector<ConeInterval>& intervals) {
  // Few intervals per ray (sec. 3.3.1 found bubble sort good enough); std::sort is an
  // insertion sort below 16 elements anyway.
  std::sort(intervals.begin(), intervals.end(),
            [](const ConeInterval& a, const ConeInterval& b) { return a.t_enter < b.t_enter; });
  size_t kept = 0;
  for (size_t i = 0; i < intervals.size(); ++i) {
    if (kept > 0 && intervals[i].t_enter <= intervals[kept - 1].t_exit) {
      intervals[kept - 1].t_exit = std::max(intervals[kept - 1].t_exit, intervals[i].t_exit);
    } else {
      intervals[kept++] = intervals[i];
    }
  }
  intervals.resize(kept);
}

// ---- The hierarchy ---------------------------------------------------------------------

namespace {

constexpr uint32_t kLeafSize = 4;
constexpr uint32_t kStackSize = 96;     // traversal stack; the build keeps depth below it
constexpr uint32_t kSahDepthLimit = 40; // beyond: median splits (depth <= 40 + 32 + 1)
constexpr int kBins = 16;

struct Box {
  glm::dvec3 lo{kInf, kInf, kInf};
  glm::dvec3 hi{-kInf, -kInf, -kInf};
  void grow(const Box& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  void grow(const glm::dvec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  double half_area() const {
    const glm::dvec3 e = hi - lo;
    if (!(e.x >= 0 && e.y >= 0 && e.z >= 0)) return 0;
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
};

glm::dvec3 to_frame(const glm::dvec3 (&frame)[3], const glm::dvec3& v) {
  return {glm::dot(frame[0], v), glm::dot(frame[1], v), glm::dot(frame[2], v)};
}

// The box of a cone in the frame: the solid is the convex hull of its two end discs (r is
// linear in s), and a disc of radius r with unit normal a reaches r·sqrt(1 − a_i²) along
// axis i. Padded so that rounding (of the frame change, of the cone's own interval)
// cannot put a point of an interval the cone reports outside its box.
Box cone_box(const glm::dvec3 (&frame)[3], const ShadowCone& cone) {
  const glm::dvec3 a = to_frame(frame, cone.axis);
  const double end = cone.end_s();
  const glm::dvec3 c0 = to_frame(frame, cone.base);
  const glm::dvec3 c1 = to_frame(frame, cone.base + end * cone.axis);
  const double r0 = cone.radius_base_m, r1 = std::max(0.0, cone.radius_at(end));
  Box b;
  for (int i = 0; i < 3; ++i) {
    const double reach = std::sqrt(std::max(0.0, 1 - a[i] * a[i]));
    b.lo[i] = std::min(c0[i] - r0 * reach, c1[i] - r1 * reach);
    b.hi[i] = std::max(c0[i] + r0 * reach, c1[i] + r1 * reach);
  }
  const double size = end + std::max(r0, r1);
  const double magnitude = std::max({std::abs(c0.x), std::abs(c0.y), std::abs(c0.z), std::abs(c1.x),
                                     std::abs(c1.y), std::abs(c1.z)});
  const double pad = 1e-7 * size + 1e-12 * magnitude + 1e-300;
  b.lo -= glm::dvec3(pad);
  b.hi += glm::dvec3(pad);
  return b;
}

struct BuildItem {
  Box box;
  glm::dvec3 centroid;
};

class Builder {
 public:
  Builder(const std::vector<BuildItem>& items, std::vector<ConeSet::Node>& nodes,
          std::vector<uint32_t>& order)
      : items_(items), nodes_(nodes), order_(order) {}
  uint32_t depth = 0;

  void build(uint32_t begin, uint32_t end, uint32_t level) {
    const uint32_t index = static_cast<uint32_t>(nodes_.size());
    nodes_.push_back({});
    depth = std::max(depth, level);
    Box box, centroids;
    for (uint32_t i = begin; i < end; ++i) {
      box.grow(items_[order_[i]].box);
      centroids.grow(items_[order_[i]].centroid);
    }
    for (int k = 0; k < 3; ++k) {
      nodes_[index].lo[k] = box.lo[k];
      nodes_[index].hi[k] = box.hi[k];
    }
    const uint32_t n = end - begin;
    uint32_t mid = begin;
    if (n > kLeafSize) mid = level < kSahDepthLimit ? sah_split(begin, end, centroids) : begin;
    if (n > kLeafSize && (mid == begin || mid == end)) mid = median_split(begin, end, centroids);
    if (n <= kLeafSize || mid == begin || mid == end) {
      nodes_[index].first = begin;
      nodes_[index].count = n;
      return;
    }
    build(begin, mid, level + 1);
    nodes_[index].first = static_cast<uint32_t>(nodes_.size());
    nodes_[index].count = 0;
    build(mid, end, level + 1);
  }

 private:
  static int widest(const Box& centroids) {
    const glm::dvec3 e = centroids.hi - centroids.lo;
    return e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
  }

  uint32_t median_split(uint32_t begin, uint32_t end, const Box& centroids) {
    const int axis = widest(centroids);
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](uint32_t a, uint32_t b) {
                       const double ca = items_[a].centroid[axis], cb = items_[b].centroid[axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    return mid;
  }

  // Binned SAH (Wald 2007): 16 centroid bins along the widest axis, the cheapest of the
  // 15 bin boundaries; `begin` when the centroids do not spread (the caller then splits
  // at the median).
  uint32_t sah_split(uint32_t begin, uint32_t end, const Box& centroids) {
    const int axis = widest(centroids);
    const double lo = centroids.lo[axis], extent = centroids.hi[axis] - lo;
    if (!(extent > 0)) return begin;
    std::array<Box, kBins> bins;
    std::array<uint32_t, kBins> counts{};
    auto bin_of = [&](uint32_t item) {
      const int b = static_cast<int>((items_[item].centroid[axis] - lo) / extent * kBins);
      return std::clamp(b, 0, kBins - 1);
    };
    for (uint32_t i = begin; i < end; ++i) {
      const int b = bin_of(order_[i]);
      bins[b].grow(items_[order_[i]].box);
      ++counts[b];
    }
    std::array<double, kBins> left_cost{};
    Box acc;
    uint32_t acc_n = 0;
    for (int b = 0; b < kBins - 1; ++b) {
      acc.grow(bins[b]);
      acc_n += counts[b];
      left_cost[b] = acc.half_area() * acc_n;
    }
    double best = kInf;
    int best_b = -1;
    acc = Box{};
    acc_n = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.grow(bins[b]);
      acc_n += counts[b];
      const double cost = left_cost[b - 1] + acc.half_area() * acc_n;
      if (cost < best) best = cost, best_b = b;
    }
    if (best_b < 0) return begin;
    const auto middle = std::partition(order_.begin() + begin, order_.begin() + end,
                                       [&](uint32_t item) { return bin_of(item) < best_b; });
    return static_cast<uint32_t>(middle - order_.begin());
  }

  const std::vector<BuildItem>& items_;
  std::vector<ConeSet::Node>& nodes_;
  std::vector<uint32_t>& order_;
};

// The ray against a node's box, in the frame; t in [t_min, t_max].
struct FrameRay {
  glm::dvec3 origin, direction, inverse;
};

bool crosses(const ConeSet::Node& node, const FrameRay& r, double t_min, double t_max) {
  double near = t_min, far = t_max;
  for (int i = 0; i < 3; ++i) {
    if (r.direction[i] == 0) {
      if (r.origin[i] < node.lo[i] || r.origin[i] > node.hi[i]) return false;
      continue;
    }
    double t0 = (node.lo[i] - r.origin[i]) * r.inverse[i];
    double t1 = (node.hi[i] - r.origin[i]) * r.inverse[i];
    if (t0 > t1) std::swap(t0, t1);
    near = std::max(near, t0);
    far = std::min(far, t1);
    if (!(near <= far)) return false;
  }
  return true;
}

bool inside(const ConeSet::Node& node, const glm::dvec3& p) {
  for (int i = 0; i < 3; ++i)
    if (!(p[i] >= node.lo[i] && p[i] <= node.hi[i])) return false;
  return true;
}

}  // namespace

ConeSet::ConeSet(std::vector<ShadowCone> cones) : cones_(std::move(cones)) {
  if (cones_.empty()) return;
  glm::dvec3 mean{0, 0, 0};
  for (const ShadowCone& c : cones_) {
    assert(cone_usable(c) && "ConeSet: a cone needs a unit axis, radius >= 0, 0 < length < inf");
    mean += c.axis;
  }
  const glm::dvec3 axis = glm::length(mean) > 1e-6 ? glm::normalize(mean) : glm::dvec3(0, 1, 0);
  const AxisFrame f = axis_frame(axis);
  frame_[0] = f.e0, frame_[1] = f.e1, frame_[2] = axis;

  local_.reserve(cones_.size());
  std::vector<BuildItem> items(cones_.size());
  for (size_t i = 0; i < cones_.size(); ++i) {
    local_.push_back(cone_geometry(cones_[i]));
    items[i].box = cone_box(frame_, cones_[i]);
    items[i].centroid = 0.5 * (items[i].box.lo + items[i].box.hi);
  }
  order_.resize(cones_.size());
  for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  nodes_.reserve(2 * cones_.size() / kLeafSize + 1);
  Builder builder(items, nodes_, order_);
  builder.build(0, static_cast<uint32_t>(cones_.size()), 1);
  depth_ = builder.depth;
  assert(depth_ < kStackSize);
}

void ConeSet::collect(const Ray& ray, double t_min, double t_max, uint32_t cone,
                      std::vector<ConeInterval>* out) const {
  const SolidInterval iv = local_[cone].interval(ray, t_min, t_max);
  if (iv.hit && iv.t_exit > iv.t_enter) out->push_back({iv.t_enter, iv.t_exit});
}

void ConeSet::intervals(const Ray& ray, double t_min, double t_max,
                        std::vector<ConeInterval>* out) const {
  out->clear();
  if (nodes_.empty() || !(t_min <= t_max)) return;
  FrameRay r;
  r.origin = to_frame(frame_, ray.origin);
  r.direction = to_frame(frame_, ray.direction);
  for (int i = 0; i < 3; ++i) r.inverse[i] = r.direction[i] != 0 ? 1 / r.direction[i] : 0;
  uint32_t stack[kStackSize];
  uint32_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t index = stack[--top];
    const Node& node = nodes_[index];
    if (!crosses(node, r, t_min, t_max)) continue;
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) collect(ray, t_min, t_max, order_[i], out);
    } else {
      stack[top++] = node.first;
      stack[top++] = index + 1;
    }
  }
  sort_and_merge(*out);
}

void ConeSet::intervals_brute_force(const Ray& ray, double t_min, double t_max,
                                    std::vector<ConeInterval>* out) const {
  out->clear();
  if (!(t_min <= t_max)) return;
  for (uint32_t i = 0; i < cones_.size(); ++i) collect(ray, t_min, t_max, i, out);
  sort_and_merge(*out);
}

bool ConeSet::contains(const glm::dvec3& point) const {
  if (nodes_.empty()) return false;
  const glm::dvec3 p = to_frame(frame_, point);
  uint32_t stack[kStackSize];
  uint32_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t index = stack[--top];
    const Node& node = nodes_[index];
    if (!inside(node, p)) continue;
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i)
        if (cone_contains(cones_[order_[i]], point)) return true;
    } else {
      stack[top++] = node.first;
      stack[top++] = index + 1;
    }
  }
  return false;
}

size_t ConeSet::memory_bytes() const {
  return cones_.capacity() * sizeof(ShadowCone) + local_.capacity() * sizeof(ShadowConeGeometry) +
         nodes_.capacity() * sizeof(Node) + order_.capacity() * sizeof(uint32_t);
}

// ---- Clustering (sec. 3.2) -------------------------------------------------------------

const char* cone_params_error(const ConeParams& p) {
  if (p.p2 < 2) return "p2 (angular sectors) must be at least 2";
  if (p.p3 < 1) return "p3 (vectors per ring) must be at least 1";
  if (p.p1 < p.p3 + 1) return "p1 (nearest neighbours) must be at least p3 + 1 (one ring and the seed)";
  if (p.p4 < 1) return "p4 (least vectors per cone) must be at least 1";
  if (!(p.variance_threshold > 0) || !std::isfinite(p.variance_threshold))
    return "the variance threshold must be a positive number";
  return nullptr;
}

namespace {

// One plant's vectors as nanoflann's dataset: a compact copy of their positions.
struct PointCloud {
  std::vector<std::array<float, 3>> points;
  size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(size_t i, size_t dim) const { return points[i][dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointCloud>,
                                                   PointCloud, 3, uint32_t>;

// The unit eigenvector of the smallest eigenvalue of a symmetric 3×3 matrix (cyclic
// Jacobi): the least principal axis of a point set, its estimated surface normal.
glm::dvec3 least_principal_axis(double m[3][3]) {
  double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int sweep = 0; sweep < 32; ++sweep) {
    const double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    const double diag = m[0][0] * m[0][0] + m[1][1] * m[1][1] + m[2][2] * m[2][2];
    if (!(off > 1e-30 * diag)) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (m[p][q] == 0) continue;
        const double theta = (m[q][q] - m[p][p]) / (2 * m[p][q]);
        const double t = std::copysign(1.0, theta) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // m ← m·J
          const double a = m[k][p], b = m[k][q];
          m[k][p] = c * a - s * b;
          m[k][q] = s * a + c * b;
        }
        for (int k = 0; k < 3; ++k) {  // m ← Jᵀ·m
          const double a = m[p][k], b = m[q][k];
          m[p][k] = c * a - s * b;
          m[q][k] = s * a + c * b;
        }
        for (int k = 0; k < 3; ++k) {  // v ← v·J
          const double a = v[k][p], b = v[k][q];
          v[k][p] = c * a - s * b;
          v[k][q] = s * a + c * b;
        }
      }
  }
  int least = 0;
  for (int i = 1; i < 3; ++i)
    if (m[i][i] < m[least][least]) least = i;
  return glm::normalize(glm::dvec3(v[0][least], v[1][least], v[2][least]));
}

glm::dvec3 to_d(const glm::vec3& v) { return {v.x, v.y, v.z}; }

// A seed's cone as the vectors make it, whatever earlier cones took (step 5 before the
// p4 test): a pure function of the seed, so the seeds of a block can be proposed in
// parallel and accepted in order with the very result of the sequential loop.
struct Proposal {
  bool possible = false;       // rings passed, a usable radius and axis
  ShadowCone cone;             // all but `vectors`
  std::vector<uint32_t> disc;  // the candidates within the radius (plant-local indices)
};

// What a thread reuses from seed to seed.
struct Scratch {
  std::vector<uint32_t> neighbours, k, counts;
  std::vector<float> dists;
  std::vector<double> k_dist;
};

}  // namespace

// One plant's vectors: their positions in a kd-tree, and optionally everyone's nearest
// neighbours found once. Local indices follow a Morton order of the positions (a seed's
// neighbours sit together in memory: the kd-tree and the sector tests read them), and
// `in_order` lists them in the vectors' order, the order seeds are taken in.
struct ShadowVectorIndex::Plant {
  uint32_t plant = 0;
  std::vector<uint32_t> members;   // local → index into vectors
  std::vector<uint32_t> in_order;  // the vectors' order → local
  PointCloud cloud;                // local → position
  std::vector<glm::vec3> direction;
  std::unique_ptr<KdTree> tree;
  uint32_t table_p1 = 0;          // > 0: table[i·table_p1 ..] holds i's nearest
  std::vector<uint32_t> table;    // local indices, nearest first (i itself among them),
  std::vector<float> table_dist;  // squared distances
  std::vector<uint32_t> table_count;
};

namespace {

// Runs body(thread, begin, end) over [0, n) split into `threads` (>= 1) contiguous
// ranges, fewer for a small n (at most n/64 + 1): a thread is worth its start-up only
// for a few dozen items.
template <class Body>
void parallel_ranges(size_t n, unsigned threads, Body&& body) {
  threads = static_cast<unsigned>(std::max<size_t>(1, std::min<size_t>(threads, n / 64 + 1)));
  run_on_workers(threads, [&](unsigned t) { body(t, n * t / threads, n * (t + 1) / threads); });
}

// atan2 within 1e-5 rad (a minimax polynomial on one octant): the angular sector of a
// vector needs no more, and the library's atan2 was a tenth of the clustering's time.
double sector_atan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double big = std::max(ax, ay);
  if (!(big > 0)) return 0;
  const double a = std::min(ax, ay) / big, s = a * a;
  double r = ((-0.0464964749 * s + 0.15931422) * s - 0.327622764) * s * a + a;
  if (ay > ax) r = 0.5 * kPi - r;
  if (x < 0) r = kPi - r;
  return y < 0 ? -r : r;
}

// Steps 1–5 for `seed` of `plant` (see shadow_cones.h).
void propose(const ShadowVectors& all, const ShadowVectorIndex::Plant& plant, uint32_t seed, const ConeParams& p,
             const ConeLimits& limits, Scratch& w, Proposal& out) {
  out.possible = false;
  out.disc.clear();
  struct LocalVector {
    glm::vec3 position, direction;
  };
  auto vec = [&](uint32_t local) {
    const std::array<float, 3>& q = plant.cloud.points[local];
    return LocalVector{{q[0], q[1], q[2]}, plant.direction[local]};
  };
  const glm::vec3 sp = vec(seed).position;
  // Step 1: K, in order of distance, the seed first (a vector at the seed's very
  // position may come before it).
  // K is gathered in two stages: the seed's first ring (p3 + 1 neighbours, where most
  // seeds among thin twigs already fail), then, only if that ring passes, all p1.
  auto gather = [&](uint32_t count) {
    const uint32_t* found_index;
    const float* found_dist;
    uint32_t found;
    if (plant.table_p1 >= count) {
      found_index = &plant.table[size_t(seed) * plant.table_p1];
      found_dist = &plant.table_dist[size_t(seed) * plant.table_p1];
      found = std::min(plant.table_count[seed], count);
    } else {
      w.neighbours.resize(count);
      w.dists.resize(count);
      const float query[3] = {sp.x, sp.y, sp.z};
      found = static_cast<uint32_t>(plant.tree->knnSearch(query, count, w.neighbours.data(), w.dists.data()));
      found_index = w.neighbours.data();
      found_dist = w.dists.data();
    }
    w.k.clear();
    w.k_dist.clear();
    w.k.push_back(seed);
    w.k_dist.push_back(0);
    for (uint32_t i = 0; i < found && w.k.size() < count; ++i) {
      if (found_index[i] == seed) continue;
      w.k.push_back(found_index[i]);
      w.k_dist.push_back(std::sqrt(double(found_dist[i])));
    }
  };
  const uint32_t first = std::min(p.p1, p.p3 + 1);
  gather(first);
  if (w.k.size() < p.p3 + 1) return;  // not even one ring

  // Step 2: the plane perpendicular to the mean direction (of the seed and its first
  // ring: sunlight's directions differ by the sun's radius, so which vectors it averages
  // moves the plane by less than that), and each vector's sector in it.
  glm::dvec3 mean{0, 0, 0};
  for (uint32_t v : w.k) mean += to_d(vec(v).direction);
  if (!(glm::length(mean) > 0)) return;
  mean = glm::normalize(mean);
  const AxisFrame plane = axis_frame(mean);
  const glm::dvec3 seed_p = to_d(sp);

  // Steps 3–4: rings of p3 vectors, the index of dispersion of their sector counts.
  w.counts.assign(p.p2, 0);
  const double expected = double(p.p3) / p.p2;
  uint32_t passed = 0, rings = 1;
  for (uint32_t ring = 1; ring <= rings; ++ring) {
    if (ring == 2) {
      gather(p.p1);  // the first ring passed: the rest of K
      rings = static_cast<uint32_t>((w.k.size() - 1) / p.p3);
      if (rings < 2) break;
    }
    std::fill(w.counts.begin(), w.counts.end(), 0u);
    for (uint32_t i = (ring - 1) * p.p3 + 1; i <= ring * p.p3; ++i) {
      const glm::dvec3 q = to_d(vec(w.k[i]).position) - seed_p;
      const double angle = sector_atan2(glm::dot(q, plane.e1), glm::dot(q, plane.e0));  // [-π, π]
      const int sector = std::clamp(int((angle + kPi) / (2 * kPi) * p.p2), 0, int(p.p2) - 1);
      ++w.counts[sector];
    }
    double variance = 0;
    for (uint32_t c : w.counts) variance += (c - expected) * (c - expected);
    variance /= p.p2;
    if (variance / expected > p.variance_threshold) break;
    passed = ring;
    if (ring == 1 && p.p1 > first) rings = 2;  // go on to gather the rest
  }
  if (passed == 0) return;
  const uint32_t candidates = passed * p.p3 + 1;
  if (candidates < p.p4) return;  // too few even if none were taken
  const double r = w.k_dist[candidates - 1];

  // Step 5: axis (eq. 3), expansion (the smallest dot product, as tan), normal, radius.
  glm::dvec3 axis{0, 0, 0};
  for (uint32_t i = 0; i < candidates; ++i) axis += to_d(vec(w.k[i]).direction);
  if (!(glm::length(axis) > 0)) return;
  axis = glm::normalize(axis);
  double tan_theta = 0;
  for (uint32_t i = 0; i < candidates; ++i) {
    const glm::dvec3 d = to_d(vec(w.k[i]).direction);
    const double along = glm::dot(d, axis);
    if (!(along > 0)) return;  // a vector at 90° or more from the axis: no cone
    tan_theta = std::max(tan_theta, glm::length(glm::cross(d, axis)) / along);
  }
  glm::dvec3 centroid{0, 0, 0};
  for (uint32_t i = 0; i < candidates; ++i) centroid += to_d(vec(w.k[i]).position);
  centroid /= double(candidates);
  double cov[3][3] = {};
  for (uint32_t i = 0; i < candidates; ++i) {
    const glm::dvec3 q = to_d(vec(w.k[i]).position) - centroid;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) cov[a][b] += q[a] * q[b];
  }
  const glm::dvec3 normal = least_principal_axis(cov);
  const double radius = r * std::abs(glm::dot(normal, axis));  // Fig. 5

  // The cone holds the candidates within the radius of the axis line through the seed.
  // A hair of margin keeps them inside after rounding (world position, base).
  const double margin = 1e-9 * r + 1e-13 * (glm::length(all.origin) + glm::length(seed_p));
  if (!(radius > 2 * margin)) return;
  double s_min = 0, s_max = 0;
  for (uint32_t i = 0; i < candidates; ++i) {
    const glm::dvec3 q = to_d(vec(w.k[i]).position) - seed_p;
    const double s = glm::dot(q, axis);
    const glm::dvec3 perp = q - s * axis;
    if (glm::dot(perp, perp) > (radius - margin) * (radius - margin) && i > 0) continue;
    s_min = std::min(s_min, s);
    s_max = std::max(s_max, s);
    out.disc.push_back(w.k[i]);
  }
  if (out.disc.size() < p.p4) return;
  s_min -= margin;
  s_max += margin;

  ShadowCone& cone = out.cone;
  cone.base = all.origin + seed_p + s_min * axis;
  cone.axis = axis;
  cone.radius_base_m = radius;
  cone.tan_theta = tan_theta;
  cone.plant = plant.plant;
  double length = limits.max_length_m;
  if (limits.ground && axis.y < 0) {
    // The whole cross-section below the ground: its highest point, base.y + s·a_y +
    // r(s)·sqrt(1 − a_y²), at or below ground_height.
    const double horizontal = std::sqrt(std::max(0.0, 1 - axis.y * axis.y));
    const double descent = -axis.y - tan_theta * horizontal;
    if (descent > 0) {
      const double s_ground = (cone.base.y - limits.ground_height + radius * horizontal) / descent;
      length = std::min(length, s_ground);
    }
  }
  cone.length_m = std::max(length, s_max - s_min);
  out.possible = true;
}

constexpr uint32_t kBlock = 4096;  // seeds proposed in parallel, then accepted in order

}  // namespace

ShadowVectorIndex::ShadowVectorIndex(const ShadowVectors& vectors, std::span<const uint32_t> plant_of_frustum,
                                     uint32_t neighbours_p1, unsigned threads)
    : vectors_(vectors) {
  if (vectors.vectors.empty()) return;
  std::vector<uint32_t> order(vectors.vectors.size());
  for (uint32_t i = 0; i < order.size(); ++i) {
    assert(vectors.vectors[i].frustum < plant_of_frustum.size());
    order[i] = i;
  }
  auto plant_of = [&](uint32_t v) { return plant_of_frustum[vectors.vectors[v].frustum]; };
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return plant_of(a) < plant_of(b); });
  for (size_t begin = 0; begin < order.size();) {
    size_t end = begin;
    while (end < order.size() && plant_of(order[end]) == plant_of(order[begin])) ++end;
    auto plant = std::make_unique<Plant>();
    plant->plant = plant_of(order[begin]);
    // Morton order of the positions (10 bits per axis over the plant's box).
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (size_t k = begin; k < end; ++k) {
      lo = glm::min(lo, vectors.vectors[order[k]].position);
      hi = glm::max(hi, vectors.vectors[order[k]].position);
    }
    const glm::vec3 scale = 1023.0f / glm::max(hi - lo, glm::vec3(1e-30f));
    auto spread = [](uint32_t x) {  // 10 bits → every third bit
      x = (x | (x << 16)) & 0x030000FF;
      x = (x | (x << 8)) & 0x0300F00F;
      x = (x | (x << 4)) & 0x030C30C3;
      return (x | (x << 2)) & 0x09249249;
    };
    std::vector<std::pair<uint32_t, uint32_t>> morton(end - begin);  // (code, rank in order)
    for (size_t k = begin; k < end; ++k) {
      const glm::vec3 c = glm::clamp((vectors.vectors[order[k]].position - lo) * scale, 0.0f, 1023.0f);
      morton[k - begin] = {spread(uint32_t(c.x)) | spread(uint32_t(c.y)) << 1 | spread(uint32_t(c.z)) << 2,
                           static_cast<uint32_t>(k - begin)};
    }
    std::sort(morton.begin(), morton.end());
    const size_t n = end - begin;
    plant->members.resize(n);
    plant->in_order.resize(n);
    plant->cloud.points.resize(n);
    plant->direction.resize(n);
    for (uint32_t local = 0; local < n; ++local) {
      const uint32_t rank = morton[local].second;
      const ShadowVector& v = vectors.vectors[order[begin + rank]];
      plant->members[local] = order[begin + rank];
      plant->in_order[rank] = local;
      plant->cloud.points[local] = {v.position.x, v.position.y, v.position.z};
      plant->direction[local] = v.direction;
    }
    plant->tree = std::make_unique<KdTree>(3, plant->cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    if (neighbours_p1 > 0) {
      Plant& pl = *plant;
      pl.table_p1 = neighbours_p1;
      pl.table.resize(n * neighbours_p1);
      pl.table_dist.resize(n * neighbours_p1);
      pl.table_count.resize(n);
      parallel_ranges(n, worker_count(threads), [&](unsigned, size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) {
          const std::array<float, 3>& q = pl.cloud.points[i];
          pl.table_count[i] = static_cast<uint32_t>(
              pl.tree->knnSearch(q.data(), neighbours_p1, &pl.table[i * neighbours_p1], &pl.table_dist[i * neighbours_p1]));
        }
      });
    }
    plants_.push_back(std::move(plant));
    begin = end;
  }
}

ShadowVectorIndex::~ShadowVectorIndex() = default;

std::vector<ShadowCone> ShadowVectorIndex::cluster(const ConeParams& params, const ConeLimits& limits,
                                                   ClusterReport* report, std::vector<uint32_t>* cone_of_vector,
                                                   unsigned threads) const {
  assert(cone_params_error(params) == nullptr && "cluster: invalid ConeParams");
  assert(limits.max_length_m > 0 && std::isfinite(limits.max_length_m));
  ClusterReport local_report;
  ClusterReport& rep = report ? *report : local_report;
  rep = {};
  rep.vectors = vectors_.vectors.size();
  if (cone_of_vector) cone_of_vector->assign(vectors_.vectors.size(), kNoCone);
  std::vector<ShadowCone> cones;
  const unsigned workers = worker_count(threads);
  std::vector<Scratch> scratch(workers);
  std::vector<Proposal> proposals;
  std::vector<uint32_t> seeds;
  for (const auto& plant_ptr : plants_) {
    const Plant& plant = *plant_ptr;
    ++rep.plants;
    const uint32_t n = static_cast<uint32_t>(plant.members.size());
    std::vector<uint8_t> removed(n, 0);
    for (uint32_t block = 0; block < n; block += kBlock) {
      seeds.clear();
      for (uint32_t k = block; k < std::min(n, block + kBlock); ++k)
        if (!removed[plant.in_order[k]]) seeds.push_back(plant.in_order[k]);
      if (proposals.size() < seeds.size()) proposals.resize(seeds.size());
      parallel_ranges(seeds.size(), workers, [&](unsigned t, size_t b, size_t e) {
        for (size_t k = b; k < e; ++k) propose(vectors_, plant, seeds[k], params, limits, scratch[t], proposals[k]);
      });
      // In order: a seed an earlier cone (of this block too) took is no seed.
      for (size_t k = 0; k < seeds.size(); ++k) {
        if (removed[seeds[k]]) continue;
        ++rep.seeds;
        const Proposal& prop = proposals[k];
        if (!prop.possible) continue;
        uint32_t fresh = 0;
        for (uint32_t v : prop.disc) fresh += !removed[v];
        if (fresh < params.p4) continue;
        ShadowCone cone = prop.cone;
        cone.vectors = fresh;
        const uint32_t index = static_cast<uint32_t>(cones.size());
        cones.push_back(cone);
        ++rep.cones;
        for (uint32_t v : prop.disc) {
          if (removed[v]) continue;
          removed[v] = 1;
          if (cone_of_vector) (*cone_of_vector)[plant.members[v]] = index;
        }
      }
    }
    for (uint8_t r : removed) {
      if (r) ++rep.covered;
      else ++rep.discarded;
    }
  }
  return cones;
}

std::vector<ShadowCone> cluster_shadow_cones(const ShadowVectors& vectors, std::span<const uint32_t> plant_of_frustum,
                                             const ConeParams& params, const ConeLimits& limits, ClusterReport* report,
                                             std::vector<uint32_t>* cone_of_vector, unsigned threads) {
  return ShadowVectorIndex(vectors, plant_of_frustum, 0, threads).cluster(params, limits, report, cone_of_vector, threads);
}

}  // namespace sylva
