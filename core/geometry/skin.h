// skin.h — skinning: a skeleton (skeleton.h) becomes conical frusta (frustum_shape.h),
// Bhagvat et al. 2009, sec. 2.1–2.4 and 2.6, plus the relief shell of sec. 3.
//
// Units and frames: world space, metres, Y up, doubles. u is in turns ([0,1) around the
// axis), v is either the 0..1 ratio between the two cutting planes or arc length in metres
// along the chain (v_m). Angles in names carry their unit (_deg, _rad).
//
// Preconditions: the skeleton satisfies validate_skeleton (finite positions, radii >= 0,
// parents before children). Violations are internal errors (asserts), not values: the
// readers at the file boundary already rejected them. Segments of zero length
// (coincident joints) are skipped and counted, never divided by.
//
// What skin_skeleton guarantees for every frustum it returns (tested):
//   G1  both plane normals satisfy dot(normal, axis) >= cos(max_tilt_deg) (the promise of
//       frustum_shape.h), and every generator line and every edge line of the bounding
//       pyramid crosses each plane with denominator dot(n, axis) + slope·dot(n, dir) >=
//       kMinCrossingDenominator — so each cut is a proper ellipse on the r >= 0 nappe;
//   G2  the cuts do not meet inside the frustum: the whole lower cut lies strictly below
//       the whole upper cut along the axis (checked on the bounding pyramid, which
//       contains the cuts, so it holds for the cone a fortiori);
//   G3  at a mitred interior joint both frusta use the identical Plane, so their cut
//       curves lie in one plane and share the major axis A–B of eq. 3–5; they coincide
//       exactly for equal slopes and within seam_error otherwise; the minor-axis fit
//       (fit_minor_axis, the smooth skin's) makes them coincide where it finds a radius,
//       and a continuation is mitred onto its parent's end only where it does;
//   G4  no NaN or infinity for any joint angle, antiparallel segments included.
//
// Sharp bends (the paper leaves intersecting caps unhandled). Each interior joint is
// first mitred: the medial-plane normal is clamped, in the bend plane, into the interval
// of normals whose tilt against both axes is within max_tilt_deg minus the cone's half
// angle. If that interval is empty (bend > 2·tilt, e.g. 135°, 179°, 180°) or a segment
// would violate G1/G2 (short fat segments between bends), the joint is SPLIT: both legs
// end in perpendicular planes with flat caps (closed solids) and a "knuckle" — a ball of
// the joint radius built of knuckle_frusta stacked frusta along the bend-plane normal,
// profile circumscribed about the ball, parallel perpendicular cuts, tips at the poles —
// is added around the joint. Proof sketch of watertightness: every frustum is either
// closed (caps) or glued to its neighbour along one shared cut curve (G3), and G1/G2 make
// every frustum a proper band between two disjoint closed curves; a union of closed
// solids is closed, so the union has no hole. The ball contains both cap discs (they
// are great discs of it) and the outer wedge between the legs, so no gap is visible;
// nothing extends beyond the ball of radius r/cos(pi/2k) around the joint, so no spike.
// A centre-line elbow (extra segments cutting the corner) was rejected: at 179° the two
// legs are 1° apart, an elbow whose own bends are within the limit needs a U-turn at
// least 2r wide, i.e. legs of length >= r/tan(0.5°) ≈ 115 r, which plants do not have.
// Splitting is sufficient, not minimal: an S-bend may be split where a tighter test
// (per generator instead of slab) would have let it be mitred.
//
// Joints between chains and rounded bends (docs/joints.md) change the frusta, never the
// skeleton: a rounded bend replaces the corner at a joint by an arc of short frusta (each
// still a segment of its original segment: `segment` names that segment's lower joint),
// a collar splits a lateral's first segment in two, and a chain end that carries children
// gets a knuckle ball. The guarantees G1–G4 hold for all of them (the same construction).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <vector>

#include "core/geometry/frustum_shape.h"
#include "core/geometry/skeleton.h"
#include "core/util/diagnostic.h"
#include "core/util/progress.h"

