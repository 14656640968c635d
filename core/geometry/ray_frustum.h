// ray_frustum.h — ray against one conical frustum (Bhagvat et al. 2009, sec. 2.5, eq. 9–10), made
// robust: the CPU reference in double, and a float twin that the GLSL ray caster mirrors
// function for function. The shape is the contract of core/geometry/frustum_shape.h, used exactly.
//
// Units: metres; t is in units of the ray's direction (the hit point is origin + t·direction,
// the direction need not be unit). Normals are unit and always point out of the solid; a hit
// from inside has dot(direction, normal) > 0 and says so in `from_inside`.
//
// Accuracy (docs/accuracy.md, measured by tests/geometry/ray_frustum_test.cpp against a long
// double reference): double t within 1e-9 of the distance scale max(|t|·|direction|,
// length + max radius), normals within 1e-6 rad, away from the grazing band (rays within
// ~1e-6 rad of tangent to the surface, hits within ~1e-9 of an edge).
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>

#include "core/geometry/frustum_shape.h"

namespace sylva {

struct Ray {
  glm::dvec3 origin{0, 0, 0};     // metres, world space
  glm::dvec3 direction{0, 0, 1};  // non-zero, need not be unit
};

// What part of the frustum a ray hit.
enum class FrustumHitKind : uint8_t {
  none = 0,       // no hit in (t_min, t_max)
  side = 1,       // the conical side surface
  lower_cap = 2,  // the flat disc on the lower plane (only where shape.cap_lower)
  upper_cap = 3,  // the flat disc on the upper plane (only where shape.cap_upper)
};

struct FrustumHit {
  FrustumHitKind kind = FrustumHitKind::none;  // none: every other field is default
  double t = 0;                 // hit point = origin + t·direction, t_min < t < t_max
  glm::dvec3 normal{0, 0, 0};   // unit, outward: side ∝ ê − slope·axis, caps ∓ plane normal
  double y = 0;                 // axial coordinate of the hit (0 at base, length at top)
  glm::dvec3 radial{0, 0, 0};   // ê: unit, ⊥ axis, from the axis toward the hit (any ⊥ on it)
  bool from_inside = false;     // the ray meets the surface from inside the solid

  bool hit() const { return kind != FrustumHitKind::none; }
};

// nullptr when `shape` satisfies frustum_shape.h, else what is wrong with it (length not
// > 0, negative or non-finite radius, axis or plane normal not unit, a plane normal with
// dot(normal, axis) <= 0, a cap on a plane that is not perpendicular to the axis).
const char* frustum_shape_error(const FrustumShape& shape);

// The nearest hit of `ray` with the closed surface of `shape` (side between the planes on
// the nappe where r(y) >= 0, plus the caps that exist) with t_min < t < t_max. A shape
// whose length is not > 0 or whose radii are negative or non-finite is rejected: the
// result is a miss (never NaN). A ray lying exactly in the side surface (along a
// generator line) has no side hit; a ray tangent to it hits once.
FrustumHit intersect_frustum(const Ray& ray, const FrustumShape& shape, double t_min,
                             double t_max);

// True when the line of `ray` passes farther than `reach_m` from the axis line of `shape`
// (reach_m: frustum_radial_reach, skin.h), so that the ray cannot hit it: a test of a few
// products that accelerators run before intersect_frustum. Conservative: the rounding of
// the triple product is allowed for (a relative 1e-12 of |origin − base|·|direction|), so
// it never rejects a ray that intersect_frustum hits. A ray
// parallel to the axis is never rejected; reach_m = +inf rejects nothing.
bool ray_beyond_reach(const Ray& ray, const FrustumShape& shape, double reach_m);

// ---- Float twin: the GLSL ray caster, line by line --------------------------------------

// A ray in the frame of a FrustumShapeF (relative to that shape's per-segment origin).
struct RayF {
  glm::vec3 origin{0, 0, 0};
  glm::vec3 direction{0, 0, 1};
};

// A FrustumShape in float, relative to a per-segment origin (the GPU record stores floats
// relative to the segment base). slope is precomputed in double before rounding; plane
// offsets are relative to the per-segment origin.
struct FrustumShapeF {
  glm::vec3 base{0, 0, 0};
  glm::vec3 axis{0, 1, 0};
  float length = 1;
  float radius0 = 0.1f;
  float slope = 0;
  glm::vec3 lower_normal{0, 1, 0};
  float lower_offset = 0;
  glm::vec3 upper_normal{0, 1, 0};
  float upper_offset = 1;
  uint32_t caps = 0;  // bit 0: lower cap, bit 1: upper cap
};

struct FrustumHitF {
  uint32_t kind = 0;  // a FrustumHitKind value
  float t = 0;
  glm::vec3 normal{0, 0, 0};
  float y = 0;
  glm::vec3 radial{0, 0, 0};
};

// `shape` relative to `segment_origin` (usually shape.base), rounded to float once; the
// plane offsets are shifted in compensated double so nothing is lost before rounding.
FrustumShapeF to_float_shape(const FrustumShape& shape, const glm::dvec3& segment_origin);

// `ray` relative to `segment_origin`, rounded to float once (origin − segment_origin in
// double first). t is unchanged by this change of frame.
RayF to_float_ray(const Ray& ray, const glm::dvec3& segment_origin);

// intersect_frustum in float, same algorithm and order of operations as the GLSL. Its
// error is float's: ~1e-6 of the distance scale for well-conditioned hits, growing as
// 1/|cos(incidence)| toward grazing.
FrustumHitF intersect_frustum_f(const RayF& ray, const FrustumShapeF& shape, float t_min,
                                float t_max);

}  // namespace sylva
