// shadow_cones.h — shadow vectors, shadow cones and the set of cones a ray is tested
// against: Hougs and Day 2001 (Hougs & Day 2001), sec. 3.1–3.3, with what the paper leaves as
// future work (sec. 6.2: a hierarchy over the cones) and a stable ray–cone interval in
// place of appendix A's quadratic.
//
// Shadow vectors (sec. 3.1, Fig. 2b): where a sun photon leaves the first plant it hit,
// its direction and the frustum it left. They are made by core/cpu/photons.h; here they
// are only data.
//
// Shadow cones: apex-free solid cones, in the cone's frame (s along the unit axis from the
// base point, ρ the distance from the axis)
//     0 <= s <= length,   ρ <= r(s) = radius_base + s·tan Θ,   r(s) >= 0.
// Sunlight makes Θ about the sun's angular radius (nearly a cylinder); Θ = 0 is a
// cylinder and Θ < 0 a converging cone (an umbra), both ordinary: r(s) never divides by
// tan Θ, and a converging cone ends at its apex at the latest. This is exactly the solid
// of frustum_solid_interval (relief.h) for a frustum cut by two planes perpendicular to
// the axis, so a ray meets a cone in one interval, computed by that function's algorithm
// (re-centred ray, regrouped discriminant, stable roots) specialised to the cone's frame.
// Appendix A's x² + y² = z²·tan²θ puts the apex at the origin: it has no base radius, and
// a cylinder (θ = 0) is the degenerate limit apex → ∞ whose digits it loses.
//
// Clustering (sec. 3.2), per plant; the shadow vectors of a plant in a kd-tree
// (nanoflann), taken in their order. For the first remaining vector (the seed):
//   1. K = its p1 nearest vectors (3D distance; the seed first), those an earlier cone
//      took included: removal takes a vector out of S as a seed and as a cone's vector,
//      but a region already covered is still part of the occluder, not a hole in it.
//      (Drawn from the remaining vectors only, K of a seed among the leftovers between
//      earlier cones spans those cones' holes, whose scattered rims pass the sector test,
//      and grows cones across the occluder's edge: measured, a 0.6 m cone from 25
//      vectors on a 1 m disc, 52% of the shadow's volume covered again outside it.)
//   2. The mean direction of the seed and its first ring (below); each vector of K gets
//      an angle around it (its position relative to the seed, projected into the plane
//      perpendicular to the mean direction) and falls into one of p2 equal angular
//      sectors. (Sunlight's directions differ by the sun's radius, so which of K's
//      vectors the mean takes tilts the plane by less than that; taking the first ring's
//      lets K be gathered in two stages, the first ring and then, only if it passes, the
//      rest: most seeds among thin twigs fail at the first ring.)
//   3. Rings of p3 vectors each, outwards from the seed in the order of K (the paper's
//      "p3, the number of points per sector test, which determines r1..rk"): ring k holds
//      K[(k−1)·p3 + 1 .. k·p3] and reaches out to r_k, the distance of its last vector.
//      Every ring has the same count, so one threshold means the same in every ring.
//   4. The bin-variance test: the variance of the ring's sector counts divided by their
//      mean (the index of dispersion: about 1 for vectors scattered uniformly whatever
//      p2 and p3, about 1 + p3/p2 for a ring half of whose sectors are empty, i.e. an
//      edge; Fig. 4). The first ring k whose index exceeds `variance_threshold` stops the
//      growth; the rings before it passed. Rings run out at the end of K.
//   5. No ring passed: no cone from this seed (it stays in the set, as a vector that
//      ends up discarded unless a later cone covers it). Otherwise the candidates are the
//      seed and the vectors of the passed rings, r = r_{k−1} the radius they reach (the
//      paper's (k−1)·r, its rings being r wide), and:
//        axis     V_M = the normalised mean direction of the candidates (eq. 3);
//        Θ        the largest deviation of a candidate from V_M, i.e. the smallest dot
//                 product (sec. 3.2.2's pseudo-code compares the dot product, a cosine,
//                 with THETA, an angle, and so would keep the smallest deviation);
//                 computed as the largest |v × V_M| / (v · V_M) = tan, which keeps its
//                 digits at sun-sized angles where 1 − cos does not;
//        radius   r_b = r · cos θ, θ the angle between the candidates' estimated surface
//                 normal (the least principal axis of their positions) and V_M (Fig. 5:
//                 the disc of radius r on the surface, seen along V_M, holds a circle of
//                 radius r·cos θ);
//        base     the seed moved along V_M to the most sunward candidate within r_b of
//                 the axis line, so every such candidate lies in the cone (s >= 0);
//        length   until the whole cross-section is below the ground, or the length
//                 limit (sec. 5: far from its base a cone overestimates the shadow), but
//                 never shorter than its deepest candidate.
//      The cone holds the candidates within r_b of the axis line; its vectors are those
//      of them still in the set. Fewer than p4: no cone from this seed. Otherwise the
//      cone is kept and its vectors are removed from the set.
//   6. After the last seed, whatever no cone took is discarded (sec. 3.2.1).
// Deterministic: the same vectors in the same order give the same cones, on any number
// of threads (a seed's cone before the p4 test depends on the seed alone, so blocks of
// seeds are proposed in parallel and accepted in order).
//
// Hierarchy (sec. 6.2): a BVH over the cones' bounding boxes, built in a frame aligned
// with the cones' mean axis (sunlight's cones are nearly parallel, so boxes in the world
// frame would be long diagonals overlapping each other; in the sun's frame they are
// tight prisms). A ray collects the intervals of the cones whose boxes it crosses, then
// sorts and merges them (sec. 3.3.1).
//
// Units and frames: world space, metres, Y up, doubles except the stored shadow vectors
// (float, relative to ShadowVectors::origin, 32 bytes). t is in units of the ray's
// direction. Thread-safe: a built ConeSet is only read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "core/geometry/ray_frustum.h"
#include "core/geometry/relief.h"  // SolidInterval, frustum_solid_interval

