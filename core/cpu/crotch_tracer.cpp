// crotch_tracer.cpp — see crotch_tracer.h.
#include "core/cpu/crotch_tracer.h"

#include <algorithm>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>

#include "core/cpu/embree_scene.h"

namespace sylva {

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();
constexpr uint32_t kNone = 0xFFFFFFFFu;

struct Data {
  const Crotch* crotches;
  std::span<const Frustum> frusta;
  glm::dvec3 centre;
  double pad;
};

// The query context (Embree's first) with the double ray and the nearest fillet so far.
struct Query {
  RTCIntersectContext embree;
  const Data* data;
  Ray ray;
  double t_min;
  double t_best;
  bool shadow;  // any(): each march starts 10⁻³ of its ball's radius past t_min
  uint32_t best = kNone;
};

Aabb ball_box(const Crotch& c) { return {c.centre - glm::dvec3(c.radius), c.centre + glm::dvec3(c.radius)}; }

void bounds_callback(const RTCBoundsFunctionArguments* args) {
  const auto* d = static_cast<const Data*>(args->geometryUserPtr);
  EmbreeScene::write_bounds(args->bounds_o, ball_box(d->crotches[args->primID]), d->centre, d->pad);
}

bool test_candidate(Query* q, unsigned prim) {
  const Crotch& c = q->data->crotches[prim];
  const double t_min = q->shadow ? q->t_min + 1e-3 * c.radius / glm::length(q->ray.direction) : q->t_min;
  const std::optional<CrotchHit> h = march_crotch(c, q->data->frusta, q->ray, t_min, q->t_best);
  if (!h || !(h->t < q->t_best)) return false;
  q->t_best = h->t;
  q->best = prim;
  return true;
}

void intersect_callback(const RTCIntersectFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* q = reinterpret_cast<Query*>(args->context);
  if (!test_candidate(q, args->primID)) return;
  EmbreeScene::record_hit(args, q->t_best, glm::dvec3(0, 1, 0));
}

void occluded_callback(const RTCOccludedFunctionNArguments* args) {
  if (!args->valid[0]) return;
  auto* q = reinterpret_cast<Query*>(args->context);
  if (!test_candidate(q, args->primID)) return;
  reinterpret_cast<RTCRay*>(args->ray)->tfar = -kInfF;  // Embree's "occluded" mark
}

// Around: a full turn is the circumference at the point's radius; along: the axis.
void set_tangents(SurfaceHit& s, const FrustumShape& f) {
  const glm::dvec3 w = s.position - f.base;
  const glm::dvec3 perp = w - glm::dot(w, f.axis) * f.axis;
  const double r = glm::length(perp);
  const glm::dvec3 radial = r > 0 ? perp / r : glm::dvec3(0);
  s.dp_du = (2 * std::numbers::pi * r) * glm::cross(f.axis, radial);
  s.dp_dv = glm::normalize(f.axis + f.slope() * radial);
}

}  // namespace

struct CrotchTracer::Impl {
  std::vector<Crotch> crotches;
  std::span<const Frustum> frusta;
  std::span<const uint32_t> plant_of_frustum;
  std::unique_ptr<SceneTracer> other;
  EmbreeScene embree;
  Data data{};
  Aabb box = empty_box();

  Query query(const Ray& ray, double t_min, double t_max, bool shadow) const {
    Query q{};
    rtcInitIntersectContext(&q.embree);
    q.data = &data;
    q.ray = ray;
    q.t_min = t_min;
    q.t_best = t_max;
    q.shadow = shadow;
    return q;
  }
};

