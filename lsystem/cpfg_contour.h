// cpfg_contour.h — cpfg's contours (CPFG manual 6.7.3 `@#(id)`, 8.1.5 `contour: id file`;
// docs/cpfg.md "Contours"): the cross-section a generalized cylinder sweeps instead of a
// circle, a uniform cubic B-spline in its own plane, open or closed, read from a `.con` file
// and sampled as cpfg's MakeContour samples it (general.c).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/util/diagnostic.h"

namespace sylva::lsys {

struct CpfgContour {
  int id = 0;                                  // the view file's id: `@#(id)` selects it
  bool closed = false;
  std::vector<std::array<double, 3>> control;  // control points, each repeated by its multiplicity

  // `sides` points evenly spaced by arc length (measured in x and y), as cpfg samples it:
  // sides + 1 points, the last equal to the first for a closed contour (turned about the
  // origin so that its first point lies on +x), from the start to the end for an open one.
  std::vector<std::array<double, 3>> sample(int sides) const;
};

// The most points a contour is sampled to around a cylinder (cpfg warns above 1024).
inline constexpr int kMaxContourSides = 1024;

// Reads the contour file `path` (formats `cver 1 1` to `cver 1 3`, and the oldest "n dim
// open|closed" one). Errors at their line: a missing field, a malformed point, fewer than 4
// control points.
Expected<CpfgContour> read_cpfg_contour(const std::string& path, int id);

}  // namespace sylva::lsys
