// culling.h — which plants can affect no pixel (docs/spec/scene.md: "a plant outside the view
// frustum is not drawn"). A plant is left out when its world box lies outside the
// camera's view frustum AND its shadow cannot fall into the view; the test is
// conservative: a plant that might show, directly or by its shadow, is always kept.
//
// The plant's box (plant_box): skeleton_bounds of the placed skeleton (joints grown by
// their radii), each joint grown further so the box contains the skinned surface. A
// frustum's surface is ruled by generator segments between its two cut curves, so it lies
// in their convex hull; it is enough that every cut curve lies in the box. A cut plane
// passes through its joint, tilted by θ <= max_tilt_deg; on a cone of slope s a cut point
// lies r_joint·sqrt(sin²θ·c² + cos²θ)/D <= r_joint/D from the joint (c: the cosine
// between the generator's radial and the tilt direction), D = cos θ + s·sin θ·c >=
// max(cos θ_max − |s|·sin θ_max, kMinCrossingDenominator) (G1 of skin.h). A knuckle ball
// reaches r/cos(π/2k). A relief or displacement adds its depth.
//
// The shadow: only plants cast shadows (render_cpu.h), onto anything along −sun from
// them, and an opaque ground ends every shadow. So the shadow of the box lies in the box
// swept along −l (l: unit direction toward the sun) down to the ground plane, which is
// inside the union of the box and its projection onto the ground along l (shadow_box).
// A sun disc of angular radius α shadows along every direction within α of l: the
// projection is grown by the horizontal spread of those directions. A sun at or below
// the horizon (its disc reaching it) casts shadows without end: the box swept along −l'
// for ever is outside a view plane of inward normal n when its corners are and
// dot(n, −l) <= −sin α (no direction of the disc leads back inside). A sun of radiance 0
// casts no shadow.
//
// The view: the four side planes of the pinhole frustum through the image's corners (the
// rays of camera_ray, render_cpu.h) and the plane through the eye facing forward (the
// near plane: nothing behind the eye is seen). A box is outside when all 8 corners lie
// strictly outside one of these planes (a separating plane).
#pragma once

#include <optional>

#include "core/util/bounds.h"
#include "core/scene/scene.h"
#include "core/geometry/skin.h"

namespace sylva {

// The view frustum's five planes as inward half-spaces dot(normal, p) >= offset.
struct ViewFrustum {
  Plane planes[5];  // left, right, bottom, top, near
};
ViewFrustum view_frustum(const Scene& scene);

// A conservative world box of the skinned surface of `placed` (a placed skeleton:
// place_plant) and its leaves, grown by `relief_m` (relief or displacement depth, metres).
Aabb plant_box(const Skeleton& placed, const SkinOptions& skin, double relief_m = 0);

// The box containing every point the plant in `box` can shadow under `scene`'s sun and
// ground; nullopt when that region is unbounded (sun at the horizon). `box` itself when the
// sun is off.
std::optional<Aabb> shadow_box(const Scene& scene, const Aabb& box);

// The most pixels a radian of view spans anywhere in `scene`'s image (at its corners, where
// a pinhole's pixels subtend the least angle): f·(1 + tan²θ) for the focal length
// f = (height / 2) / tan(fov_y / 2) in pixels and θ the corner's angle off the axis. A
// feature of angular size a covers at most a times this many pixels.
double pixels_per_radian(const Scene& scene);

// Whether `box` lies outside `view` (one plane separates it from the view).
bool outside_view(const ViewFrustum& view, const Aabb& box);

// Whether a plant occupying `box` can affect no pixel of `scene`: outside the view and
// casting no shadow into it.
bool plant_is_culled(const Scene& scene, const ViewFrustum& view, const Aabb& box);

}  // namespace sylva