CrotchTracer::CrotchTracer(std::vector<Crotch> crotches, std::span<const Frustum> frusta,
                           std::span<const uint32_t> plant_of_frustum, std::unique_ptr<SceneTracer> other)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.crotches = std::move(crotches);
  m.frusta = frusta;
  m.plant_of_frustum = plant_of_frustum;
  m.other = std::move(other);
  Aabb balls = empty_box();
  for (const Crotch& c : m.crotches) grow(balls, ball_box(c));
  m.box = m.other ? m.other->bounds() : empty_box();
  grow(m.box, balls);
  m.data.crotches = m.crotches.data();
  m.data.frusta = frusta;
  m.data.centre = m.crotches.empty() ? glm::dvec3(0) : 0.5 * (balls.lo + balls.hi);
  m.data.pad = m.crotches.empty() ? 0 : 1e-6 * glm::length(balls.hi - balls.lo);
  m.embree.attach_user_geometry(static_cast<unsigned>(m.crotches.size()), &m.data, bounds_callback,
                                intersect_callback, occluded_callback);
  m.embree.commit();
}

CrotchTracer::~CrotchTracer() = default;

SurfaceHit CrotchTracer::nearest(const Ray& ray, double t_min, double t_max) const {
  const Impl& m = *impl_;
  SurfaceHit exact = m.other ? m.other->nearest(ray, t_min, t_max) : SurfaceHit{};
  Query q = m.query(ray, t_min, std::min(t_max, exact.t), false);
  RTCRayHit rh{};
  rh.ray = EmbreeScene::embree_ray(ray, m.data.centre, t_min, q.t_best);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(m.embree.scene(), &q.embree, &rh);
  if (q.best == kNone) return exact;
  const Crotch& c = m.crotches[q.best];
  // In front of the exact surface by more than the march's tolerance: the fillet proper.
  if (exact.hit() && !(q.t_best < exact.t - 1e-6 * c.radius / glm::length(ray.direction))) return exact;
  SurfaceHit s;
  s.t = q.t_best;
  s.position = ray.origin + s.t * ray.direction;
  const CrotchShade shade = crotch_shade(c, m.frusta, s.position);
  const bool parent = shade.h >= 0.5;
  const Frustum& f = m.frusta[parent ? shade.parent_frustum : shade.lateral_frustum];
  const Frustum& other = m.frusta[parent ? shade.lateral_frustum : shade.parent_frustum];
  s.geometric_normal = s.shading_normal = shade.normal;
  s.u = parent ? shade.parent_uv.u : shade.lateral_uv.u;
  s.v_m = parent ? shade.parent_uv.v_m : shade.lateral_uv.v_m;
  s.u_other = parent ? shade.lateral_uv.u : shade.parent_uv.u;
  s.v_m_other = parent ? shade.lateral_uv.v_m : shade.parent_uv.v_m;
  s.blend = std::max(shade.h, 1 - shade.h);
  s.material_other = other.material;
  set_tangents(s, f.shape);
  s.frustum = parent ? shade.parent_frustum : shade.lateral_frustum;
  s.plant = m.plant_of_frustum[s.frustum];
  s.chain = f.chain;
  s.segment = f.segment;
  s.material = f.material;
  return s;
}

bool CrotchTracer::any(const Ray& ray, double t_min, double t_max) const {
  const Impl& m = *impl_;
  if (m.other && m.other->any(ray, t_min, t_max)) return true;
  Query q = m.query(ray, t_min, t_max, true);
  RTCRay r = EmbreeScene::embree_ray(ray, m.data.centre, t_min, t_max);
  rtcOccluded1(m.embree.scene(), &q.embree, &r);
  return q.best != kNone;
}

Aabb CrotchTracer::bounds() const { return impl_->box; }

size_t CrotchTracer::memory_bytes() const {
  size_t bytes = impl_->embree.memory_bytes() + impl_->crotches.capacity() * sizeof(Crotch);
  for (const Crotch& c : impl_->crotches)
    bytes += (c.parent_frusta.capacity() + c.lateral_frusta.capacity()) * sizeof(uint32_t) +
             c.depth.capacity() * sizeof(double);
  return bytes + (impl_->other ? impl_->other->memory_bytes() : 0);
}

std::string CrotchTracer::describe() const {
  const std::string others = impl_->other ? impl_->other->describe() : std::string("nothing else");
  return others + ", " + std::to_string(impl_->crotches.size()) + " blended crotches";
}

}  // namespace sylva