namespace sylva {

// Where a sun photon exits the first plant it hit (sec. 3.1, Fig. 2b).
struct ShadowVector {
  glm::vec3 position;   // world metres relative to ShadowVectors::origin (float, re-centred)
  glm::vec3 direction;  // unit, the photon's direction (away from the sun)
  uint32_t frustum;     // index into SceneGeometry::frusta (plant/chain/segment from it);
                        // instanced geometry: the photon tracer's frustum space (photons.h)
};
static_assert(sizeof(ShadowVector) <= 32, "a shadow vector is at most 32 bytes (issue: photons)");

// The shadow vectors of a scene and the origin their float positions are relative to
// (near the plants, so float keeps millimetres at any world offset).
struct ShadowVectors {
  glm::dvec3 origin{0, 0, 0};
  std::vector<ShadowVector> vectors;
};

// An apex-free solid cone (see the header comment).
struct ShadowCone {
  glm::dvec3 base{0, 0, 0};  // world metres: centre of the base disc (s = 0)
  glm::dvec3 axis{0, -1, 0}; // unit, away from the sun
  double radius_base_m = 0;  // r(0) >= 0
  double tan_theta = 0;      // dr/ds, any sign
  double length_m = 1;       // > 0; with tan_theta < 0 the cone ends at its apex if sooner
  uint32_t plant = 0;        // index into Scene::plants of the occluder
  uint32_t vectors = 0;      // shadow vectors it took from the set (0: made by hand)

  // Where the solid ends: length_m, or the apex r(s) = 0 of a converging cone if sooner.
  double end_s() const;
  double radius_at(double s) const { return radius_base_m + s * tan_theta; }
};

// Whether `point` lies in the closed solid of `cone`.
bool cone_contains(const ShadowCone& cone, const glm::dvec3& point);

// The solid of `cone` as a frustum shape in the cone's frame: base at the origin, planes
// s = 0 and s = end_s() perpendicular to the axis (so their offsets are exact). The tests
// check shadow_cone_interval against frustum_solid_interval on it.
FrustumShape cone_local_shape(const ShadowCone& cone);

// A cone as the interval queries use it: what frustum_solid_interval would see of
// cone_local_shape, precomputed.
struct ShadowConeGeometry {
  glm::dvec3 base{0, 0, 0};
  glm::dvec3 axis{0, -1, 0};
  double end = 1;      // end_s()
  double radius0 = 0;  // r(0)
  double slope = 0;    // (max(0, r(end)) − r(0)) / end
  // The part of `ray` with t in [t_min, t_max] inside the cone (see shadow_cone_interval).
  SolidInterval interval(const Ray& ray, double t_min, double t_max) const;
};
ShadowConeGeometry cone_geometry(const ShadowCone& cone);

// The part of `ray` with t in [t_min, t_max] inside `cone`: frustum_solid_interval's
// algorithm (re-centred ray, regrouped discriminant, the root pair chosen by their error
// bounds) specialised to the cone's frame, into which the ray is moved by origin − base
// (exact to half an ulp of the local coordinate, which keeps a millimetre cone 10⁶ m from
// the world origin). 1.7× cheaper than the general function (measured; shadow_cones.cpp).
SolidInterval shadow_cone_interval(const Ray& ray, const ShadowCone& cone, double t_min,
                                   double t_max);

struct ConeInterval {
  double t_enter = 0, t_exit = 0;  // t in units of ray.direction, t_enter < t_exit
};

// Sorts `intervals` by t_enter and merges overlapping or touching ones in place (sec.
// 3.3.1): the result is sorted and disjoint.
void sort_and_merge(std::vector<ConeInterval>& intervals);

class ConeSet {  // viewpoint independent: built once per (plants, sun)
 public:
  ConeSet() = default;
  // Every cone must have a unit axis, radius_base_m >= 0 and length_m > 0 (finite).
  explicit ConeSet(std::vector<ShadowCone> cones);

