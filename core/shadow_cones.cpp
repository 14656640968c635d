// shadow_cones.cpp — shadow cones of paper 002 (Hougs & Day 2001): clustering of shadow
// vectors (sec. 3.2.1–3.2.2), ray–cone intervals, sort and merge (sec. 3.3.1), and a
// hierarchy over the cones (sec. 6.2). See shadow_cones.h for the contract.
#include "core/shadow_cones.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <glm/geometric.hpp>
#include <memory>
#include <nanoflann.hpp>

#include "core/relief.h"
#include "core/skin.h"
#include "core/util/math.h"

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

SolidInterval shadow_cone_interval(const Ray& ray, const ShadowCone& cone, double t_min,
                                   double t_max) {
  const Ray local{ray.origin - cone.base, ray.direction};
  return frustum_solid_interval(local, cone_local_shape(cone), t_min, t_max);
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
    local_.push_back({cones_[i].base, cone_local_shape(cones_[i])});
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
  const Local& l = local_[cone];
  const SolidInterval iv =
      frustum_solid_interval({ray.origin - l.base, ray.direction}, l.shape, t_min, t_max);
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
  return cones_.capacity() * sizeof(ShadowCone) + local_.capacity() * sizeof(Local) +
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

// Clusters one plant's vectors (indices into all.vectors, in their order).
class PlantClusterer {
 public:
  PlantClusterer(const ShadowVectors& all, const std::vector<uint32_t>& members, uint32_t plant,
                 const ConeParams& params, const ConeLimits& limits, ClusterReport& report,
                 std::vector<ShadowCone>& out, std::vector<uint32_t>* cone_of_vector)
      : all_(all), members_(members), plant_(plant), p_(params), limits_(limits), report_(report),
        out_(out), cone_of_vector_(cone_of_vector), removed_(members.size(), 0) {}

  void run() {
    cloud_.points.reserve(members_.size());
    for (uint32_t i = 0; i < members_.size(); ++i) {
      const glm::vec3& p = vec(i).position;
      cloud_.points.push_back({p.x, p.y, p.z});
    }
    tree_ = std::make_unique<KdTree>(3, cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    neighbours_.resize(p_.p1);
    dists_.resize(p_.p1);
    for (uint32_t seed = 0; seed < members_.size(); ++seed) {
      if (removed_[seed]) continue;
      ++report_.seeds;
      try_seed(seed);
    }
    for (uint8_t r : removed_) {
      if (r) ++report_.covered;
      else ++report_.discarded;
    }
  }

 private:
  const ShadowVector& vec(uint32_t local) const { return all_.vectors[members_[local]]; }

  void try_seed(uint32_t seed) {
    const glm::vec3& sp = vec(seed).position;
    const float query[3] = {sp.x, sp.y, sp.z};
    const uint32_t found =
        static_cast<uint32_t>(tree_->knnSearch(query, p_.p1, neighbours_.data(), dists_.data()));
    // K: vectors in order of distance, the seed first (a vector at the seed's very
    // position may come before it).
    k_.clear();
    k_dist_.clear();
    k_.push_back(seed);
    k_dist_.push_back(0);
    for (uint32_t i = 0; i < found && k_.size() < p_.p1; ++i) {
      if (neighbours_[i] == seed) continue;
      k_.push_back(neighbours_[i]);
      k_dist_.push_back(std::sqrt(double(dists_[i])));
    }
    const uint32_t rings = static_cast<uint32_t>((k_.size() - 1) / p_.p3);
    if (rings == 0) return;

    // Step 2: the plane perpendicular to K's mean direction, and each vector's sector.
    glm::dvec3 mean{0, 0, 0};
    for (uint32_t v : k_) mean += to_d(vec(v).direction);
    if (!(glm::length(mean) > 0)) return;
    mean = glm::normalize(mean);
    const AxisFrame plane = axis_frame(mean);
    const glm::dvec3 seed_p = to_d(sp);

    // Steps 3–4: rings of p3 vectors, the index of dispersion of their sector counts.
    counts_.assign(p_.p2, 0);
    const double expected = double(p_.p3) / p_.p2;
    uint32_t passed = 0;
    for (uint32_t ring = 1; ring <= rings; ++ring) {
      std::fill(counts_.begin(), counts_.end(), 0u);
      for (uint32_t i = (ring - 1) * p_.p3 + 1; i <= ring * p_.p3; ++i) {
        const glm::dvec3 q = to_d(vec(k_[i]).position) - seed_p;
        const double angle = std::atan2(glm::dot(q, plane.e1), glm::dot(q, plane.e0));  // [-π, π]
        const int sector = std::clamp(int((angle + kPi) / (2 * kPi) * p_.p2), 0, int(p_.p2) - 1);
        ++counts_[sector];
      }
      double variance = 0;
      for (uint32_t c : counts_) variance += (c - expected) * (c - expected);
      variance /= p_.p2;
      if (variance / expected > p_.variance_threshold) break;
      passed = ring;
    }
    if (passed == 0) return;
    const uint32_t candidates = passed * p_.p3 + 1;
    const double r = k_dist_[candidates - 1];

    // Step 5: axis (eq. 3), expansion (the smallest dot product, as tan), normal, radius.
    glm::dvec3 axis{0, 0, 0};
    for (uint32_t i = 0; i < candidates; ++i) axis += to_d(vec(k_[i]).direction);
    if (!(glm::length(axis) > 0)) return;
    axis = glm::normalize(axis);
    double tan_theta = 0;
    for (uint32_t i = 0; i < candidates; ++i) {
      const glm::dvec3 d = to_d(vec(k_[i]).direction);
      const double along = glm::dot(d, axis);
      if (!(along > 0)) return;  // a vector at 90° or more from the axis: no cone
      tan_theta = std::max(tan_theta, glm::length(glm::cross(d, axis)) / along);
    }
    glm::dvec3 centroid{0, 0, 0};
    for (uint32_t i = 0; i < candidates; ++i) centroid += to_d(vec(k_[i]).position);
    centroid /= double(candidates);
    double cov[3][3] = {};
    for (uint32_t i = 0; i < candidates; ++i) {
      const glm::dvec3 q = to_d(vec(k_[i]).position) - centroid;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) cov[a][b] += q[a] * q[b];
    }
    const glm::dvec3 normal = least_principal_axis(cov);
    const double radius = r * std::abs(glm::dot(normal, axis));  // Fig. 5

    // The cone holds the candidates within the radius of the axis line through the seed;
    // its vectors are those of them still in the set. A hair of margin keeps them inside
    // after rounding (world position, base).
    const double margin = 1e-9 * r + 1e-13 * (glm::length(all_.origin) + glm::length(seed_p));
    if (!(radius > 2 * margin)) return;
    cone_.clear();
    double s_min = 0, s_max = 0;
    for (uint32_t i = 0; i < candidates; ++i) {
      const glm::dvec3 q = to_d(vec(k_[i]).position) - seed_p;
      const double s = glm::dot(q, axis);
      const glm::dvec3 perp = q - s * axis;
      if (glm::dot(perp, perp) > (radius - margin) * (radius - margin) && i > 0) continue;
      s_min = std::min(s_min, s);
      s_max = std::max(s_max, s);
      if (!removed_[k_[i]]) cone_.push_back(k_[i]);
    }
    if (cone_.size() < p_.p4) return;
    s_min -= margin;
    s_max += margin;

    ShadowCone cone;
    cone.base = all_.origin + seed_p + s_min * axis;
    cone.axis = axis;
    cone.radius_base_m = radius;
    cone.tan_theta = tan_theta;
    cone.plant = plant_;
    cone.vectors = static_cast<uint32_t>(cone_.size());
    double length = limits_.max_length_m;
    if (limits_.ground && axis.y < 0) {
      // The whole cross-section below the ground: its highest point, base.y + s·a_y +
      // r(s)·sqrt(1 − a_y²), at or below ground_height.
      const double horizontal = std::sqrt(std::max(0.0, 1 - axis.y * axis.y));
      const double descent = -axis.y - tan_theta * horizontal;
      if (descent > 0) {
        const double s_ground = (cone.base.y - limits_.ground_height + radius * horizontal) / descent;
        length = std::min(length, s_ground);
      }
    }
    cone.length_m = std::max(length, s_max - s_min);
    out_.push_back(cone);
    ++report_.cones;
    for (uint32_t v : cone_) {
      removed_[v] = 1;
      if (cone_of_vector_) (*cone_of_vector_)[members_[v]] = static_cast<uint32_t>(out_.size() - 1);
    }
  }

  const ShadowVectors& all_;
  const std::vector<uint32_t>& members_;
  uint32_t plant_;
  const ConeParams& p_;
  const ConeLimits& limits_;
  ClusterReport& report_;
  std::vector<ShadowCone>& out_;
  std::vector<uint32_t>* cone_of_vector_;
  std::vector<uint8_t> removed_;
  PointCloud cloud_;
  std::unique_ptr<KdTree> tree_;
  std::vector<uint32_t> neighbours_, k_, cone_, counts_;
  std::vector<float> dists_;
  std::vector<double> k_dist_;
};

}  // namespace

