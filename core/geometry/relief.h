// relief.h — relief mapping of one conical frustum (Bhagvat et al. 2009, sec. 3, eq. 11–12): a height
// field lifts the surface of a skinned frustum (skin.h) into a shell of thickness d, and a
// ray is marched through that shell, uniform steps then bisection (Policarpo et al. 2005).
//
// The geometry, in the frustum's frame (axial coordinate y from base, distance from the
// axis ρ, r(y) = radius0 + slope·y the inner cone of frustum_shape.h):
//   shell  = the frustum with radii radius0 + d0 and radius1 + d1: same cutting planes,
//            same caps, apex-free like the inner one (`relief_shell`), where
//            d_end = min(d, max_depth_per_radius · radius_end) and d the bark's
//            relief_depth. Where both ends are thick enough (radius >= d /
//            max_depth_per_radius: every trunk and limb) d0 = d1 = d and the shell is the
//            paper's, parallel to the inner cone; a thin twig or needle gets a shell at most
//            max_depth_per_radius of its radius thick (a 1 cm bark relief on a 1.5 mm
//            needle would make it seven times thicker), tapering to 0 at a tip. Frusta
//            meeting at a joint share its radius, so their shells meet there too.
//            d(y) = d0 + (d1 − d0)·y/length is the shell's thickness at y.
//   solid  = { p between the two planes : ρ(p) <= r(y) + d(y)·H(s, t) }, H in [0, 1]
//            the height field (1 = the outer shell, 0 = the inner frustum), read at
//            s = u·u_repeat, t = v_m·v_per_metre (texture.h's texture coordinates).
// The shell solid (single-nappe solid cone ∩ slab) is convex, so a ray meets it in one
// interval (`frustum_solid_interval`). Along that interval the ray's relief height is
//   w = (ρ − r(y)) / d(y)                                               (eq. 11–12)
// in the plane y = P_y (the paper's (d − r_i)/(r_o − r_i), r_o − r_i = d(y)), u is
// exact (the angle around the axis, u_offset and twist applied as skin.h's surface_uv),
// and v_m is either interpolated linearly between the interval's ends (the paper; exact
// for parallel planes) or exact (ReliefOptions::exact_v: eq. 7 on the cone of constant w
// through the sample, radius r(y) + w·d(y)). A sample is inside the solid iff w <= H.
// exact_v is the default: with linear v the relief depends on the ray (v at a point
// follows that ray's entry and exit), so a shadow ray leaving a hit sees a surface shifted
// along v and shadows itself in speckles wherever the planes are tilted (the bent arms of
// the saguaro preset); exact v makes the relief one surface. It costs two plane crossings
// per sample, a few percent of a render; linear v stays as the paper's (GPU) option.
//
// Marching: linear_steps uniform steps over the interval (linear_steps + 1 samples, the
// ends included), then bisection_steps halvings of the first bracket [last outside, first
// inside]. The hit is the bracket's outside end (so a shadow ray leaving the hit starts
// outside the solid; it is within (t_exit − t_enter) / (linear_steps·2^bisection_steps)
// of the true crossing along the ray, for a crossing the uniform steps did not jump over).
// A first sample already inside is a hit on the boundary the ray entered by, exactly: on
// the outer shell (where H = 1) with the relief normal; on a capped plane with the plane's
// normal; on an uncapped plane (an interior joint, where the neighbouring frustum's solid
// continues) with the relief normal, so that rounding differences between neighbours
// cannot show up as plane-shaded specks along joints. A ray whose origin lies inside the
// shell (t_min inside the interval) and inside the solid looks for the way out instead
// (from_inside), as intersect_frustum does for a solid's inside.
//
// Normal of a side hit: the base normal n0 (eq. 8 for shading; as geometric normal the
// exact normal of the constant-w cone through the hit, ∝ ê − k_w·axis with
// k_w = slope + w·d'(y)) perturbed by the gradient of the displacement h = d(y)·H over
// the local surface frame (bump mapping of a displaced surface, Blinn 1978):
//   n = normalize(n0 − ∂h/∂a·T_u − ∂h/∂b·T_v),
//   ∂h/∂a = d(y)·H_s·u_repeat / (2π ρ)                   (a: arc around, metres; ∂a/∂s = 2πρ/u_repeat)
//   ∂h/∂b = d(y)·(H_t·v_per_metre + H_s·u_repeat·twist/(2π))   (b: arc along, metres ≈ v_m)
// with T_u = axis × ê (direction of increasing u), T_v = normalize(axis + k_w·ê) (the
// generator, increasing v), ρ the hit's distance from the axis, and H_s, H_t central
// differences of H. "≈ v_m": one metre along the generator is taken as one metre of v_m
// (exact for parallel planes and slope 0), as frustum_tracer.h's dp_dv does.
// The differences are taken over the larger of two gradient steps (±1 texel, HeightField)
// and the ray's footprint at the hit, pixel_spread_rad × distance travelled, converted to
// texture units (w_s = footprint·u_repeat/(2πρ), w_t = footprint·v_per_metre), of H
// filtered over that footprint: H_s = (H_f(s + w_s/2) − H_f(s − w_s/2))/w_s, the gradient
// of the box-filtered height; a footprint of half a repeat or more in s or t leaves the
// base normal unperturbed (the relief is averaged away). The marching always reads the
// finest level (the relief's geometry is one surface for every ray, primary and shadow
// alike); only the shading normal is filtered, so texel-scale roughness far smaller than
// a pixel does not sparkle (as a MIP-mapped normal map would not), while the ribs and
// furrows a pixel resolves keep their slope.
//
// Fading (ReliefFade, optional): a smooth factor f(p) in [0, 1] of the world point scales
// the height field, so the solid is { ρ <= r(y) + d(y)·f(p)·H } inside the same shell: 1
// leaves the relief as it is, 0 is the inner frustum. The blended crotches fade the relief
// into their fillets with it (crotch.h crotch_relief_fade). The normal's perturbation is
// that of the displacement d·f·H: the differences of H above scaled by f, plus H times
// f's own gradient along the two tangents (central differences of f over fade_step_m).
//
// Units: metres, t in units of the ray's direction. Thread-safe (pure functions; the
// HeightField must be safe for concurrent calls).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>
#include <glm/vec3.hpp>