namespace sylva {

// Smallest accepted dot(n, axis) + slope·dot(n, dir) for a cut (see G1): keeps v, cut
// points and the ray caster's plane tests away from a division by ~0.
inline constexpr double kMinCrossingDenominator = 0.1;

// How surface_normal shades a point.
enum class NormalMode : uint8_t {
  interpolated,  // eq. 8: C0 across joints (smooth shading)
  exact,         // the cone's own normal, ∝ ê − slope·axis (facetted at joints)
};

// What a frustum models.
enum class FrustumKind : uint8_t {
  segment,  // one segment of a chain (joint i to joint i+1)
  knuckle,  // part of the ball closing a split (sharp) joint
};

// How chains meet (docs/spec/scene.md "Skin"): the scene's and each plant's `skin` key and
// `--skin` on render, export and studio.
enum class SkinStyle : uint8_t {
  smooth,  // collars where laterals leave, domes on chain ends that carry children, rounded bends
  paper,   // Bhagvat et al. 2009, sec. 2, as published: mitres, plain capped laterals, flat ends
};
inline constexpr const char* skin_style_name(SkinStyle s) { return s == SkinStyle::paper ? "paper" : "smooth"; }
// "smooth" or "paper" (exactly); none for anything else.
std::optional<SkinStyle> parse_skin_style(std::string_view text);

// Options of skin_skeleton.
struct SkinOptions {
  // Sec. 2.2's iterative fit of the new cone's base radius at a mitre (within a chain and
  // where a continuation meets its parent's end), so that the two elliptical cuts share
  // their minor axis as well as their major one and coincide (G3). The smooth skin fits:
  // without it a mitre between unequal slopes leaves a crack (0.71 mm at the crown
  // close-up's trunk end, through which a collar inside was seen; up to 5 cm at the elm's
  // twig tips, docs/joints.md); the paper's skin does not ("in practice we found this
  // extra fitting step to be unnecessary").
  bool fit_minor_axis = true;
  double fit_tolerance = 1e-12;   // fit stops when |b2 − b1| <= tolerance · joint radius
  int fit_max_iterations = 50;    // secant steps before the fit gives up (keeps radius)
  double max_tilt_deg = 60;       // (0, 80]: largest angle between a plane normal and axis
  double twist_rad_per_m = 0;     // u turns by this many radians per metre of arc length
  int knuckle_frusta = 8;         // >= 2: frusta per knuckle ball at a split joint
  // Joints (docs/joints.md). A lateral's first segment gets a collar: it starts on its
  // parent's axis flared to collar_flare × its radius where its axis leaves the parent
  // (at most 0.9 of the parent's radius there, so the flare stays inside the parent;
  // none for a lateral under a quarter of its parent's radius); a chain whose last joint
  // carries children ends in a dome of knuckle_frusta / 2 frusta inscribed in the ball of
  // its end radius instead of a flat cap, and the child most in line with it (within 45°)
  // starts at that radius.
  bool collars = true;
  double collar_flare = 1.3;        // >= 1: collar radius / branch radius at the surface
  double round_bends_over_deg = 20; // bends sharper than this are rounded by an arc ...
  double round_piece_deg = 10;      // ... of pieces that each turn at most this much
  // Blended crotches (crotch.h, docs/joints.md "Crotches"): a fillet where each lateral
  // leaves its parent, marched by the CPU ray caster, drawn as triangles by GL and the
  // mesh paths — in a view, only those at least kFilletMinPixels wide (GeometryOptions::
  // cull). The smooth skin's; the frusta are the same either way.
  bool blend_crotches = true;