std::vector<ShadowCone> cluster_shadow_cones(const ShadowVectors& vectors,
                                             std::span<const uint32_t> plant_of_frustum,
                                             const ConeParams& params, const ConeLimits& limits,
                                             ClusterReport* report,
                                             std::vector<uint32_t>* cone_of_vector) {
  assert(cone_params_error(params) == nullptr && "cluster_shadow_cones: invalid ConeParams");
  assert(limits.max_length_m > 0 && std::isfinite(limits.max_length_m));
  ClusterReport local_report;
  ClusterReport& rep = report ? *report : local_report;
  rep = {};
  rep.vectors = vectors.vectors.size();
  if (cone_of_vector) cone_of_vector->assign(vectors.vectors.size(), kNoCone);
  std::vector<ShadowCone> cones;
  if (vectors.vectors.empty()) return cones;

  // The vectors of each plant, in their order.
  std::vector<uint32_t> order(vectors.vectors.size());
  for (uint32_t i = 0; i < order.size(); ++i) {
    assert(vectors.vectors[i].frustum < plant_of_frustum.size());
    order[i] = i;
  }
  auto plant_of = [&](uint32_t v) { return plant_of_frustum[vectors.vectors[v].frustum]; };
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return plant_of(a) < plant_of(b); });
  std::vector<uint32_t> members;
  for (size_t begin = 0; begin < order.size();) {
    const uint32_t plant = plant_of(order[begin]);
    size_t end = begin;
    while (end < order.size() && plant_of(order[end]) == plant) ++end;
    members.assign(order.begin() + begin, order.begin() + end);
    ++rep.plants;
    PlantClusterer(vectors, members, plant, params, limits, rep, cones, cone_of_vector).run();
    begin = end;
  }
  return cones;
}

}  // namespace sylva
