// instance_tracer.h — plants that share a skeleton traced as instances (docs/scatter.md,
// "Instancing"): each distinct skeleton is skinned once into a prototype tracer in its own
// frame (its frusta in their Embree user-geometry scene, its leaves beside them:
// frustum_tracer.h, leaf_tracer.h), and an Embree scene over the plants holds one user
// primitive per plant — the prototype's box through the plant's transform — whose callbacks
// take the caller's double ray into the prototype's frame (instances.h) and ask the
// prototype's scene.
//
// Why not Embree's RTC_GEOMETRY_TYPE_INSTANCE: it hands the user geometry a float ray it has
// transformed itself, while the frusta's exactness rests on intersecting the caller's double
// ray (frustum_accel.h); here the double ray is transformed in double, and the prototype's
// own Embree scene stays what the single-plant path builds.
//
// What a hit reports: the prototype's SurfaceHit taken to the world — t unchanged (the local
// ray is the affine image of the world ray), position origin + t·direction in the world,
// normals and dp_dv rotated, dp_du rotated and scaled, v_m scaled (arc length in world
// metres, as place_plant's skeleton measures it), u, chain, segment, material and leaf as in
// the prototype, plant the instance's plant; frustum indexes the prototype's frusta. Equal to
// the hit on the placed plant's own frusta up to the rounding of the two transforms.
//
// Preconditions: the transforms are place_plant's (uniform scale > 0, rotation about y).
// Thread-safe for concurrent queries.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/scene/instances.h"
#include "core/geometry/surface.h"

namespace sylva {

struct TracedInstance {
  uint32_t prototype = 0;  // index into the tracer's prototypes
  uint32_t plant = 0;      // the SurfaceHit::plant its hits report; kOwnPlant: the prototype's
  PlantTransform transform;

  // A prototype of plants already placed in the world (identity transform, which takes
  // rays and hits through exactly): its hits keep the plant the prototype reports.
  static constexpr uint32_t kOwnPlant = 0xFFFFFFFFu;
};

class InstanceTracer final : public SceneTracer {
 public:
  // `prototypes`: one tracer per distinct skeleton, in the skeleton's frame (or of world
  // plants, for kOwnPlant instances). Throws std::runtime_error when Embree fails.
  InstanceTracer(std::vector<std::unique_ptr<SceneTracer>> prototypes, std::vector<TracedInstance> instances);
  ~InstanceTracer() override;
  InstanceTracer(const InstanceTracer&) = delete;
  InstanceTracer& operator=(const InstanceTracer&) = delete;

  SurfaceHit nearest(const Ray& ray, double t_min, double t_max) const override;
  bool any(const Ray& ray, double t_min, double t_max) const override;
  Aabb bounds() const override;
  size_t memory_bytes() const override;
  // "N instances of K skeletons (<the first prototype's line>...)".
  std::string describe() const override;

  size_t instances() const;
  size_t prototypes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sylva
