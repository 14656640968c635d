// surface.h — what a ray finds in a scene, whatever geometry stands behind it: the
// analytic frusta (with or without relief, frustum_tracer.h) or a tessellated mesh
// (mesh_accel.h). The CPU renderer (render_cpu.h) shades a SurfaceHit and never looks at
// the geometry itself, so every geometry is shaded, textured and measured identically.
//
// Units and frames: world space, metres, Y up, doubles. t is in units of the ray's
// direction (hit point = origin + t·direction). Texture parametrisation as skin.h: u in
// turns around the axis (u_offset and twist applied), v_m in metres of arc length along
// the chain; on a leaf (is_leaf) u, v_m are its texture coordinates instead, both in
// [0, 1] (leaf_mesh.h leaf_uvs). Normals are unit and point out of the solid.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <limits>
#include <string>

#include "core/geometry/ray_frustum.h"
#include "core/util/bounds.h"

namespace sylva {

struct SurfaceHit {
  double t = std::numeric_limits<double>::infinity();  // +inf: no hit
  glm::dvec3 position{0, 0, 0};          // origin + t·direction
  glm::dvec3 geometric_normal{0, 0, 0};  // unit, outward: the surface that was hit
  glm::dvec3 shading_normal{0, 0, 0};    // unit, outward: eq. 8 / interpolated / relief
  double u = 0;                          // turns
  double v_m = 0;                        // metres of arc length
  glm::dvec3 dp_du{0, 0, 0};             // ∂position/∂u, metres per turn (texture footprint)
  glm::dvec3 dp_dv{0, 0, 0};             // ∂position/∂v_m, metres per metre
  uint32_t plant = 0;                    // index into Scene::plants
  uint32_t chain = 0;                    // chain of the plant's skeleton
  uint32_t segment = 0;                  // segment (knuckle: joint) index in the chain
  uint32_t material = 0;                 // material index of the segment
  uint32_t frustum = 0;                  // index into SceneGeometry::frusta (a leaf: none, 0)
  uint32_t leaf = kNoLeaf;               // a leaf hit: index into the plant's Skeleton::leaves
  // A crotch fillet's hit (crotch.h, docs/joints.md): its colour is the mix of two
  // textures, this hit's (material, u, v_m) with weight `blend` and the other group's
  // (material_other, u_other, v_m_other) with 1 − blend. 1 on every other surface.
  double blend = 1;
  double u_other = 0, v_m_other = 0;
  uint32_t material_other = 0;

  static constexpr uint32_t kNoLeaf = 0xFFFFFFFFu;
  bool is_leaf() const { return leaf != kNoLeaf; }

  bool hit() const { return t < std::numeric_limits<double>::infinity(); }
};

// A scene's geometry as the renderer sees it. Implementations are thread-safe for
// concurrent queries. A ray origin inside a solid finds the surface from inside.
class SceneTracer {
 public:
  virtual ~SceneTracer() = default;
  // The nearest surface with t_min < t < t_max, fully described.
  virtual SurfaceHit nearest(const Ray& ray, double t_min, double t_max) const = 0;
  // Whether any surface lies at t_min < t < t_max (shadow rays).
  virtual bool any(const Ray& ray, double t_min, double t_max) const = 0;
  // A box holding every surface (empty_box() when there is none): a ray that misses it
  // hits nothing (the fog's shadow rays start only where theirs meet it, docs/fog.md).
  virtual Aabb bounds() const = 0;
  // Bytes held by the geometry and its acceleration structure.
  virtual size_t memory_bytes() const = 0;
  // One line for --verbose, e.g. "Embree user geometry, 17468 frusta".
  virtual std::string describe() const = 0;
};

}  // namespace sylva
