// frustum_accel.cpp — Embree 3 user geometry over frusta (see frustum_accel.h).
#include "core/cpu/frustum_accel.h"

#include "core/cpu/embree_scene.h"
#include "core/util/parallel.h"


#include <atomic>
#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace sylva {

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

// The intersect context Embree passes to the callbacks, extended with the double ray and
// the best double hit so far (Embree 3 allows a context to be embedded first).
struct QueryContext {
  RTCIntersectContext embree;
  const Frustum* frusta;
  const double* reach;         // per frustum: frustum_radial_reach
  const double* custom_shell;  // nullptr: no custom frusta
  const CustomFrustumIntersector* custom;
  CustomHitDetail* detail;     // the caller's, for custom hits (nullptr: not wanted)
  Ray ray;
  double t_min;
  double t_best;
  BvhHit best;
  const ExtraPrimitives* extra;  // null: none
  ExtraHit extra_best;           // the nearest extra crossing before t_best
};

struct GeometryData {
  const Frustum* frusta;
  const double* reach;
  const double* custom_shell;  // per frustum, or nullptr
  const CustomFrustumIntersector* custom;
  glm::dvec3 centre;
  double pad;
  const ExtraPrimitives* extra;  // null: none
};

// A fresh query for `ray` in (t_min, t_max).
QueryContext start_query(const GeometryData& data, const Ray& ray, double t_min, double t_max,
                         CustomHitDetail* detail) {
  QueryContext q{};
  rtcInitIntersectContext(&q.embree);
  q.frusta = data.frusta;
  q.reach = data.reach;
  q.custom_shell = data.custom_shell;
  q.custom = data.custom;
  q.detail = detail;
  q.ray = ray;
  q.t_min = t_min;
  q.t_best = t_max;
  q.extra = data.extra;
  return q;
}

void bounds_callback(const RTCBoundsFunctionArguments* args) {
  const auto* data = static_cast<const GeometryData*>(args->geometryUserPtr);
  FrustumShape shape = data->frusta[args->primID].shape;
  if (data->custom_shell && data->custom_shell[args->primID] > 0) {
    shape.radius0 += data->custom_shell[args->primID];
    shape.radius1 += data->custom_shell[args->primID];
  }
  EmbreeScene::write_bounds(args->bounds_o, frustum_bounds(shape), data->centre, data->pad);
}

// Tests one candidate with the exact double ray; records it if nearer. Embree's boxes
// are axis-aligned, so most candidates of a slanted twig or needle are rays that pass
// beside it: the reach test rejects those for a few products before the exact test.
bool test_candidate(QueryContext* q, unsigned prim) {
  const bool custom = q->custom_shell && q->custom_shell[prim] > 0;
  if (!custom && ray_beyond_reach(q->ray, q->frusta[prim].shape, q->reach[prim])) return false;
  FrustumHit h = custom ? q->custom->intersect(prim, q->ray, q->t_min, q->t_best, q->detail)
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
  EmbreeScene::record_hit(args, q->t_best, q->best.hit.normal);
}

void occluded_callback(const RTCOccludedFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* q = reinterpret_cast<QueryContext*>(args->context);
  if (!test_candidate(q, args->primID)) return;
  reinterpret_cast<RTCRay*>(args->ray)->tfar = -kInfF;  // Embree's "occluded" mark
}

// The extra primitives' callbacks (frustum_accel.h): their crossings are kept in the
// query, never written to Embree's ray, so they never cull a frustum.
void extra_bounds_callback(const RTCBoundsFunctionArguments* args) {
  const auto* data = static_cast<const GeometryData*>(args->geometryUserPtr);
  EmbreeScene::write_bounds(args->bounds_o, data->extra->bounds(args->primID), data->centre, data->pad);
}

void extra_intersect_callback(const RTCIntersectFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* q = reinterpret_cast<QueryContext*>(args->context);
  const double t_max = q->extra_best.hit() ? std::min(q->t_best, q->extra_best.t) : q->t_best;
  // ExtraPrimitives::intersect keeps its crossing inside (t_min, t_max): nearer than both.
  if (const std::optional<double> t = q->extra->intersect(args->primID, q->ray, q->t_min, t_max))
    q->extra_best = {args->primID, *t};
}

