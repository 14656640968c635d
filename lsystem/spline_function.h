// spline_function.h — cpfg's user-defined functions (CPFG manual 5.5 `func(id, x)`, 8.1.6
// `function:` and `function set:`; docs/cpfg.md "Functions"). A function is a curve drawn in
// vlab's function editor: control points (x, y) of an open uniform cubic B-spline; its value
// at x is the curve's y where the curve's x equals x (x clamped to [0, 1]), found as cpfg's
// splinefun.cpp finds it: bisection on the curve's parameter to within 0.001 in x. A function
// with more than 2 samples answers by linear interpolation between its values at `samples`
// evenly spaced x, as cpfg precomputes them.
#pragma once

#include <array>
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

// cpfg's contour functions (CPFG manual 5.5: curveX, curveY, curveZ(id, t) and curveGAL(id);
// the view file's `curve: file [samples]` lines, ids 1, 2, ... in order; docs/cpfg.md
// "Contour functions"): a curve drawn in vlab's cuspy, read from its `.con` file and measured
// as cpfg's curveXYZ.cpp measures it: `samples` points evenly spaced in the curve's parameter
// (100 without the number), the polyline through them its arc length. curveX(id, t) is the
// curve's point at the fraction t of that length (t clamped to [0, 1]), curveGAL(id) the
// length.
struct CpfgCurve {
  // cuspy's `type:` (cpfg's curveXYZ.h ECURVE): how the control points make the curve.
  enum class Type { kBSpline, kBSplineClosed, kBSplineEndpoint, kBSplinePhantom, kBezier };
  Type type = Type::kBSpline;
  std::vector<std::array<double, 3>> control;  // each repeated by its multiplicity (and closed / phantom's extras)
  std::vector<double> lengths;                 // the arc length at each sample, normalised to end at 1
  double length = 0;                           // the sampled polyline's length: curveGAL

  // The point at parameter u in [0, 1] (curveXYZ.cpp's calcPValue).
  std::array<double, 3> point(double u) const;
  // The point at the fraction s of the length, s clamped to [0, 1] (calcAValue).
  std::array<double, 3> at_length(double s) const;
};

// The most samples a curve may be measured with (a table of 8 MB).
inline constexpr int kMaxCurveSamples = 1'000'000;

// Reads the curve file `path` (cuspy's `version: 1.4` format: `points: n`, `type:`, then n
// lines "x y z multiplicity"; the other fields are read and not used) and measures it with
// `samples` points (2 to kMaxCurveSamples). Errors at their line: a missing or malformed
// field, fewer than 4 control points, an unknown type.
Expected<CpfgCurve> read_cpfg_curve(const std::string& path, int samples);

}  // namespace sylva::lsys
