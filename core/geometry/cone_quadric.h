// cone_quadric.h — the ray–cone quadratic of Bhagvat et al. 2009 sec. 2.5 (eq. 9–10) in its
// apex-free form, written once for everything that solves it: the frustum intersector
// (ray_frustum.cpp, in double and in its float twin), the relief shell's solid interval
// (relief.cpp, through solid_bounds.h) and the shadow cones' interval
// (core/light/shadow_cones.cpp, the same). The GLSL twin is shaders/ray_frustum.glsl's
// cone_quadric: same name, same fields, same order of operations.
//
// Eq. 9–10 put the ray E + tD into the cone of eq. 1, h'²(x² + z²) = r1²(y − h')², with
// the apex height h' = r1·h/(r1 − r2) of eq. 2, and solve a t² + b t + c = 0 with
//   a = Dx² + Dz² − Dy²(r1/h')²,  b = 2(Ex Dx + Ez Dz − Dy(Ey − h')(r1/h')²),
//   c = Ex² + Ez² − (Ey − h')²(r1/h')².
// With slope k = (r2 − r1)/h = −r1/h' and ρ = r1 + k·Ey the radius at the origin's height:
//   (Ey − h')·(r1/h') = −ρ  and  (r1/h')² = k², so
//   a = D⊥·D⊥ − k²Dy²,  b = 2(E⊥·D⊥ − k ρ Dy),  c = E⊥·E⊥ − ρ²,
// the apex-free form used here (A, B = 2·half_b, C) for the cone r(y) = r0 + k·y: it never
// forms h' (infinite for a cylinder), and it is the same equation for the base radius
// r0 = r1 of the paper.
//
// Internal to core/: not part of any stage's public contract.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace sylva {

// f(t) = A·t² + 2·half_b·t + C for the ray w + t·d and the cone |p⊥| = r(y), with
// f <= 0 inside the double cone (both nappes: which one a root lies on is the caller's
// test, r(y) >= 0).
template <class Real>
struct ConeQuadric {
  Real A;             // |d⊥|² − (k·dy)²: 0 for a ray parallel to a generator line
  Real half_b;        // w⊥·d⊥ − ρ·k·dy
  Real C;             // |w⊥|² − ρ²: < 0 with the origin inside the cone
  Real radial_sq;     // |ρ·d⊥ − k·dy·w⊥|²
  Real moment_sq;     // |w⊥ × d⊥|²
  Real discriminant;  // D' = half_b² − A·C, computed as radial_sq − moment_sq (see below)
};

// The quadric of the ray whose origin and direction have the parts `origin_perp` (w⊥) and
// `dir_perp` (d⊥) perpendicular to the cone's axis, for a cone whose radius is `rho` (ρ)
// at the origin's height and grows by `slope_dir_y` (k·dy) per unit of t. Any units, as
// long as they agree; nothing is checked and no root is taken (NaN in, NaN out).
//
// D' = half_b² − A·C expanded and regrouped: the terms ρ²k²dy² cancel algebraically,
//   D' = |ρ·d⊥ − k·dy·w⊥|² − |w⊥ × d⊥|²,
// so a ray through or near the apex (where half_b² and A·C are both ≈ ρ²k²dy²) keeps its
// small discriminant to full relative precision instead of sqrt(ε). radial_sq and
// moment_sq stay in the result: their sum is the scale of the discriminant's rounding.
// The roots are the callers': the stable pair q = −(half_b + sign(half_b)·√D'), q/A and
// C/q, with what a tangent (D' = 0) or a ray along a generator (A = 0) means to each
// (ray_frustum.cpp's frustum_side_roots for surface hits, solid_bounds.h's inside_cone
// for solid intervals).
template <class Real>
ConeQuadric<Real> cone_quadric(const glm::vec<3, Real>& origin_perp, const glm::vec<3, Real>& dir_perp,
                               Real rho, Real slope_dir_y) {
  ConeQuadric<Real> f;
  f.A = glm::dot(dir_perp, dir_perp) - slope_dir_y * slope_dir_y;
  f.half_b = glm::dot(origin_perp, dir_perp) - rho * slope_dir_y;
  f.C = glm::dot(origin_perp, origin_perp) - rho * rho;
  const glm::vec<3, Real> radial_term = rho * dir_perp - slope_dir_y * origin_perp;
  const glm::vec<3, Real> moment = glm::cross(origin_perp, dir_perp);
  f.radial_sq = glm::dot(radial_term, radial_term);
  f.moment_sq = glm::dot(moment, moment);
  f.discriminant = f.radial_sq - f.moment_sq;
  return f;
}

}  // namespace sylva