  // These options with the joints of `style`: smooth keeps them; paper (sec. 2 as
  // published: laterals start with a plain capped cylinder, chain ends are flat caps and
  // every bend is a mitre or a split joint, what the paper's figures show) turns collars,
  // domes, rounded bends, the minor-axis fit and the crotch blend off. The other knobs
  // (tilt, knuckles, twist) are kept.
  SkinOptions styled(SkinStyle style) const {
    SkinOptions o = *this;
    if (style == SkinStyle::paper) {
      o.collars = false;
      o.round_bends_over_deg = 180;
      o.round_piece_deg = 180;
      o.fit_minor_axis = false;
      o.blend_crotches = false;
    }
    return o;
  }
  static SkinOptions paper() { return SkinOptions{}.styled(SkinStyle::paper); }
};

// One skinned frustum: the shared shape plus what renderers and texturing need.
struct Frustum {
  FrustumShape shape;              // geometry (frustum_shape.h conventions)
  uint32_t chain = 0;              // index into Skeleton::chains
  uint32_t segment = 0;            // segment: index of its lower joint in the chain;
                                   // knuckle: index of the split joint in the chain
  FrustumKind kind = FrustumKind::segment;  // segment or knuckle
  uint32_t material = 0;           // material of the segment (of its upper joint)
  int64_t parent = -1;             // frustum below it in the chain, or for a branch's
                                   // first segment the parent chain's frustum at the
                                   // attachment joint; -1 for a root chain's first
  double u_offset = 0;             // turns subtracted from the raw u (sec. 2.3), [0,1)
  double twist_rad_per_m = 0;      // copied from SkinOptions for surface_uv
  double v_lower_m = 0;            // arc length along the chain at the lower cut, metres
  double v_upper_m = 1;            // ... at the upper cut (= v_lower_m + length)
};

// The skinned skeleton: one flat array of frusta, segments of a chain in order.
struct SkinnedSkeleton {
  std::vector<Frustum> frusta;        // segments and knuckles, chain after chain
  uint64_t zero_length_skipped = 0;   // segments skipped because their joints coincide
  uint64_t split_joints = 0;          // sharp joints closed by caps + knuckle
  uint64_t clamped_joints = 0;        // mitred joints whose plane tilt was limited
};

// Skins every chain (see the guarantees above). Deterministic.
SkinnedSkeleton skin_skeleton(const Skeleton& skeleton, const SkinOptions& options = {});

// The same, telling `progress` (core/util/progress.h) the fraction of chains skinned and
// checking it every 1024 chains; cancelled: cancelled_diagnostic().
Expected<SkinnedSkeleton> skin_skeleton(const Skeleton& skeleton, const SkinOptions& options,
                                        const Progress& progress);

// Unit direction of chain `ch` at its joint `k`: the mean of the directions into and out
// of it (coincident joints skipped); none for a chain of one point.
std::optional<glm::dvec3> chain_direction_at(const Skeleton& skeleton, const Chain& ch, uint32_t k);

// For each chain, the child chain that carries its axis on (docs/joints.md
// "Continuations"): of the children attached at its last joint (which must have a radius),
// the one most in line with it, within 45°; -1 where there is none. skin_skeleton's smooth
// skin mitres that child onto its parent where it can and carries u and v on into it.
std::vector<int64_t> continuation_children(const Skeleton& skeleton);

// The fixed frame around an axis from which raw u is measured (Duff et al. 2017, "Building
// an orthonormal basis, revisited"): e0 is u = 0, e1 = axis × e0. The GPU rebuilds it
// from the axis with the same formula, so it is never stored.
struct AxisFrame {
  glm::dvec3 e0;  // unit, ⊥ axis
  glm::dvec3 e1;  // unit, axis × e0
};
AxisFrame axis_frame(const glm::dvec3& axis);  // axis must be unit

// Axial coordinate y (from base) where the generator line base + y·axis + r(y)·radial
// crosses `plane`; radial is a unit vector ⊥ axis. Safe for cylinders (no apex).
double generator_crossing_y(const FrustumShape& shape, const Plane& plane,
                            const glm::dvec3& radial);

// Point of the cut curve of `plane` on the cone at raw angle u (turns, axis_frame).
glm::dvec3 cut_point(const FrustumShape& shape, const Plane& plane, double u_raw);

// Texture coordinates of a point on (or near) the surface of a frustum.
struct SurfaceUV {
  double u = 0;    // turns in [0,1): raw angle − u_offset + twist
  double v = 0;    // eq. 7: 0 on the lower cut, 1 on the upper cut
  double v_m = 0;  // arc length: v_lower_m + v·(v_upper_m − v_lower_m), metres
};
SurfaceUV surface_uv(const Frustum& frustum, const glm::dvec3& point);

// Unit normal at a surface point: eq. 8 or the exact cone normal. Knuckle frusta always
// use the exact normal; near a tip eq. 8 falls back to the exact normal.
glm::dvec3 surface_normal(const Frustum& frustum, const glm::dvec3& point, NormalMode mode);

// Seam error at a mitred joint: the Hausdorff distance (metres) between the upper cut
// curve of `below` and the lower cut curve of `above`: `samples` points per curve, each
// distance refined by a golden-section search on the other curve. 0 up to rounding for
// equal slopes.
double seam_error(const Frustum& below, const Frustum& above, int samples = 256);

// Sec. 2.6: the obliquely cut pyramidal frustum around a shape, optionally grown by a
// relief shell. Its square cross-section circumscribes the circle of radius r(y)+shell,
// one side aligned with the tilt direction of the more tilted cutting plane.
struct BoundingPyramid {
  std::array<glm::dvec3, 8> vertices;    // 0..3 on the lower plane, 4..7 on the upper,
                                         // counter-clockwise about the axis
  std::array<Plane, 6> planes;           // outward: lower, upper, then 4 sides
  std::array<uint8_t, 36> triangles;     // 12 triangles, counter-clockwise from outside
  bool proper = false;                   // G1 and G2 hold on its 4 edge lines
};
BoundingPyramid bounding_pyramid(const FrustumShape& shape, double shell_m = 0);

// The largest distance from the axis line of any point of the shape's solid, in metres,
// grown by a relative 1e-9: the larger r(y) at the lowest and highest axial coordinates of
// its bounding pyramid's vertices, which hold the solid (r is linear in y). +inf where the
// pyramid is not proper (no bound is claimed). A ray whose line passes farther
// from the axis than this cannot hit the frustum (ray_beyond_reach, ray_frustum.h).
double frustum_radial_reach(const FrustumShape& shape);

// Worst signed distance (metres) of `point` outside the pyramid's 6 planes; <= 0 inside.
double distance_outside(const BoundingPyramid& pyramid, const glm::dvec3& point);

// G1 and G2 for a shape (what skinning enforces on every frustum).
bool cuts_are_proper(const FrustumShape& shape, double max_tilt_deg);

// The compact record the GPU ray caster uploads, 64 bytes, little-endian, std430-safe
// (4-byte fields only). Positions are relative to a per-record origin so that offsets of
// 1e6 m keep float precision: origin_hi = float(base), and base − origin_hi (at most half
// a float ulp) is stored as 3 snorm16 in units of |origin_hi|·2^-23.
//   offset type      field
//    0     float[3]  origin_hi: world base, rounded to float (metres)
//   12     float[3]  axis_scaled: top − base = axis · length (world direction, metres)
//   24     float     radius0 (metres)
//   28     float     radius1 (metres)
//   32     float     lower_axis_y: where the lower plane crosses the axis, metres from base
//   36     float     upper_axis_y: same for the upper plane (≈ length)
//   40     float     v_lower_m: arc length at the lower cut (v_upper_m = + length)
//   44     uint32    bits 0–15 u_offset (unorm16, turns), 16–23 material (clamped to
//                    255), 24 cap_lower, 25 cap_upper, 26 knuckle, 27–31 zero
//   48     uint32[4] a 128-bit field, bit i of the record is bit (i%32) of word i/32:
//                    bits 0–47 base − origin_hi as 3 snorm16 (x, y, z);
//                    bits 48–127 plane normals as 20-bit snorm components along
//                    axis_frame(axis).e0 and .e1: lower e0, lower e1, upper e0, upper e1;
//                    the axial component is +sqrt(1 − a² − b²) (>= cos(max tilt)).
struct GpuSegment {
  float origin_hi[3];
  float axis_scaled[3];
  float radius0;
  float radius1;
  float lower_axis_y;
  float upper_axis_y;
  float v_lower_m;
  uint32_t meta;
  uint32_t bits[4];
};
static_assert(sizeof(GpuSegment) <= 64, "GpuSegment must stay within 64 bytes");
static_assert(sizeof(GpuSegment) == 64, "the layout above documents 64 bytes");

// Packs a frustum into its GPU record (float precision, see the layout).
GpuSegment pack_gpu_segment(const Frustum& frustum);

// What the GPU reads back from a record, in double (the reference for the shader).
struct UnpackedGpuSegment {
  FrustumShape shape;   // base, axis, length, radii, planes, caps
  double u_offset = 0;  // turns
  double v_lower_m = 0; // metres
  uint32_t material = 0;
  bool knuckle = false;
};
UnpackedGpuSegment unpack_gpu_segment(const GpuSegment& record);

}  // namespace sylva
