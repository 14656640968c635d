// frustum_shape.h — the geometry of one skinned segment: a conical frustum in apex-free
// form, cut by two planes (Bhagvat et al. 2009, sec. 2.1–2.2). Shared by skinning (which makes
// them), the ray casters (CPU double, CPU float twin, GLSL) and the tessellator.
//
// Frame and units: world space, metres, Y up. The segment runs from `base` along the
// unit `axis` for `length` metres. Its radius at axial coordinate y (0 at base, `length`
// at the top joint) is r(y) = radius0 + slope·y, slope = (radius1 − radius0) / length:
// a cylinder is slope 0, and no apex height r1·h/(r1 − r2) is ever formed.
//
// Cutting planes: the surface is the part of the (infinite, single-nappe where r ≥ 0)
// cone between the lower plane and the upper plane. Both plane normals are unit and point
// "up the segment" (dot(normal, axis) > 0), and a point p is between the planes iff
//     dot(lower.normal, p) >= lower.offset  and  dot(upper.normal, p) <= upper.offset.
// Skinning guarantees dot(normal, axis) >= cos(max tilt) > 0 for both planes, so every
// generator line crosses each plane exactly once.
//
// Caps: a flat disc closes the segment at a plane where the chain ends (cap_lower /
// cap_upper true; such planes are perpendicular to the axis), unless the radius there is 0.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>

namespace sylva {

struct Plane {
  glm::dvec3 normal{0, 1, 0};  // unit
  double offset = 0;           // plane: dot(normal, p) == offset
};

struct FrustumShape {
  glm::dvec3 base{0, 0, 0};  // the segment's first joint (metres)
  glm::dvec3 axis{0, 1, 0};  // unit, from base toward the second joint
  double length = 1;         // > 0, metres
  double radius0 = 0.1;      // radius at base, >= 0
  double radius1 = 0.1;      // radius at base + length·axis, >= 0
  Plane lower;               // cutting plane at the base joint
  Plane upper;               // cutting plane at the top joint
  bool cap_lower = false;    // flat cap on the lower plane (chain start, radius0 > 0)
  bool cap_upper = false;    // flat cap on the upper plane (chain end, radius1 > 0)

  double slope() const { return (radius1 - radius0) / length; }
  double radius_at(double y) const { return radius0 + slope() * y; }
};

}  // namespace sylva
