// solid_bounds.h — the interval of a ray parameter t inside a conical solid, built up one
// constraint at a time: what relief.cpp's frustum_solid_interval and shadow_cones.cpp's
// cone interval (the same algorithm in the cone's own frame) share. Internal to core/.
#pragma once

#include <limits>

#include "core/geometry/relief.h"  // SolidBoundary

namespace sylva::solid_bounds {

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
};

}  // namespace sylva::solid_bounds
