// frustum_tracer.h — the analytic geometry of a scene as a SceneTracer (surface.h): skinned
// frusta in one Embree acceleration structure (frustum_accel.h), each hit intersected
// exactly (ray_frustum.h) and described for shading: eq. 8 normal on the side (the cap's
// own normal on a cap), u/v_m of skin.h, tangents for the texture footprint.
//
// Preconditions: `frusta` and `plant_of_frustum` have equal sizes and outlive the tracer
// unchanged. Thread-safe for concurrent queries.
#pragma once

#include <memory>
#include <span>

#include "core/frustum_accel.h"
#include "core/skin.h"
#include "core/surface.h"

namespace sylva {

class FrustumTracer final : public SceneTracer {
 public:
  FrustumTracer(std::span<const Frustum> frusta, std::span<const uint32_t> plant_of_frustum);

  SurfaceHit nearest(const Ray& ray, double t_min, double t_max) const override;
  bool any(const Ray& ray, double t_min, double t_max) const override;
  size_t memory_bytes() const override;
  std::string describe() const override;

 private:
  std::span<const Frustum> frusta_;
  std::span<const uint32_t> plant_of_frustum_;
  FrustumAccel accel_;
};

// Describes an exact hit `hit` of `ray` on frustum `f` for shading (position, normals,
// u/v_m, tangents, ids except plant and frustum, which the caller sets).
SurfaceHit describe_frustum_hit(const Ray& ray, const Frustum& f, const FrustumHit& hit);

}  // namespace sylva