  // Sorted, disjoint (merged) intervals of t within [t_min, t_max] where origin +
  // t·direction lies inside at least one shadow cone. Appends to *out after clearing it.
  // Intervals of zero length (a ray touching a cone) are left out. Thread-safe.
  void intervals(const Ray& ray, double t_min, double t_max, std::vector<ConeInterval>* out) const;
  // The same, testing every cone (the reference the hierarchy is measured against).
  void intervals_brute_force(const Ray& ray, double t_min, double t_max,
                             std::vector<ConeInterval>* out) const;
  // Whether `point` lies inside at least one cone (through the hierarchy).
  bool contains(const glm::dvec3& point) const;

  size_t size() const { return cones_.size(); }  // cones
  const std::vector<ShadowCone>& cones() const { return cones_; }
  size_t memory_bytes() const;
  uint32_t depth() const { return depth_; }  // of the hierarchy (root = 1; 0 when empty)

  // One node of the hierarchy, in the frame (e0, e1, axis): count > 0 is a leaf of cones
  // order_[first .. first + count); count == 0 an interior node whose left child is the
  // next node and whose right child is `first`.
  struct Node {
    double lo[3], hi[3];
    uint32_t first = 0, count = 0;
  };

 private:
  void collect(const Ray& ray, double t_min, double t_max, uint32_t cone,
               std::vector<ConeInterval>* out) const;

  std::vector<ShadowCone> cones_;
  std::vector<ShadowConeGeometry> local_;
  std::vector<Node> nodes_;
  std::vector<uint32_t> order_;
  glm::dvec3 frame_[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // rows: e0, e1, mean axis
  uint32_t depth_ = 0;
};

// The clustering's parameters (sec. 3.2.1; see the header comment for their meaning).
struct ConeParams {
  uint32_t p1 = 96;                 // nearest neighbours in K, >= p3 + 1
  uint32_t p2 = 8;                  // angular sectors, >= 2
  uint32_t p3 = 24;                 // vectors per ring (per sector test), >= 1
  uint32_t p4 = 16;                 // least vectors per cone, >= 1
  double variance_threshold = 2.5;  // index of dispersion above which a ring fails, > 0
};

// nullptr when `params` is usable, else what is wrong with it.
const char* cone_params_error(const ConeParams& params);

// Where cones end (sec. 5).
struct ConeLimits {
  double max_length_m = 100;  // > 0, finite: the length limit
  bool ground = false;        // a ground plane y = ground_height ends cones below it
  double ground_height = 0;
};

// What the clustering did.
struct ClusterReport {
  uint64_t vectors = 0;    // shadow vectors in
  uint64_t covered = 0;    // vectors taken by a cone
  uint64_t discarded = 0;  // vectors no cone took
  uint64_t seeds = 0;      // seeds tried
  uint64_t cones = 0;      // cones made
  uint64_t plants = 0;     // plants with at least one shadow vector
};

inline constexpr uint32_t kNoCone = 0xffffffffu;

// The shadow vectors of a scene grouped per plant, each plant's positions in a kd-tree,
// ready to be clustered (as the header comment describes) with one parameter set or
// several (the automatic choice clusters one window many times). With neighbours_p1 > 0
// every vector's nearest neighbours_p1 are found once, here, and shared by every
// clustering whose p1 <= neighbours_p1 (the nearest p1 are a prefix of them, up to ties
// in distance); with 0
// each clustering finds them as it goes. `vectors` must outlive the index, unchanged;
// every frustum index must be within plant_of_frustum.
class ShadowVectorIndex {
 public:
  ShadowVectorIndex(const ShadowVectors& vectors, std::span<const uint32_t> plant_of_frustum,
                    uint32_t neighbours_p1 = 0, unsigned threads = 0);
  ~ShadowVectorIndex();
  ShadowVectorIndex(const ShadowVectorIndex&) = delete;
  ShadowVectorIndex& operator=(const ShadowVectorIndex&) = delete;

  // Plants are clustered one after the other, in increasing plant index, and the cones
  // come out in that order. Within a plant, blocks of seeds have their cones proposed on
  // `threads` threads (0: every core) and accepted in seed order, so the result is the
  // sequential algorithm's for every thread count. Writes what happened to *report, and
  // for each vector the index of the cone that took it (kNoCone: discarded) to
  // *cone_of_vector, when they are non-null. Thread-safe (const).
  std::vector<ShadowCone> cluster(const ConeParams& params, const ConeLimits& limits,
                                  ClusterReport* report = nullptr,
                                  std::vector<uint32_t>* cone_of_vector = nullptr,
                                  unsigned threads = 0) const;

  struct Plant;  // (shadow_cones.cpp)

 private:
  const ShadowVectors& vectors_;
  std::vector<std::unique_ptr<Plant>> plants_;
};

// ShadowVectorIndex(vectors, plant_of_frustum).cluster(params, limits, ...).
std::vector<ShadowCone> cluster_shadow_cones(const ShadowVectors& vectors,
                                             std::span<const uint32_t> plant_of_frustum,
                                             const ConeParams& params, const ConeLimits& limits,
                                             ClusterReport* report = nullptr,
                                             std::vector<uint32_t>* cone_of_vector = nullptr,
                                             unsigned threads = 0);

}  // namespace sylva