void extra_occluded_callback(const RTCOccludedFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* q = reinterpret_cast<QueryContext*>(args->context);
  if (!q->extra->occludes(args->primID, q->ray, q->t_min, q->t_best)) return;
  q->extra_best = {args->primID, q->t_min};
  reinterpret_cast<RTCRay*>(args->ray)->tfar = -kInfF;  // Embree's "occluded" mark
}

}  // namespace

struct FrustumAccel::Impl {
  EmbreeScene embree;
  GeometryData data{};
  std::vector<double> reach;
};

FrustumAccel::FrustumAccel(std::span<const Frustum> frusta, CustomFrusta custom, const ExtraPrimitives* extra)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  // Centre and a padding that covers float rounding of rays far across the scene.
  const bool has_custom = !custom.shell_m.empty() && custom.intersector;
  if (has_custom && custom.shell_m.size() != frusta.size())
    throw std::invalid_argument("FrustumAccel: custom.shell_m must have one entry per frustum");
  // The bounds and each frustum's reach, in chunks on every core (min and max are exact
  // in any order, so the result does not depend on the split).
  constexpr size_t kChunk = 4096;
  const size_t chunks = (frusta.size() + kChunk - 1) / kChunk;
  std::vector<Aabb> chunk_box(chunks, empty_box());
  m.reach.resize(frusta.size());
  parallel_for(chunks, 0, nullptr, [&](size_t c, unsigned) {
    for (size_t i = c * kChunk; i < std::min(frusta.size(), (c + 1) * kChunk); ++i) {
      FrustumShape shape = frusta[i].shape;
      if (has_custom && custom.shell_m[i] > 0) shape.radius0 += custom.shell_m[i], shape.radius1 += custom.shell_m[i];
      grow(chunk_box[c], frustum_bounds(shape));
      m.reach[i] = frustum_radial_reach(frusta[i].shape);
    }
  });
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const Aabb& b : chunk_box) lo = glm::min(lo, b.lo), hi = glm::max(hi, b.hi);
  const uint32_t extras = extra ? extra->count() : 0;
  for (uint32_t i = 0; i < extras; ++i) {
    const Aabb b = extra->bounds(i);
    lo = glm::min(lo, b.lo), hi = glm::max(hi, b.hi);
  }
  m.data.frusta = frusta.data();
  m.data.reach = m.reach.data();
  m.data.custom_shell = has_custom ? custom.shell_m.data() : nullptr;
  m.data.custom = has_custom ? custom.intersector : nullptr;
  const bool any = !frusta.empty() || extras > 0;
  m.data.centre = any ? 0.5 * (lo + hi) : glm::dvec3(0);
  m.data.pad = any ? 1e-6 * glm::length(hi - lo) : 0;
  m.data.extra = extras > 0 ? extra : nullptr;
  m.embree.attach_user_geometry(static_cast<unsigned>(frusta.size()), &m.data, bounds_callback, intersect_callback,
                                occluded_callback);
  m.embree.attach_user_geometry(extras, &m.data, extra_bounds_callback, extra_intersect_callback,
                                extra_occluded_callback);
  m.embree.commit();
}

FrustumAccel::~FrustumAccel() = default;

BvhHit FrustumAccel::nearest(const Ray& ray, double t_min, double t_max, CustomHitDetail* detail,
                             ExtraHit* extra) const {
  QueryContext q = start_query(impl_->data, ray, t_min, t_max, detail);
  RTCRayHit rh{};
  rh.ray = EmbreeScene::embree_ray(ray, impl_->data.centre, t_min, t_max);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->embree.scene(), &q.embree, &rh);
  if (extra) *extra = q.extra_best.hit() && q.extra_best.t < q.t_best ? q.extra_best : ExtraHit{};
  return q.best;
}

bool FrustumAccel::any(const Ray& ray, double t_min, double t_max) const {
  QueryContext q = start_query(impl_->data, ray, t_min, t_max, nullptr);
  RTCRay r = EmbreeScene::embree_ray(ray, impl_->data.centre, t_min, t_max);
  rtcOccluded1(impl_->embree.scene(), &q.embree, &r);
  return q.best.hit_any() || q.extra_best.hit();
}

size_t FrustumAccel::memory_bytes() const {
  return impl_->embree.memory_bytes() + impl_->reach.capacity() * sizeof(double);
}

}  // namespace sylva
