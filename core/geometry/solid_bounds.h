// solid_bounds.h — the interval of a ray parameter t inside a conical solid, built up one
// constraint at a time: what relief.cpp's frustum_solid_interval and shadow_cones.cpp's
// cone interval (the same algorithm in the cone's own frame) share. Internal to core/.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <utility>

#include "core/geometry/cone_quadric.h"
#include "core/geometry/relief.h"  // SolidBoundary

namespace sylva::solid_bounds {

// How Bounds::inside_cone picks the second root of the stable pair (see there).
enum class SecondRoot : uint8_t {
  by_error_bounds,    // the form with the smaller first-order error bound (relief.cpp)
  quick_then_bounds,  // C/q at once where (|w⊥|² + ρ²)·|A| <= q², the bounds elsewhere
                      // (shadow_cones.cpp, whose cone test is hot; see inside_cone)
};

// A half-line or interval bound of t with the boundary that made each end.
struct Bounds {
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  SolidBoundary lo_by = SolidBoundary::range, hi_by = SolidBoundary::range;
  void at_least(double t, SolidBoundary by) {
    if (t > lo) lo = t, lo_by = by;
  }
  void at_most(double t, SolidBoundary by) {
    if (t < hi) hi = t, hi_by = by;
  }
  bool empty() const { return !(lo <= hi); }
  // Restricts to a·t >= c (a linear constraint); false when nothing is left.
  bool linear_at_least(double a, double c, SolidBoundary by) {
    if (a > 0) at_least(c / a, by);
    else if (a < 0) at_most(c / a, by);
    else if (!(0 >= c)) return false;  // 0 >= c everywhere or nowhere
    return !empty();
  }
  // Restricts to where the side's quadric A·t² + ... with roots r0 <= r1 says inside:
  // between the roots for A > 0; outside them, (−∞, r0] ∪ [r1, ∞), for A < 0, where the
  // nappe bound already taken leaves one of them (both only for a ray through the apex,
  // where the longer is kept). False when nothing is left.
  bool inside_quadric(double A, double r0, double r1) {
    if (A > 0) {
      at_least(r0, SolidBoundary::side);
      at_most(r1, SolidBoundary::side);
      return !empty();
    }
    Bounds first = *this, second = *this;
    first.at_most(r0, SolidBoundary::side);
    second.at_least(r1, SolidBoundary::side);
    const bool first_ok = !first.empty(), second_ok = !second.empty();
    if (!first_ok && !second_ok) return false;
    if (first_ok && second_ok) *this = (first.hi - first.lo >= second.hi - second.lo) ? first : second;
    else *this = first_ok ? first : second;
    return true;
  }
  // Restricts to where the ray w + t·d is inside the cone, f(t) <= 0 for the quadric of
  // cone_quadric.h (the arguments are its); the nappe bound r(y) = ρ + k·dy·t >= 0 must be
  // taken already. False when nothing is left.
  //   A = 0: the linear 2·half_b·t + C <= 0.
  //   D' < 0: no real root, f keeps A's sign; A < 0 means the whole line (rounding near
  //     the apex; the nappe bound keeps one nappe).
  //   else: the roots q/A and the other, between or outside them (inside_quadric).
  // The other root is C/q (the stable pair) unless q is itself rounding noise. A ray
  // tangent to the side, re-centred at the tangent point, has half_b ≈ 0 and D' ≈ 0, and
  // C/q is then noise over noise (measured: a spurious interval 27% of the radius wide,
  // tests/light/shadow_cones_test.cpp's tangent rays). The textbook root
  // (−half_b + sign·√D')/A cancels only where |half_b| ≈ √D', i.e. C ≈ 0, which is where
  // C/q is good; so the one with the smaller first-order error bound is taken. The
  // textbook bound is at least ε·|q|/|A| (|q| = |half_b| + √D'), so where
  // ε·(|w⊥|² + ρ²)/|q| is below that, C/q wins without the rest of the bounds (nearly
  // every ray): SecondRoot::quick_then_bounds tests that first. It differs from the bounds
  // alone only at q = 0 (a ray through the apex) and where rounding decides the
  // comparison; each caller keeps the choice its results were made with.
  bool inside_cone(const glm::dvec3& origin_perp, const glm::dvec3& dir_perp, double rho, double slope_dir_y,
                   SecondRoot second_root) {
    const ConeQuadric<double> f = cone_quadric(origin_perp, dir_perp, rho, slope_dir_y);
    if (f.A == 0) return linear_at_least(-2 * f.half_b, f.C, SolidBoundary::side);
    if (!(f.discriminant >= 0)) return !(f.A > 0 || std::isnan(f.discriminant));
    const double sign_b = f.half_b >= 0 ? 1.0 : -1.0;
    const double root = std::sqrt(f.discriminant);
    const double q = -(f.half_b + sign_b * root);
    double r0 = q / f.A;
    const double origin_perp_sq = glm::dot(origin_perp, origin_perp);
    bool pair = second_root == SecondRoot::quick_then_bounds &&
                (origin_perp_sq + rho * rho) * std::abs(f.A) <= q * q;
    if (!pair && (q != 0 || second_root == SecondRoot::by_error_bounds)) {
      constexpr double eps = std::numeric_limits<double>::epsilon();
      const double c_error = eps * (origin_perp_sq + rho * rho);
      const double half_b_error =
          eps * (std::sqrt(origin_perp_sq * glm::dot(dir_perp, dir_perp)) + std::abs(rho * slope_dir_y));
      const double d_error = eps * (f.radial_sq + f.moment_sq);
      const double root_error = d_error / (root + std::sqrt(d_error) + std::numeric_limits<double>::min());
      const double pair_bound = q != 0 ? c_error / std::abs(q) : std::numeric_limits<double>::infinity();
      const double direct_bound = (eps * (std::abs(f.half_b) + root) + half_b_error + root_error) / std::abs(f.A);
      pair = pair_bound <= direct_bound;
    }
    double r1 = pair ? f.C / q : (-f.half_b + sign_b * root) / f.A;
    if (r1 < r0) std::swap(r0, r1);
    return inside_quadric(f.A, r0, r1);
  }
};

}  // namespace sylva::solid_bounds
