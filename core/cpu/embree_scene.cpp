// embree_scene.cpp — see embree_scene.h.
#include "core/cpu/embree_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace sylva {

namespace {
constexpr float kInfF = std::numeric_limits<float>::infinity();
}  // namespace

EmbreeScene::EmbreeScene(bool need_filter_functions) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("Embree: cannot create a device");
  if (need_filter_functions && !rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED)) {
    rtcReleaseDevice(device_);
    throw std::runtime_error("Embree was built without filter functions (EMBREE_FILTER_FUNCTION)");
  }
  rtcSetDeviceMemoryMonitorFunction(device_, &EmbreeScene::monitor, this);
  scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
}

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

void EmbreeScene::attach(RTCGeometry geometry) {
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene_, geometry);
  rtcReleaseGeometry(geometry);
}

void EmbreeScene::attach_user_geometry(unsigned count, void* user_data, RTCBoundsFunction bounds,
                                       RTCIntersectFunctionN intersect, RTCOccludedFunctionN occluded) {
  if (count == 0) return;
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geom, count);
  rtcSetGeometryUserData(geom, user_data);
  rtcSetGeometryBoundsFunction(geom, bounds, nullptr);
  rtcSetGeometryIntersectFunction(geom, intersect);
  rtcSetGeometryOccludedFunction(geom, occluded);
  attach(geom);
}

void EmbreeScene::write_bounds(RTCBounds* o, const Aabb& box, const glm::dvec3& centre, double pad) {
  const glm::dvec3 lo = box.lo - centre - glm::dvec3(pad);
  const glm::dvec3 hi = box.hi - centre + glm::dvec3(pad);
  o->lower_x = round_down(lo.x), o->lower_y = round_down(lo.y), o->lower_z = round_down(lo.z);
  o->upper_x = round_up(hi.x), o->upper_y = round_up(hi.y), o->upper_z = round_up(hi.z);
}

void EmbreeScene::record_hit(const RTCIntersectFunctionNArguments* args, double t, const glm::dvec3& n) {
  auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
  rh->ray.tfar = round_up(t);
  rh->hit.Ng_x = static_cast<float>(n.x), rh->hit.Ng_y = static_cast<float>(n.y), rh->hit.Ng_z = static_cast<float>(n.z);
  rh->hit.u = rh->hit.v = 0;
  rh->hit.primID = args->primID;
  rh->hit.geomID = args->geomID;
  rh->hit.instID[0] = args->context->instID[0];
}

void EmbreeScene::commit() { rtcCommitScene(scene_); }

size_t EmbreeScene::memory_bytes() const { return static_cast<size_t>(std::max<int64_t>(0, bytes_.load())); }

bool EmbreeScene::monitor(void* user, ssize_t delta, bool) {
  static_cast<EmbreeScene*>(user)->bytes_ += delta;
  return true;
}

float EmbreeScene::round_up(double v) {
  const float f = static_cast<float>(v);
  return static_cast<double>(f) < v ? std::nextafter(f, kInfF) : f;
}

float EmbreeScene::round_down(double v) {
  const float f = static_cast<float>(v);
  return static_cast<double>(f) > v ? std::nextafter(f, -kInfF) : f;
}

RTCRay EmbreeScene::embree_ray(const Ray& ray, const glm::dvec3& centre, double t_min, double t_max) {
  RTCRay r{};
  const glm::dvec3 o = ray.origin - centre;
  r.org_x = static_cast<float>(o.x), r.org_y = static_cast<float>(o.y), r.org_z = static_cast<float>(o.z);
  r.dir_x = static_cast<float>(ray.direction.x), r.dir_y = static_cast<float>(ray.direction.y),
  r.dir_z = static_cast<float>(ray.direction.z);
  r.tnear = std::max(0.0f, round_down(t_min));
  r.tfar = std::isfinite(t_max) ? round_up(t_max) : kInfF;
  r.mask = 0xFFFFFFFFu;
  return r;
}

}  // namespace sylva