#include "core/geometry/ray_frustum.h"
#include "core/geometry/skin.h"

namespace sylva {

// How the marcher samples (sec. 3).
struct ReliefOptions {
  int linear_steps = 32;     // >= 1: uniform steps over the shell interval
  int bisection_steps = 8;   // >= 0: halvings of the first bracket
  bool exact_v = true;       // v_m by eq. 7 on each sample's constant-w cone (else linear
                             // between the interval's ends, the paper; see above)
  double max_depth_per_radius = 0.5;  // > 0: shell thickness <= this · radius (see
                                      // above); infinity: the paper's constant shell
  double pixel_spread_rad = 0;  // >= 0: footprint of a ray per metre travelled (a pixel's
                                // angle); widens the normal's differences, see above
};

// A height field H(s, t) in [0, 1], periodic with period 1 in s and t. The renderer's is
// a texture lookup (texture.h); tests pass analytic fields. Must be thread-safe.
class HeightField {
 public:
  virtual ~HeightField() = default;
  // H at texture coordinates (s, t); values outside [0, 1] are clamped by the marcher.
  virtual double height(double s, double t) const = 0;
  // H averaged over a footprint about width_s × width_t (texture units) around (s, t),
  // for the shading normal of a distant hit (default: the point value).
  virtual double filtered_height(double s, double t, double width_s, double width_t) const {
    (void)width_s, (void)width_t;
    return height(s, t);
  }
  // Step of the central differences for the normal, in s and in t (a texel for an image).
  virtual double gradient_step_s() const = 0;
  virtual double gradient_step_t() const = 0;
};

// An image's height field at its finest level: channel 0 of width × height texels,
// row-major from row 0 (t = 0), sampled bilinearly and periodically as OpenImageIO's
// MipModeNoMIP + InterpBilinear lookups (texel i's centre at s = (i + 0.5)/width), in
// double. The CPU's relief marcher (core/cpu/texture.h) and the GS+R displacement on both
// backends read it.
struct HeightTexels {
  int width = 0, height = 0;  // >= 1 each once filled
  std::vector<float> texels;  // width · height values, H in [0, 1]
  // H at (s, t), periodic with period 1 in both.
  double at(double s, double t) const;
  size_t bytes() const { return texels.size() * sizeof(float); }
};

inline double HeightTexels::at(double s, double t) const {
  const double x = (s - std::floor(s)) * width - 0.5, y = (t - std::floor(t)) * height - 0.5;
  const double x0 = std::floor(x), y0 = std::floor(y);
  const double fx = x - x0, fy = y - y0;
  auto wrap = [](int i, int n) { return i < 0 ? i + n : (i >= n ? i - n : i); };
  const int i0 = wrap(static_cast<int>(x0), width), i1 = wrap(i0 + 1, width);
  const int j0 = wrap(static_cast<int>(y0), height), j1 = wrap(j0 + 1, height);
  const float* row0 = &texels[static_cast<size_t>(j0) * width];
  const float* row1 = &texels[static_cast<size_t>(j1) * width];
  const double top = row0[i0] + fx * (row0[i1] - row0[i0]);
  const double bottom = row1[i0] + fx * (row1[i1] - row1[i0]);
  return top + fy * (bottom - top);
}

// A factor in [0, 1] the height field is multiplied by at a world point (see the header
// comment); continuous in p, smooth where the normal is taken. Must be thread-safe.
class ReliefFade {
 public:
  virtual ~ReliefFade() = default;
  virtual double scale(const glm::dvec3& world) const = 0;
  // Step of the central differences that give the fade's gradient for the normal, metres.
  virtual double fade_step_m() const = 0;
};

// What the relief of one frustum needs besides its shape.
struct ReliefMap {
  const HeightField* field = nullptr;  // H; not owned
  double depth_m = 0;                  // d > 0: shell thickness
  double u_repeat = 1;                 // s = u·u_repeat (u in turns)
  double v_per_metre = 1;              // t = v_m·v_per_metre (v_m in metres)
};

// The shell's thickness at the lower and upper end of `inner` (at y = 0 and y = length):
// min(depth_m, max_depth_per_radius · radius) (see the header comment).
struct ShellDepths {
  double lower_m = 0;
  double upper_m = 0;
};
ShellDepths relief_shell_depths(const FrustumShape& inner, double depth_m, double max_depth_per_radius);

// The outer shell of `inner`: radii grown by relief_shell_depths, same planes and caps.
FrustumShape relief_shell(const FrustumShape& inner, double depth_m, double max_depth_per_radius);

// Which boundary of a solid an interval end lies on.
enum class SolidBoundary : uint8_t {
  range,  // t_min or t_max: the ray starts or stops inside the solid
  side,   // the conical side (or the nappe's apex)
  lower,  // the lower cutting plane
  upper,  // the upper cutting plane
};

// The part of a ray inside a closed solid frustum.
struct SolidInterval {
  bool hit = false;          // false: the ray misses the solid in [t_min, t_max]
  double t_enter = 0;        // t_min <= t_enter <= t_exit <= t_max
  double t_exit = 0;
  SolidBoundary enter = SolidBoundary::range;
  SolidBoundary exit = SolidBoundary::range;
};

// The interval of t in [t_min, t_max] where origin + t·direction lies in the solid
// { between the planes, distance from the axis <= r(y), r(y) >= 0 } of `shape` (caps or
// not: the solid is closed). Apex-free, re-centred origin and stable roots as
// intersect_frustum (ray_frustum.cpp), so its side ends agree with intersect_frustum's
// hits to the same accuracy. A shape intersect_frustum rejects gives no interval.
SolidInterval frustum_solid_interval(const Ray& ray, const FrustumShape& shape, double t_min,
                                     double t_max);

// A hit on the relief of a frustum.
struct ReliefHit {
  FrustumHit hit;                      // kind: side (relief or uncapped plane) or a cap;
                                       // normal: geometric (see the header comment)
  double u = 0;                        // turns
  double v_m = 0;                      // metres
  glm::dvec3 shading_normal{0, 0, 0};  // unit, outward
};

// The nearest hit of `ray` with t_min < t < t_max on the relief solid of `frustum` under
// `map` (map.field non-null, map.depth_m > 0), its height scaled by `fade` where one is
// given. With describe false only hit.kind and hit.t are set (shadow rays).
ReliefHit intersect_relief(const Ray& ray, const Frustum& frustum, const ReliefMap& map,
                           const ReliefOptions& options, double t_min, double t_max,
                           bool describe = true, const ReliefFade* fade = nullptr);

}  // namespace sylva
