// frustum_accel.cpp — Embree 3 user geometry over frusta (see frustum_accel.h).
#include "core/cpu/frustum_accel.h"

#include "core/cpu/embree_scene.h"


#include <atomic>
#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <limits>
#include <stdexcept>
#include <string>

namespace sylva {

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

// The intersect context Embree passes to the callbacks, extended with the double ray and
// the best double hit so far (Embree 3 allows a context to be embedded first).
struct QueryContext {
  RTCIntersectContext embree;
  const Frustum* frusta;
  const double* custom_shell;  // nullptr: no custom frusta
  const CustomFrustumIntersector* custom;
  CustomHitDetail* detail;     // the caller's, for custom hits (nullptr: not wanted)
  Ray ray;
  double t_min;
  double t_best;
  BvhHit best;
};

struct GeometryData {
  const Frustum* frusta;
  const double* custom_shell;  // per frustum, or nullptr
  const CustomFrustumIntersector* custom;
  glm::dvec3 centre;
  double pad;
};

// A fresh query for `ray` in (t_min, t_max).
QueryContext start_query(const GeometryData& data, const Ray& ray, double t_min, double t_max,
                         CustomHitDetail* detail) {
  QueryContext q{};
  rtcInitIntersectContext(&q.embree);
  q.frusta = data.frusta;
  q.custom_shell = data.custom_shell;
  q.custom = data.custom;
  q.detail = detail;
  q.ray = ray;
  q.t_min = t_min;
  q.t_best = t_max;
  return q;
}

void bounds_callback(const RTCBoundsFunctionArguments* args) {
  const auto* data = static_cast<const GeometryData*>(args->geometryUserPtr);
  FrustumShape shape = data->frusta[args->primID].shape;
  if (data->custom_shell && data->custom_shell[args->primID] > 0) {
    shape.radius0 += data->custom_shell[args->primID];
    shape.radius1 += data->custom_shell[args->primID];
  }
  const Aabb b = frustum_bounds(shape);
  const glm::dvec3 lo = b.lo - data->centre - glm::dvec3(data->pad);
  const glm::dvec3 hi = b.hi - data->centre + glm::dvec3(data->pad);
  RTCBounds* o = args->bounds_o;
  o->lower_x = EmbreeScene::round_down(lo.x), o->lower_y = EmbreeScene::round_down(lo.y), o->lower_z = EmbreeScene::round_down(lo.z);
  o->upper_x = EmbreeScene::round_up(hi.x), o->upper_y = EmbreeScene::round_up(hi.y), o->upper_z = EmbreeScene::round_up(hi.z);
}

// Tests one candidate with the exact double ray; records it if nearer.
bool test_candidate(QueryContext* q, unsigned prim) {
  FrustumHit h = q->custom_shell && q->custom_shell[prim] > 0
                     ? q->custom->intersect(prim, q->ray, q->t_min, q->t_best, q->detail)
                     : intersect_frustum(q->ray, q->frusta[prim].shape, q->t_min, q->t_best);
  if (!h.hit()) return false;
  q->t_best = h.t;
  q->best.hit = h;
  q->best.frustum = prim;
  return true;
}

void intersect_callback(const RTCIntersectFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* q = reinterpret_cast<QueryContext*>(args->context);
  if (!test_candidate(q, args->primID)) return;
  auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
  // Embree culls with a float tfar: round the exact t up so no nearer box is skipped.
  rh->ray.tfar = EmbreeScene::round_up(q->t_best);
  rh->hit.Ng_x = static_cast<float>(q->best.hit.normal.x);
  rh->hit.Ng_y = static_cast<float>(q->best.hit.normal.y);
  rh->hit.Ng_z = static_cast<float>(q->best.hit.normal.z);
  rh->hit.u = rh->hit.v = 0;
  rh->hit.primID = args->primID;
  rh->hit.geomID = args->geomID;
  rh->hit.instID[0] = args->context->instID[0];
}

void occluded_callback(const RTCOccludedFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* q = reinterpret_cast<QueryContext*>(args->context);
  if (!test_candidate(q, args->primID)) return;
  reinterpret_cast<RTCRay*>(args->ray)->tfar = -kInfF;  // Embree's "occluded" mark
}

}  // namespace

struct FrustumAccel::Impl {
  EmbreeScene embree;
  GeometryData data{};
};

FrustumAccel::FrustumAccel(std::span<const Frustum> frusta, CustomFrusta custom)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  // Centre and a padding that covers float rounding of rays far across the scene.
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  const bool has_custom = !custom.shell_m.empty() && custom.intersector;
  if (has_custom && custom.shell_m.size() != frusta.size())
    throw std::invalid_argument("FrustumAccel: custom.shell_m must have one entry per frustum");
  for (size_t i = 0; i < frusta.size(); ++i) {
    FrustumShape shape = frusta[i].shape;
    if (has_custom && custom.shell_m[i] > 0) shape.radius0 += custom.shell_m[i], shape.radius1 += custom.shell_m[i];
    const Aabb b = frustum_bounds(shape);
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  m.data.frusta = frusta.data();
  m.data.custom_shell = has_custom ? custom.shell_m.data() : nullptr;
  m.data.custom = has_custom ? custom.intersector : nullptr;
  m.data.centre = frusta.empty() ? glm::dvec3(0) : 0.5 * (lo + hi);
  m.data.pad = frusta.empty() ? 0 : 1e-6 * glm::length(hi - lo);
  if (!frusta.empty()) {
    RTCGeometry geom = rtcNewGeometry(m.embree.device(), RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geom, static_cast<unsigned>(frusta.size()));
    rtcSetGeometryUserData(geom, &m.data);
    rtcSetGeometryBoundsFunction(geom, bounds_callback, nullptr);
    rtcSetGeometryIntersectFunction(geom, intersect_callback);
    rtcSetGeometryOccludedFunction(geom, occluded_callback);
    m.embree.attach(geom);
  }
  m.embree.commit();
}

FrustumAccel::~FrustumAccel() = default;

BvhHit FrustumAccel::nearest(const Ray& ray, double t_min, double t_max, CustomHitDetail* detail) const {
  QueryContext q = start_query(impl_->data, ray, t_min, t_max, detail);
  RTCRayHit rh{};
  rh.ray = EmbreeScene::embree_ray(ray, impl_->data.centre, t_min, t_max);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->embree.scene(), &q.embree, &rh);
  return q.best;
}

bool FrustumAccel::any(const Ray& ray, double t_min, double t_max) const {
  QueryContext q = start_query(impl_->data, ray, t_min, t_max, nullptr);
  RTCRay r = EmbreeScene::embree_ray(ray, impl_->data.centre, t_min, t_max);
  rtcOccluded1(impl_->embree.scene(), &q.embree, &r);
  return q.best.hit_any();
}

size_t FrustumAccel::memory_bytes() const { return impl_->embree.memory_bytes(); }

}  // namespace sylva
