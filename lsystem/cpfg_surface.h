// cpfg_surface.h — cpfg's predefined surfaces (CPFG manual 6.7.1 `~`, 8.1.5 `surface:` and
// `tsurface:`, 8.4; docs/cpfg.md "Surfaces"): a `.s` file of bicubic Bézier patches, placed and
// sized as cpfg's patches.c places it, tessellated once into a grid of points per patch, or a
// tsurface's triangles. The turtle draws a `~X(s)` as polygon leaves through these points
// (core/grow/turtle.cpp).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/util/diagnostic.h"

namespace sylva::lsys {

struct CpfgSurface {
  char id = 0;           // the view file's id: `~X` draws it
  int s_cells = 5;       // the grid's cells across a patch (its rows of control points) ...
  int t_cells = 5;       // ... and along (its columns)
  // Per patch, (s_cells + 1) × (t_cells + 1) points, s major, in the surface's own frame:
  // x along the turtle's left, y along its heading, z along cpfg's up (sylva's reversed),
  // the contact point at the origin, sized so the file's SIZE is the view file's size.
  std::vector<std::vector<std::array<double, 3>>> patches;
  // A tsurface's (CPFG manual 8.4, `tsurface:`) triangles instead, in the same frame, their
  // points times the view file's size (cpfg's tsurfaces.c: no contact point, no SIZE).
  std::vector<std::array<std::array<double, 3>, 3>> triangles;
};

// The most cells a patch is cut into along each direction (cpfg's S_COUNT and T_COUNT).
inline constexpr int kMaxSurfaceCells = 10;

// Reads the surface file `path` for `surface: id file size [s t]` (s, t: 0 for the file's
// own PRECISION line, else cpfg's default 5 and 5). Errors at their line in the file: a
// missing field, a malformed number, a SIZE of 0, no patch.
Expected<CpfgSurface> read_cpfg_surface(const std::string& path, char id, double size, int s_cells, int t_cells);

// The most triangles one tsurface file may hold.
inline constexpr size_t kMaxTsurfaceTriangles = 1000000;

// Reads the tsurface file `path` (rayshade's triangles, CPFG manual 8.4) for `tsurface: id
// file size`: each `triangle` word, then three vertices of 3 to 8 numbers (x y z, the
// normal, the texture's u v: only x y z are used; sylva's leaves are flat), separated by
// spaces, tabs, commas or colons, a vertex ending with its line once it has 3, as cpfg's
// tsurfaces.c reads them; other words between triangles are passed over, as there. Errors
// at their place in the file: a word where a number belongs, an unfinished triangle, none.
Expected<CpfgSurface> read_cpfg_tsurface(const std::string& path, char id, double size);

}  // namespace sylva::lsys
