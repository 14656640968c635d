// embree_scene.h — what the Embree-backed tracers (frustum_accel.cpp: user geometry;
// mesh_accel.cpp: triangles) share: one device per tracer with its memory counted, one
// robust scene (RTC_SCENE_FLAG_ROBUST), and float rays re-centred on the scene so that
// Embree's float traversal never loses a hit that the double test would find.
//
// Internal to core/ (the tracers' headers do not expose Embree). Not copyable; the device
// and scene are released with the object. Errors (no device, a device without a needed
// feature) throw std::runtime_error.
#pragma once

#include <embree3/rtcore.h>

#include <atomic>
#include <cstdint>
#include <glm/vec3.hpp>

#include "core/geometry/ray_frustum.h"
#include "core/util/bounds.h"

namespace sylva {

class EmbreeScene {
 public:
  // need_filter_functions: refuse an Embree built without EMBREE_FILTER_FUNCTION.
  explicit EmbreeScene(bool need_filter_functions = false);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  RTCDevice device() const { return device_; }
  RTCScene scene() const { return scene_; }

  // Commits `geometry`, attaches it to the scene and drops the caller's reference.
  void attach(RTCGeometry geometry);
  // Attaches a user geometry of `count` primitives (none: nothing) with these callbacks
  // and user data.
  void attach_user_geometry(unsigned count, void* user_data, RTCBoundsFunction bounds,
                            RTCIntersectFunctionN intersect, RTCOccludedFunctionN occluded);
  // Builds the BVH over what is attached (call once, after the last attach).
  void commit();
  // Bytes Embree holds for this device (its memory monitor).
  size_t memory_bytes() const;

  // `ray` on [t_min, t_max] as Embree's float ray relative to `centre` (the scene's
  // vertices are relative to it too): the range widened to the floats around it.
  static RTCRay embree_ray(const Ray& ray, const glm::dvec3& centre, double t_min, double t_max);
  // `box` relative to `centre`, grown by `pad` on every side, rounded outward to floats
  // (a user geometry's bounds callback: Embree's float boxes never lose the double box).
  static void write_bounds(RTCBounds* out, const Aabb& box, const glm::dvec3& centre, double pad);
  // Records a user geometry's hit at exact distance t with normal n in the intersect
  // callback's ray: tfar rounded up (Embree culls with it in float, so no nearer box is
  // skipped), the normal, the primitive and geometry.
  static void record_hit(const RTCIntersectFunctionNArguments* args, double t, const glm::dvec3& n);
  // The smallest float >= v, the largest float <= v.
  static float round_up(double v);
  static float round_down(double v);

 private:
  static bool monitor(void* user, ssize_t delta, bool post);
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::atomic<int64_t> bytes_{0};
};

}  // namespace sylva
