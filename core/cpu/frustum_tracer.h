// frustum_tracer.h — the analytic geometry of a scene as a SceneTracer (surface.h): skinned
// frusta in one Embree acceleration structure (frustum_accel.h), each hit intersected
// exactly (ray_frustum.h) and described for shading: eq. 8 normal on the side (the cap's
// own normal on a cap), u/v_m of skin.h, tangents for the texture footprint.
//
// Relief (Bhagvat et al. 2009 sec. 3, relief.h): a plant given a ReliefMap (a height field and a
// depth > 0) has its segment frusta indexed with their shells (boxes grown by the depth)
// and intersected by intersect_relief — nearest and shadow (`any`) rays alike — as custom
// frusta of frustum_accel.h. Knuckle frusta (the balls closing split joints, skin.h) keep
// their exact surface: a ball has no meaningful (u, v) for a height field, and the capped
// legs meeting there end in relief-edged caps that the ball (radius r/cos(π/2k) >= r)
// mostly hides; the relief may protrude up to the depth beyond it at the rim. Plants
// without relief take the exact path, at the exact path's speed.
//
// Blended crotches (crotch_tracer.h): given the crotches, their balls are extra primitives
// of the same Embree scene, and a fillet in front of the frusta's hit is the hit; the
// relief of a crotch's frusta fades into its fillet (crotch.h crotch_relief_fade).
//
// Preconditions: `frusta` and `plant_of_frustum` have equal sizes and outlive the tracer
// unchanged; every ReliefMap's field outlives it. Thread-safe for concurrent queries.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "core/cpu/crotch_tracer.h"
#include "core/cpu/frustum_accel.h"
#include "core/geometry/relief.h"
#include "core/geometry/skin.h"
#include "core/geometry/surface.h"

namespace sylva {

// Relief of a scene: one entry per plant (field nullptr or depth 0: no relief).
struct SceneRelief {
  std::vector<ReliefMap> plants;
  ReliefOptions options;
};

class FrustumTracer final : public SceneTracer {
 public:
  // With `crotches` (over these frusta) the blended crotches' fillets are traced too, in
  // the same Embree scene (crotch_tracer.h).
  FrustumTracer(std::span<const Frustum> frusta, std::span<const uint32_t> plant_of_frustum,
                SceneRelief relief = {}, std::shared_ptr<const CrotchBalls> crotches = nullptr);

  SurfaceHit nearest(const Ray& ray, double t_min, double t_max) const override;
  bool any(const Ray& ray, double t_min, double t_max) const override;
  Aabb bounds() const override { return bounds_; }
  size_t memory_bytes() const override;
  std::string describe() const override;

  // Plants with relief, and frusta intersected by the relief marcher.
  size_t relief_plants() const { return relief_plants_; }
  size_t relief_frusta() const { return relief_frusta_; }

 private:
  class ReliefIntersector final : public CustomFrustumIntersector {
   public:
    explicit ReliefIntersector(const FrustumTracer& tracer) : tracer_(tracer) {}
    FrustumHit intersect(uint32_t index, const Ray& ray, double t_min, double t_max,
                         CustomHitDetail* detail) const override;

   private:
    const FrustumTracer& tracer_;
  };

  std::span<const Frustum> frusta_;
  std::span<const uint32_t> plant_of_frustum_;
  SceneRelief relief_;
  std::vector<double> shell_m_;  // per frustum: relief depth, 0 for exact frusta
  size_t relief_plants_ = 0, relief_frusta_ = 0;
  Aabb bounds_ = empty_box();  // the frusta's boxes, each grown by its relief shell, and the crotches' balls
  ReliefIntersector intersector_;
  std::shared_ptr<const CrotchBalls> crotches_;  // null: no blended crotches
  FrustumAccel accel_;
};

// Describes an exact hit `hit` of `ray` on frustum `f` for shading (position, normals,
// u/v_m, tangents, ids except plant and frustum, which the caller sets).
SurfaceHit describe_frustum_hit(const Ray& ray, const Frustum& f, const FrustumHit& hit);

// Describes a relief hit (relief.h) the same way: the geometric normal is the hit's, the
// shading normal and u/v_m the marcher's, tangents at the hit's distance from the axis.
SurfaceHit describe_relief_hit(const Ray& ray, const Frustum& f, const FrustumHit& hit,
                               const CustomHitDetail& detail);

}  // namespace sylva
