// instance_tracer.cpp — plants as instances of prototype tracers over one Embree user
// geometry (see instance_tracer.h).
#include "core/cpu/instance_tracer.h"

#include "core/cpu/embree_scene.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <limits>
#include <stdexcept>

namespace sylva {

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

struct InstanceData {
  const std::unique_ptr<SceneTracer>* prototypes;
  const TracedInstance* instances;
  const Aabb* boxes;  // world box of each instance
  glm::dvec3 centre;
  double pad;
};

// Embree's context extended with the double query (Embree 3 allows embedding it first).
struct InstanceQuery {
  RTCIntersectContext embree;
  const InstanceData* data;
  Ray ray;
  double t_min;
  double t_best;
  SurfaceHit best;
  bool found;
};

InstanceQuery start_query(const InstanceData& data, const Ray& ray, double t_min, double t_max) {
  InstanceQuery q{};
  rtcInitIntersectContext(&q.embree);
  q.data = &data;
  q.ray = ray;
  q.t_min = t_min;
  q.t_best = t_max;
  q.found = false;
  return q;
}

// The world ray in instance `inst`'s frame: the same t reaches the same point.
Ray local_ray(const TracedInstance& inst, const Ray& ray) {
  return {inst.transform.to_local(ray.origin), inst.transform.unrotate(ray.direction) / inst.transform.scale};
}

// A prototype's hit of `local` taken to the world of `ray` (instance_tracer.h).
SurfaceHit world_hit(const TracedInstance& inst, const Ray& ray, SurfaceHit h) {
  const PlantTransform& x = inst.transform;
  h.position = ray.origin + h.t * ray.direction;
  h.geometric_normal = x.rotate(h.geometric_normal);
  h.shading_normal = x.rotate(h.shading_normal);
  h.dp_du = x.scale * x.rotate(h.dp_du);
  h.dp_dv = x.rotate(h.dp_dv);
  if (!h.is_leaf()) h.v_m *= x.scale;  // metres of arc; a leaf's v is its own [0, 1]
  if (inst.plant != TracedInstance::kOwnPlant) h.plant = inst.plant;
  return h;
}

void bounds_callback(const RTCBoundsFunctionArguments* args) {
  const auto* data = static_cast<const InstanceData*>(args->geometryUserPtr);
  EmbreeScene::write_bounds(args->bounds_o, data->boxes[args->primID], data->centre, data->pad);
}

void intersect_callback(const RTCIntersectFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* q = reinterpret_cast<InstanceQuery*>(args->context);
  const TracedInstance& inst = q->data->instances[args->primID];
  const SurfaceHit h = q->data->prototypes[inst.prototype]->nearest(local_ray(inst, q->ray), q->t_min, q->t_best);
  if (!h.hit() || !(h.t < q->t_best)) return;
  q->t_best = h.t;
  q->best = world_hit(inst, q->ray, h);
  q->found = true;
  EmbreeScene::record_hit(args, q->t_best, q->best.geometric_normal);
}

void occluded_callback(const RTCOccludedFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* q = reinterpret_cast<InstanceQuery*>(args->context);
  const TracedInstance& inst = q->data->instances[args->primID];
  if (!q->data->prototypes[inst.prototype]->any(local_ray(inst, q->ray), q->t_min, q->t_best)) return;
  q->found = true;
  reinterpret_cast<RTCRay*>(args->ray)->tfar = -kInfF;  // Embree's "occluded" mark
}

}  // namespace

struct InstanceTracer::Impl {
  std::vector<std::unique_ptr<SceneTracer>> prototypes;
  std::vector<TracedInstance> instances;
  std::vector<Aabb> boxes;
  Aabb bounds = empty_box();
  EmbreeScene embree;
  InstanceData data{};
};

InstanceTracer::InstanceTracer(std::vector<std::unique_ptr<SceneTracer>> prototypes,
                               std::vector<TracedInstance> instances)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.prototypes = std::move(prototypes);
  // An instance of an empty prototype can be hit by nothing: it is left out (Embree gets
  // only valid boxes).
  for (const TracedInstance& inst : instances) {
    if (inst.prototype >= m.prototypes.size()) throw std::invalid_argument("InstanceTracer: no such prototype");
    const Aabb box = inst.transform.world_box(m.prototypes[inst.prototype]->bounds());
    if (!(box.lo.x <= box.hi.x)) continue;
    m.instances.push_back(inst);
    m.boxes.push_back(box);
    grow(m.bounds, box);
  }
  const bool empty = !(m.bounds.lo.x <= m.bounds.hi.x);
  m.data.prototypes = m.prototypes.data();
  m.data.instances = m.instances.data();
  m.data.boxes = m.boxes.data();
  m.data.centre = empty ? glm::dvec3(0) : 0.5 * (m.bounds.lo + m.bounds.hi);
  m.data.pad = empty ? 0 : 1e-6 * glm::length(m.bounds.hi - m.bounds.lo);
  m.embree.attach_user_geometry(static_cast<unsigned>(m.instances.size()), &m.data, bounds_callback,
                                intersect_callback, occluded_callback);
  m.embree.commit();
}

InstanceTracer::~InstanceTracer() = default;

SurfaceHit InstanceTracer::nearest(const Ray& ray, double t_min, double t_max) const {
  InstanceQuery q = start_query(impl_->data, ray, t_min, t_max);
  RTCRayHit rh{};
  rh.ray = EmbreeScene::embree_ray(ray, impl_->data.centre, t_min, t_max);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->embree.scene(), &q.embree, &rh);
  return q.found ? q.best : SurfaceHit{};
}

bool InstanceTracer::any(const Ray& ray, double t_min, double t_max) const {
  InstanceQuery q = start_query(impl_->data, ray, t_min, t_max);
  RTCRay r = EmbreeScene::embree_ray(ray, impl_->data.centre, t_min, t_max);
  rtcOccluded1(impl_->embree.scene(), &q.embree, &r);
  return q.found;
}

Aabb InstanceTracer::bounds() const { return impl_->bounds; }

size_t InstanceTracer::memory_bytes() const {
  size_t bytes = impl_->embree.memory_bytes() + impl_->instances.size() * (sizeof(TracedInstance) + sizeof(Aabb));
  for (const auto& p : impl_->prototypes) bytes += p->memory_bytes();
  return bytes;
}

std::string InstanceTracer::describe() const {
  std::string line = std::to_string(impl_->instances.size()) + " instances of " +
                     std::to_string(impl_->prototypes.size()) + " skeletons";
  if (!impl_->prototypes.empty()) line += " (the first: " + impl_->prototypes.front()->describe() + ")";
  return line;
}

size_t InstanceTracer::instances() const { return impl_->instances.size(); }
size_t InstanceTracer::prototypes() const { return impl_->prototypes.size(); }

}  // namespace sylva
