// crotch_tracer.h — the blended crotches (core/geometry/crotch.h, docs/joints.md
// "Crotches") in the CPU ray caster: their balls as extra primitives of the frusta's own
// Embree scene (frustum_accel.h ExtraPrimitives; FrustumTracer takes them), so that a ray
// walks one BVH, and primary rays, shadow rays and the fog's shadow rays see the fillets
// wherever they see wood.
//
// A fillet is extra material in front of the exact frusta, never behind them (F <= the
// union's bound). A ball's march asks for the fillet only (march_crotch's fillet_only) up
// to the nearer of the frusta's hit so far and the fillets' so far; a crossing counts
// (in_front) only where it is in front of the frusta's final hit by more than 10⁻⁶ of its
// ball's radius — where the blend changes nothing, the march converges on the exact
// surface and the exact hit (its relief, its caps) is kept.
//
// What a fillet hit reports (describe): t and position in double; geometric_normal =
// shading_normal = crotch_shade's mixed eq. 8 normal; the heavier group's frustum (h >= ½:
// the parent's) for plant, chain, segment, material, frustum, u, v_m and the tangents, and
// the other group's (u, v_m, material) as `*_other` with `blend` = max(h, 1 − h).
//
// A shadow ray (occludes) is marched from 10⁻³ of a ball's radius past its start, so that
// a ray leaving a fillet does not find the fillet it left along the field's kinks.
//
// Relief (relief.h) on a crotch's frusta fades into its fillet (crotch.h
// crotch_relief_fade): FrustumTracer marches those frusta with a CrotchReliefFade.
//
// The sun photons (photons.cpp) and the `?E` light (light_tracer.h) trace the same balls
// beside their frusta (nearest_wood, below). A renderer's geometry for one view holds the
// balls of the fillets that view can see only (crotch.h crotch_seen; render_cpu.cpp).
// Preconditions: `frusta` (and the plant indices given to
// describe) are the scene's, with the crotches' indices into them, and outlive this object.
// Thread-safe for concurrent queries.
#pragma once

#include <span>
#include <vector>

#include "core/cpu/frustum_accel.h"
#include "core/geometry/crotch.h"
#include "core/geometry/relief.h"
#include "core/geometry/surface.h"

namespace sylva {

class CrotchBalls final : public ExtraPrimitives {
 public:
  CrotchBalls(std::vector<Crotch> crotches, std::span<const Frustum> frusta);

  uint32_t count() const override { return static_cast<uint32_t>(crotches_.size()); }
  Aabb bounds(uint32_t index) const override;
  std::optional<double> intersect(uint32_t index, const Ray& ray, double t_min, double t_max) const override;
  bool occludes(uint32_t index, const Ray& ray, double t_min, double t_max) const override;

  // Whether crotch `index`'s crossing at t is its fillet: in front of the frusta's hit at
  // t_exact (infinity: none) by more than the march's tolerance.
  bool in_front(uint32_t index, const Ray& ray, double t, double t_exact) const;
  // The fillet hit at t of crotch `index`, described for shading (above); plant from
  // `plant_of_frustum`.
  SurfaceHit describe(uint32_t index, const Ray& ray, double t, std::span<const uint32_t> plant_of_frustum) const;
  // The frustum that describe() names for the point p of crotch `index`'s fillet (the
  // heavier group's shading frustum).
  uint32_t frustum_at(uint32_t index, const glm::dvec3& p) const;
  // Each ball's centre and radius (a caller's own bounds: the photons' mask).
  const Crotch& crotch(uint32_t index) const { return crotches_[index]; }

  // Every ball's box, grown together (empty when there are none).
  Aabb all_bounds() const;
  size_t memory_bytes() const;

  // Whether `frustum` belongs to a crotch's group (its relief fades there).
  bool fades(uint32_t frustum) const;
  // The least crotch_relief_fade at p over the crotches that hold `frustum` (1: none).
  double relief_fade(uint32_t frustum, const glm::dvec3& p) const;
  // A difference step for the fade's gradient: 10⁻³ of the least k of those crotches.
  double fade_step_m(uint32_t frustum) const;

 private:
  std::vector<Crotch> crotches_;
  std::span<const Frustum> frusta_;
  CrotchesOfFrusta of_frustum_;  // each frustum's crotches (its relief's fade)
};

// The first wood along `ray` in (t_min, t_max) for a tracer that names what it meets by
// frustum (the sun photons, the `?E` light): the frusta's nearest hit, or a fillet in front
// of it (kind side, t the fillet's), named by its heavier group's frustum (frustum_at).
// `accel` holds `crotches` as its extra primitives, or crotches is null. hit_any() false: none.
BvhHit nearest_wood(const FrustumAccel& accel, const CrotchBalls* crotches, const Ray& ray, double t_min,
                    double t_max);

// The relief fade of one frustum (relief.h ReliefFade) over a scene's crotches.
class CrotchReliefFade final : public ReliefFade {
 public:
  CrotchReliefFade(const CrotchBalls& balls, uint32_t frustum) : balls_(balls), frustum_(frustum) {}
  double scale(const glm::dvec3& world) const override { return balls_.relief_fade(frustum_, world); }
  double fade_step_m() const override { return balls_.fade_step_m(frustum_); }

 private:
  const CrotchBalls& balls_;
  uint32_t frustum_;
};

}  // namespace sylva
