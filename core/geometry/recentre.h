// recentre.h — a ray re-centred on a frustum, shared by the analytic intersector
// (ray_frustum.cpp) and the relief marcher (relief.cpp), so that both see a frustum in
// exactly the same frame. Double only: the float twin (ray_frustum.cpp's template at
// float, shaders/ray_frustum.glsl) has none, like the GPU.
//
// Internal to core/: not part of any stage's public contract.
#pragma once

#include <glm/geometric.hpp>

#include "core/geometry/frustum_shape.h"
#include "core/geometry/ray_frustum.h"
#include "core/util/compensated.h"

namespace sylva::compensated {

// plane.offset − dot(plane.normal, origin) as if in twice double precision (Ogita–Rump–
// Oishi Dot2): the plane's offset in a frame whose origin is `origin`. Plain double would
// lose ~1e-10 m at 10⁶ m, a millionth of a 0.1 mm twig.
inline double plane_offset_from(const Plane& plane, const glm::dvec3& origin) {
  Compensated sum{plane.offset, 0};
  for (int i = 0; i < 3; ++i) {
    const Compensated product = two_product(-plane.normal[i], origin[i]);
    const Compensated partial = two_sum(sum.hi, product.hi);
    sum = {partial.hi, sum.lo + (partial.lo + product.lo)};
  }
  return sum.hi + sum.lo;
}

// A ray in a frustum's frame: origin relative to the base, moved along the ray to the
// point nearest the frustum's midpoint; a parameter t of the ray is shift + t_local.
struct RecentredRay {
  glm::dvec3 origin{0, 0, 0};
  double shift = 0;
};

// Re-centres `ray` (direction non-zero) on `shape`: origin − base exactly as hi + lo, the
// shift to the point of the ray nearest the midpoint, then (origin − base) + shift·d
// compensated, so the moved origin is exact to an ulp of its own (small) size even when
// the eye is 10⁶ m away.
inline RecentredRay recentre(const Ray& ray, const FrustumShape& shape) {
  const glm::dvec3& d = ray.direction;
  Compensated relative[3];
  glm::dvec3 rough{0, 0, 0};
  for (int i = 0; i < 3; ++i) {
    relative[i] = two_sum(ray.origin[i], -shape.base[i]);
    rough[i] = relative[i].hi;
  }
  const glm::dvec3 midpoint = (0.5 * shape.length) * shape.axis;
  RecentredRay r;
  r.shift = glm::dot(midpoint - rough, d) / glm::dot(d, d);
  for (int i = 0; i < 3; ++i) {
    const Compensated step = two_product(r.shift, d[i]);
    const Compensated sum = two_sum(relative[i].hi, step.hi);
    r.origin[i] = sum.hi + (sum.lo + relative[i].lo + step.lo);
  }
  return r;
}

}  // namespace sylva::compensated
