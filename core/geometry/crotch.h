// crotch.h — the blended crotch where a lateral leaves its parent (docs/joints.md
// "Crotches"): the region, the field whose zero set is the blended surface, and the ray
// march through it. Geometry only: the CPU ray caster marches it (core/cpu/crotch_tracer.h),
// GL and the mesh paths draw its triangles (crotch_mesh.h), where SkinOptions::blend_crotches
// asks (the smooth skin; docs/joints.md says what is left).
//
// Units and frames: world space, metres, Y up, doubles, as skin.h.
//
// The blend is extra material, never less. Each frustum's solid has a signed bound
// `frustum_bound` (1-Lipschitz, <= 0 exactly on the solid, at most the distance to the
// solid outside it); a group's bound is the least of its frusta's (their union). A crotch
// holds two groups — the parent's (the parent chain, its continuation and the lateral's
// siblings from the same joint) and the lateral's — and inside its ball the smooth union
//     F(p) = smin(P(p), C(p), k(p)),  smin(a, b, k) = min(a, b) − max(k − |a − b|, 0)² / (4k)
// (the quadratic smooth minimum), with k(p) falling smoothly to 0 at the ball's rim and
// where the lateral's cross-section is wholly under the parent's surface (else the start
// of a thick lateral would swell the parent all round the joint). Since smin <= min, the
// blended solid {F <= 0} holds the exact union, and equals it wherever k = 0 and wherever
// |P − C| >= k: it only fills the crease. F >= min(P, C) − k/4: the bulge is at most k/4.
//
// Preconditions: the frusta are skin_skeleton's for the skeleton (indices as there).
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <optional>
#include <span>
#include <vector>

#include "core/geometry/ray_frustum.h"  // Ray
#include "core/geometry/skin.h"

