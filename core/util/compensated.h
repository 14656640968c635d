// compensated.h — error-free transformations of double arithmetic: a sum and a product
// as an unevaluated pair hi + lo that is exact (Knuth, Dekker; Ogita, Rump, Oishi 2005).
// core/geometry/recentre.h builds the frusta's re-centred rays on them.
#pragma once

#include <cmath>

namespace sylva::compensated {

struct Compensated {
  double hi = 0;
  double lo = 0;  // hi + lo is the exact value
};

// a + b exactly (Knuth's TwoSum; no branch on magnitudes).
inline Compensated two_sum(double a, double b) {
  const double s = a + b;
  const double bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}

// a·b exactly: a hardware FMA where there is one (where the compiler could also contract
// Dekker's products and break them), Dekker's split otherwise.
inline Compensated two_product(double a, double b) {
  const double p = a * b;
#ifdef FP_FAST_FMA
  return {p, std::fma(a, b, -p)};
#else
  constexpr double kSplit = 134217729.0;  // 2^27 + 1
  const double ca = kSplit * a;
  const double a_hi = ca - (ca - a);
  const double a_lo = a - a_hi;
  const double cb = kSplit * b;
  const double b_hi = cb - (cb - b);
  const double b_lo = b - b_hi;
  return {p, ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo};
#endif
}

}  // namespace sylva::compensated
