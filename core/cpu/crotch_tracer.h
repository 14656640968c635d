// crotch_tracer.h — the blended crotches (core/geometry/crotch.h, docs/joints.md
// "Crotches") in the CPU ray caster: an Embree user geometry over their balls beside the
// scene's other geometry, one SceneTracer over both, so that primary rays, shadow rays and
// the fog's shadow rays see the fillets wherever they see wood.
//
// A fillet is extra material in front of the exact frusta, never behind them (F <= the
// union's bound), so a nearest query asks the other geometry first and the crotches only
// up to its hit; a crotch hit counts only where it is in front of the exact surface by more
// than 10⁻⁶ of its ball's radius — where the blend changes nothing, the march converges on
// the exact surface and the exact hit (its relief, its caps) is kept.
//
// What a fillet hit reports (SurfaceHit): t and position in double; geometric_normal =
// shading_normal = crotch_shade's mixed eq. 8 normal; the heavier group's frustum (h >= ½:
// the parent's) for plant, chain, segment, material, frustum, u, v_m and the tangents, and
// the other group's (u, v_m, material) as `*_other` with `blend` = max(h, 1 − h).
//
// A shadow ray (`any`) is marched from 10⁻³ of a ball's radius past its start, so that a
// ray leaving a fillet does not find the fillet it left along the field's kinks.
//
// Not seen by: the sun photons (photons.cpp traces frusta directly) and the `?E` light —
// docs/joints.md says so. Preconditions: `frusta` and `plant_of_frustum` are the scene's,
// with the crotches' indices into them, and outlive the tracer. Thread-safe for concurrent
// queries.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/geometry/crotch.h"
#include "core/geometry/surface.h"

namespace sylva {

class CrotchTracer final : public SceneTracer {
 public:
  CrotchTracer(std::vector<Crotch> crotches, std::span<const Frustum> frusta,
               std::span<const uint32_t> plant_of_frustum, std::unique_ptr<SceneTracer> other);
  ~CrotchTracer() override;
  CrotchTracer(const CrotchTracer&) = delete;
  CrotchTracer& operator=(const CrotchTracer&) = delete;

  SurfaceHit nearest(const Ray& ray, double t_min, double t_max) const override;
  bool any(const Ray& ray, double t_min, double t_max) const override;
  Aabb bounds() const override;
  size_t memory_bytes() const override;
  // The other geometry's line, then ", N blended crotches".
  std::string describe() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sylva