namespace sylva {

// Signed bound of a frustum's solid at `p`: max of the cone's apex-free distance
// (ρ − r(y)) / sqrt(1 + slope²) and the two planes' (dot(n, p) − offset outward). It is
// 1-Lipschitz, <= 0 exactly where p is in the solid (between the planes, ρ <= r(y)), and
// outside the solid at most the distance to it (so a sphere tracer's step never passes
// the surface). Inside, it is at least minus the distance to the boundary... only where
// the cone term is the largest; no claim is made there.
double frustum_bound(const FrustumShape& shape, const glm::dvec3& p);

struct CrotchOptions {
  double blend = 0.8;        // k at the crotch's centre, as a share of the lateral's radius
  double min_ratio = 0.25;   // no crotch for a lateral under this share of its parent's
                             // radius (the collars' rule: a needle's crotch is too small to see)
};

// Samples of a crotch's depth table (Crotch::depth).
inline constexpr uint32_t kCrotchDepthSamples = 16;

// One blended crotch.
struct Crotch {
  uint32_t lateral = 0;         // the lateral chain
  glm::dvec3 start{0};          // the lateral's first joint (on its parent's axis)
  glm::dvec3 direction{0, 1, 0};// unit, along its first segment
  glm::dvec3 centre{0};         // where its axis leaves the parent's surface
  double radius = 0;            // the ball: F = min(P, C) outside it
  double k = 0;                 // blend width at the centre, metres
  double lateral_radius = 0;    // the lateral's radius at its start
  std::vector<uint32_t> parent_frusta;   // indices into the frusta: the parent group
  std::vector<uint32_t> lateral_frusta;  // ... the lateral group (within the ball)
  // The parent group's depth below its surface (−P) of the lateral's axis point at
  // s = (i + 0.5) · depth_step along `direction` from `start`, i < depth.size();
  // linear in between, clamped at the ends.
  std::vector<double> depth;
  double depth_step = 0;
};

// Every crotch of a skinned skeleton: one per lateral (a child chain that is not its
// parent's continuation, continuation_children) of at least min_ratio of its parent's
// radius at the joint, whose first segment leaves the parent. Deterministic, in chain order.
std::vector<Crotch> find_crotches(const Skeleton& skeleton, std::span<const Frustum> frusta,
                                  const CrotchOptions& options = {});

// What a view needs of the fillets (docs/joints.md "Fillets by their size on screen"): a
// fillet is about k wide and moves the surface off the exact union by at most k/4, so one
// whose k spans fewer than kFilletMinPixels pixels where its ball is nearest the eye moves
// no surface by more than half a pixel; a renderer that knows its view leaves it out.
inline constexpr double kFilletMinPixels = 2;
// Whether crotch `c`'s fillet spans at least min_pixels seen from `eye` by a view of
// pixels_per_radian (culling.h): k / (distance to the ball) · pixels_per_radian; always
// where the eye is inside the ball.
bool crotch_seen(const Crotch& c, const glm::dvec3& eye, double pixels_per_radian,
                 double min_pixels = kFilletMinPixels);
// A skeleton drawn at several places (instances sharing one skinning): whether any of
// `eyes` — the view's eye in the skeleton's frame, one per place (the width-to-distance
// ratio does not change with a placement's scale) — sees c's fillet so wide. The
// instances share the fillets any of them needs.
bool crotch_seen_from_any(const Crotch& c, std::span<const glm::dvec3> eyes, double pixels_per_radian,
                          double min_pixels = kFilletMinPixels);
// `crotches` less those no eye of `eyes` sees kFilletMinPixels wide (crotch_seen_from_any):
// the fillets a view needs, in the order given.
std::vector<Crotch> crotches_seen(std::vector<Crotch> crotches, std::span<const glm::dvec3> eyes,
                                  double pixels_per_radian);

// The two groups' bounds and the blend at a point.
struct CrotchSample {
  double value = 0;    // F(p)
  double parent = 0;   // P(p)
  double lateral = 0;  // C(p)
  double k = 0;        // k(p)
  double h = 0;        // weight of the parent's surface in the shading mix, [0, 1]:
                       // 1 where P is far below C, 0 where C is, 0.5 on the crease
};
CrotchSample crotch_field(const Crotch& crotch, std::span<const Frustum> frusta, const glm::dvec3& p);

// How a point of the blended surface is shaded (docs/joints.md "Crotches"): in each group
// the frustum whose slab (between its two planes) holds the point — of those, the least
// bound; the least bound where none does — not simply the least bound, which switches
// between the two frusta of a mitre off their shared plane, where eq. 8's normals and
// (u, v) differ. The normal is normalize(mix(n_lateral, n_parent, h)) of the two eq. 8
// normals (the fillet's bounds have kinks, so a gradient of F would not be smooth), the
// colour is the same mix of the two textures at their own (u, v_m). The fillet has no
// relief: the frusta's relief fades out before it (crotch_relief_fade). Where h is 0 or 1
// all of it is the exact surface's, so nothing jumps at the fillet's edge.
struct CrotchShade {
  uint32_t parent_frustum = 0;   // index into the frusta
  uint32_t lateral_frustum = 0;
  glm::dvec3 normal{0, 1, 0};    // unit, outward
  SurfaceUV parent_uv, lateral_uv;
  double h = 0;                  // the parent's weight
};
CrotchShade crotch_shade(const Crotch& crotch, std::span<const Frustum> frusta, const glm::dvec3& p);

// The frustum that names a fillet point (ids, material, texture, the sensors' and the
// photons' frustum): the heavier group's shading frustum, the parent's where h >= 1/2.
inline uint32_t heavier_frustum(const CrotchShade& shade) {
  return shade.h >= 0.5 ? shade.parent_frustum : shade.lateral_frustum;
}

// How much of a relief (relief.h ReliefFade) is left at p on the crotch's frusta, from the
// field's sample there: 0 wherever the blend adds material (|P − C| < k(p)), rising as a
// smoothstep of (|P − C| − k)/k to 1 at |P − C| = 2k(p), and 1 wherever k(p) = 0 (outside
// the ball, where the lateral is deep under the parent). So the ribs of both groups sink
// into the relief-free fillet before it begins: the fillet meets relief-free frusta along
// its edge, as without relief, and no rib of one group stands out of the other's surface
// within the blend. Continuous wherever k > 0 or |P − C| > 0.
double crotch_relief_fade(const CrotchSample& sample);

// Which crotches hold each frustum in one of their groups: frustum f's are
// crotches[begin[f] .. begin[f + 1]), in crotch order (CSR over `frustum_count` frusta).
struct CrotchesOfFrusta {
  std::vector<uint32_t> begin{0};
  std::vector<uint32_t> crotches;
  std::span<const uint32_t> of(uint32_t frustum) const {
    return {crotches.data() + begin[frustum], crotches.data() + begin[frustum + 1]};
  }
  size_t bytes() const { return (begin.capacity() + crotches.capacity()) * sizeof(uint32_t); }
};
CrotchesOfFrusta crotches_of_frusta(std::span<const Crotch> crotches, size_t frustum_count);

// The relief left at p on a frustum held by the crotches `which` (indices into crotches):
// the least crotch_relief_fade over those whose ball holds p, 1 where none does.
double relief_fade_at(std::span<const Crotch> crotches, std::span<const uint32_t> which,
                      std::span<const Frustum> frusta, const glm::dvec3& p);

// Largest |∇F| the step is divided by: 1 for the bounds, plus what the fading k adds
// (docs/joints.md: the ball's fade ≤ 1.54·k/R·(1/4), the depth fade ≤ 1.5·(1/4)).
inline constexpr double kCrotchLipschitz = 1.6;

// The first point of the ray inside the ball where F crosses 0 from outside, with
// t_min < t < t_max; none when the ray misses the ball, never reaches F = 0 inside it, or
// enters the ball already inside the blended solid (the exact frusta's surface is then
// in front). Sphere tracing with steps F / kCrotchLipschitz (at least 1e-3/4 of the
// ball's radius, for grazing rays), a step that lands inside bisected back to a bracket
// of 1e-7 of the radius.
//
// With `fillet_only` (what a tracer that has the exact frusta's hit already asks) the march
// also gives up as soon as no point of the rest of the ray can be on the fillet: there
// |P − C| < k (else F = min(P, C)), and |P − C| is 2-Lipschitz, so once
// |P − C| − 2·(distance left to t_max or the ball's exit) >= k only the exact surface is
// ahead. A crossing it does return may still be the exact surface's.
struct CrotchHit {
  double t = 0;
  int steps = 0;  // field evaluations
};
std::optional<CrotchHit> march_crotch(const Crotch& crotch, std::span<const Frustum> frusta, const Ray& ray,
                                      double t_min, double t_max, bool fillet_only = false);

}  // namespace sylva
