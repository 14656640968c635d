// leaf_tracer.cpp — see leaf_tracer.h.
#include "core/cpu/leaf_tracer.h"

#include <algorithm>
#include <glm/geometric.hpp>
#include <limits>

#include "core/cpu/embree_scene.h"
#include "core/cpu/embree_triangles.h"
#include "core/scene/leaf_images.h"

namespace sylva {

namespace {
constexpr float kInfF = std::numeric_limits<float>::infinity();

// The triangle query with what the leaf filter needs (TriangleQuery first: Embree hands
// the filter the context it was given).
struct LeafQuery {
  TriangleQuery triangles;
  const LeafMesh* leaves;
  const LeafImages* images;  // null: every leaf two-sided and whole
  // any(): a shadow ray, from a surface toward the light: the light runs the other way,
  // so a one-sided leaf stops it where the ray meets its back (the light its front).
  bool toward_light;
};

glm::dvec2 uv_at(const LeafMesh& m, const uint32_t* tri, const TriangleCrossing& c) {
  return (1 - c.b1 - c.b2) * m.uvs[tri[0]] + c.b1 * m.uvs[tri[1]] + c.b2 * m.uvs[tri[2]];
}

// The range filter, then the leaf's material (leaf_images.h): a one-sided leaf seen from
// its back and a cut-out's transparent texels let the ray through.
void leaf_filter(const RTCFilterFunctionNArguments* args) {
  const auto* q = reinterpret_cast<const LeafQuery*>(args->context);
  const LeafMesh& m = *q->leaves;
  for (unsigned i = 0; i < args->N; ++i) {
    if (!args->valid[i]) continue;
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    const uint32_t* tri = &m.indices[3 * static_cast<size_t>(prim)];
    const TriangleCrossing c =
        cross_triangle(q->triangles.ray, m.positions[tri[0]], m.positions[tri[1]], m.positions[tri[2]]);
    bool keep = in_query_range(c, q->triangles);
    if (keep && q->images) {
      const LeafRef& leaf = m.leaves[m.triangle_leaf[prim]];
      const double along_normal = glm::dot(q->triangles.ray.direction, leaf.normal);
      // The side the ray meets (a shadow ray runs against the light: the light meets the other).
      const uint32_t material =
          leaf.material_seen_along(q->toward_light ? -q->triangles.ray.direction : q->triangles.ray.direction);
      if (q->images->one_sided(material) && (q->toward_light ? along_normal < 0 : along_normal > 0)) keep = false;
      if (keep && q->images->has_cutout(material)) {
        const glm::dvec2 uv = uv_at(m, tri, c);
        keep = q->images->opaque(material, uv.x, uv.y);
      }
    }
    if (!keep) args->valid[i] = 0;
  }
}

}  // namespace

struct LeafTracer::Impl {
  LeafMesh leaves;
  std::shared_ptr<const LeafImages> images;  // null or empty(): plain leaves
  std::unique_ptr<SceneTracer> other;
  glm::dvec3 centre{0, 0, 0};
  Aabb bounds = empty_box();
  EmbreeScene embree{/*need_filter_functions=*/true};
};

LeafTracer::LeafTracer(LeafMesh leaves, std::unique_ptr<SceneTracer> other, std::shared_ptr<const LeafImages> images)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.leaves = std::move(leaves);
  if (images && !images->empty()) m.images = std::move(images);
  m.other = std::move(other);
  m.bounds = m.leaves.bounds();
  if (!m.leaves.empty()) {
    m.centre = 0.5 * (m.bounds.lo + m.bounds.hi);
    m.embree.attach(new_filtered_triangles(m.embree.device(), m.leaves.positions.data(), m.leaves.positions.size(),
                                           m.leaves.indices.data(), m.leaves.triangle_count(), m.centre,
                                           leaf_filter));
  }
  m.embree.commit();
}

LeafTracer::~LeafTracer() = default;

SurfaceHit LeafTracer::nearest_leaf(const Ray& ray, double t_min, double t_max) const {
  const Impl& m = *impl_;
  if (m.leaves.empty() || !(t_max > t_min)) return {};
  LeafQuery q{start_triangle_query(m.leaves.positions.data(), m.leaves.indices.data(), ray, t_min, t_max),
              &m.leaves, m.images.get(), false};
  RTCRayHit rh{};
  rh.ray = EmbreeScene::embree_ray(ray, m.centre, t_min, t_max);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(m.embree.scene(), &q.triangles.embree, &rh);
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
  const glm::dvec2 uv = uv_at(m.leaves, tri, c);
  s.u = std::clamp(uv.x, 0.0, 1.0);
  s.v_m = std::clamp(uv.y, 0.0, 1.0);
  s.plant = leaf.plant;
  s.material = leaf.material_seen_along(ray.direction);  // a double-sided leaf's back from behind
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
    LeafQuery q{start_triangle_query(m.leaves.positions.data(), m.leaves.indices.data(), ray, t_min, t_max),
                &m.leaves, m.images.get(), true};
    RTCRay r = EmbreeScene::embree_ray(ray, m.centre, t_min, t_max);
    rtcOccluded1(m.embree.scene(), &q.triangles.embree, &r);
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
const LeafImages* LeafTracer::images() const { return impl_->images.get(); }
const SceneTracer* LeafTracer::other() const { return impl_->other.get(); }

}  // namespace sylva
