// spline_function.h — cpfg's user-defined functions (CPFG manual 5.5 `func(id, x)`, 8.1.6
// `function:` and `function set:`; docs/cpfg.md "Functions"). A function is a curve drawn in
// vlab's function editor: control points (x, y) of an open uniform cubic B-spline; its value
// at x is the curve's y where the curve's x equals x (x clamped to [0, 1]), found as cpfg's
// splinefun.cpp finds it: bisection on the curve's parameter to within 0.001 in x. A function
// with more than 2 samples answers by linear interpolation between its values at `samples`
// evenly spaced x, as cpfg precomputes them.
#pragma once

#include <string>
#include <vector>

#include "core/util/diagnostic.h"

namespace sylva::lsys {

struct SplineFunction {
  std::string name;           // the file's `name:` (a function set's names become defines)
  std::vector<double> x, y;   // the control points, each repeated by its multiplicity
  std::vector<double> table;  // the values at i / (samples − 1), when samples > 2

  // The curve's point at parameter d in [0, 1] (cpfg's SplineFunction::P: at d = 1 exactly
  // the basis is empty and the point is (0, 0), as there).
  void point(double d, double* px, double* py) const;
  // The exact value at x (bisection, no table).
  double exact(double x) const;
  // func(id, x): x clamped to [0, 1]; the table's interpolation where there is one.
  double value(double x) const;
};

// The most samples a function may ask for (cpfg sets no limit; a table this long is 8 MB).
inline constexpr int kMaxFunctionSamples = 1'000'000;

// Reads a function file (`.func`): vlab's format 1.1 (`fver 1 1`, `name:`, `samples:`,
// `points:` and "x y [multiplicity]" lines) or the older one (`range: lo hi`, `points:`, "x
// y" lines), which takes `view_samples` (the view file's `function: file n`; 0: exact).
// Errors at their line: a missing or malformed field, fewer than 4 points, a value that is not
// finite.
Expected<SplineFunction> read_function_file(const std::string& path, int view_samples);

// Reads a function set (`.fset`, vlab's gallery: `funcgalleryver 1 1`, `items: n`, then n
// functions of format 1.1).
Expected<std::vector<SplineFunction>> read_function_set(const std::string& path);

}  // namespace sylva::lsys
