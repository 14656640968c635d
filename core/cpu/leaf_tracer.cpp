// leaf_tracer.cpp — see leaf_tracer.h.
#include "core/cpu/leaf_tracer.h"

#include <algorithm>
#include <limits>

#include "core/cpu/embree_scene.h"
#include "core/cpu/embree_triangles.h"

namespace sylva {

namespace {
constexpr float kInfF = std::numeric_limits<float>::infinity();
}  // namespace

struct LeafTracer::Impl {
  LeafMesh leaves;
  std::unique_ptr<SceneTracer> other;
  glm::dvec3 centre{0, 0, 0};
  Aabb bounds = empty_box();
  EmbreeScene embree{/*need_filter_functions=*/true};
};

LeafTracer::LeafTracer(LeafMesh leaves, std::unique_ptr<SceneTracer> other) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.leaves = std::move(leaves);
  m.other = std::move(other);
  m.bounds = m.leaves.bounds();
  if (!m.leaves.empty()) {
    m.centre = 0.5 * (m.bounds.lo + m.bounds.hi);
    m.embree.attach(new_filtered_triangles(m.embree.device(), m.leaves.positions.data(), m.leaves.positions.size(),
                                           m.leaves.indices.data(), m.leaves.triangle_count(), m.centre));
  }
  m.embree.commit();
}

LeafTracer::~LeafTracer() = default;

SurfaceHit LeafTracer::nearest_leaf(const Ray& ray, double t_min, double t_max) const {
  const Impl& m = *impl_;
  if (m.leaves.empty() || !(t_max > t_min)) return {};
  TriangleQuery q = start_triangle_query(m.leaves.positions.data(), m.leaves.indices.data(), ray, t_min, t_max);
  RTCRayHit rh{};
  rh.ray = EmbreeScene::embree_ray(ray, m.centre, t_min, t_max);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(m.embree.scene(), &q.embree, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
  const uint32_t* tri = &m.leaves.indices[3 * size_t{rh.hit.primID}];
  // The filter kept it: det != 0 and t in range. The barycentrics give the uv.
  const TriangleCrossing c =
      cross_triangle(ray, m.leaves.positions[tri[0]], m.leaves.positions[tri[1]], m.leaves.positions[tri[2]]);
  const LeafRef& leaf = m.leaves.leaves[m.leaves.triangle_leaf[rh.hit.primID]];
  SurfaceHit s;
  s.t = c.t;
  s.position = ray.origin + c.t * ray.direction;
  s.geometric_normal = s.shading_normal = leaf.normal;
  const glm::dvec2 uv = (1 - c.b1 - c.b2) * m.leaves.uvs[tri[0]] + c.b1 * m.leaves.uvs[tri[1]] +
                        c.b2 * m.leaves.uvs[tri[2]];
  s.u = std::clamp(uv.x, 0.0, 1.0);
  s.v_m = std::clamp(uv.y, 0.0, 1.0);
  s.plant = leaf.plant;
  s.material = leaf.material;
  s.leaf = leaf.leaf;
  return s;
}

SurfaceHit LeafTracer::nearest(const Ray& ray, double t_min, double t_max) const {
  const Impl& m = *impl_;
  SurfaceHit s = m.other ? m.other->nearest(ray, t_min, t_max) : SurfaceHit{};
  SurfaceHit leaf = nearest_leaf(ray, t_min, s.hit() ? s.t : t_max);
  return leaf.hit() ? leaf : s;
}

bool LeafTracer::any(const Ray& ray, double t_min, double t_max) const {
  const Impl& m = *impl_;
  if (!m.leaves.empty()) {
    TriangleQuery q = start_triangle_query(m.leaves.positions.data(), m.leaves.indices.data(), ray, t_min, t_max);
    RTCRay r = EmbreeScene::embree_ray(ray, m.centre, t_min, t_max);
    rtcOccluded1(m.embree.scene(), &q.embree, &r);
    if (r.tfar == -kInfF) return true;
  }
  return m.other && m.other->any(ray, t_min, t_max);
}

Aabb LeafTracer::bounds() const {
  Aabb b = impl_->bounds;
  if (impl_->other) grow(b, impl_->other->bounds());
  return b;
}

size_t LeafTracer::memory_bytes() const {
  const LeafMesh& l = impl_->leaves;
  return (impl_->other ? impl_->other->memory_bytes() : 0) + impl_->embree.memory_bytes() +
         l.positions.capacity() * sizeof(glm::dvec3) + l.uvs.capacity() * sizeof(glm::dvec2) + l.indices.capacity() * sizeof(uint32_t) +
         l.triangle_leaf.capacity() * sizeof(uint32_t) + l.leaves.capacity() * sizeof(LeafRef);
}

std::string LeafTracer::describe() const {
  const LeafMesh& l = impl_->leaves;
  return (impl_->other ? impl_->other->describe() + ", " : std::string()) + std::to_string(l.leaves.size()) +
         " leaves (" + std::to_string(l.triangle_count()) + " Embree triangles)";
}

const LeafMesh& LeafTracer::leaves() const { return impl_->leaves; }
const SceneTracer* LeafTracer::other() const { return impl_->other.get(); }

}  // namespace sylva
