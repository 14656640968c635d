// crotch_mesh.h — a crotch's fillet (crotch.h, docs/joints.md "Crotches") as triangles, for
// the paths that draw meshes (glTF, the polygon baseline), beside the frusta's own mesh.
//
// Units and frames: world space, metres, Y up, doubles, as crotch.h; the mesh's
// conventions are tessellate.h's (normals unit, uv = (u turns, v_m metres), triangles
// counter-clockwise seen from outside, triangle_frustum an index into the frusta).
//
// Naive surface nets on a cubic grid of `cell_m` over the ball: one vertex a cell the
// field changes sign in (the mean of its edges' crossings, moved onto F = 0 by Newton
// steps), one quad of the four cells round each edge the field changes sign along. Of
// those quads only the ones on the fillet are kept: with a vertex off the exact union
// (more than 1e-6 of the ball's radius outside both groups, where the blend acts, k > 0),
// or with vertices on both groups' surfaces where the blend acts (the quad across the
// crease: where the fillet is narrower than a cell no vertex need lie on it, and without
// that quad the crease would show through a gap). The frusta's mesh already draws the
// rest, so the fillet adds nothing where the blend changes nothing, and where it is kept
// it overlaps the frusta's mesh by about a cell (the renderers compose the two by depth,
// as they do the exact frusta and the marched blend).
//
// A cell should be at most about k/2: the vertices sit on the surface but the facets
// chamfer what is curved within a cell, and the acute side of a crotch is curved within
// k (crotch_mesh_test, the 45° limb with k = 0.12 m: the marched fillet within 4.4 mm of
// the mesh at cells of k/3 = 40 mm, within 8.1 mm at k/2 = 60 mm).
//
// Guarantees:
// - Every vertex is on F = 0 to 1e-7 of the ball's radius, except where Newton steps do
//   not settle within a cell of the crossings' mean (kinks of the bounds): that vertex is
//   the mean, within about a cell's linear-interpolation error of the surface.
// - Every vertex is within the ball and a cell or two beyond it, and at most k/4 (plus the
//   above) outside the exact union, since the blend adds no more (crotch.h).
// - Triangles are wound outward (toward F > 0), each quad split along its shorter diagonal;
//   exactly degenerate ones are dropped.
// - Normals are crotch_shade's mixed normal at the vertex (not the facets'; the bounds
//   have kinks). A triangle takes the group that is heavier at its centroid (h >= 0.5:
//   the parent's): triangle_frustum is that group's shading frustum there, and each of its
//   corners has that group's (u, v_m) — a vertex used by triangles of both groups, or by
//   one whose u crosses the seam (u then taken past 1), is repeated with the other uv, so
//   no triangle interpolates between the two groups' coordinates or across the seam. The
//   texture jumps where h crosses 0.5 (the renderers mix both textures; one uv cannot).
// - Deterministic (grid order); empty when the crotch has no blend (k = 0).
//
// Cost: the 45° limb (r = 0.15 m) on a 0.3 m trunk of crotch_mesh_test makes 752
// triangles at cells of k/3 and 368 at k/2; the field is sampled at (2⌈R/cell⌉ + 4)³
// grid corners (R the ball's radius), and a few dozen times more at each vertex.
#pragma once

#include <span>
#include <stdexcept>

#include "core/geometry/crotch.h"
#include "core/geometry/tessellate.h"

namespace sylva {

// The most cells a side of the grid may have (memory: one double a corner, one index a
// cell); a smaller cell is refused.
inline constexpr int kMaxCrotchGridCells = 256;

// The fillet of one crotch as triangles, for the mesh paths (glTF, the polygon baseline):
// only the part of the blended surface the exact frusta do not already have — where the
// smooth union lies outside the exact union — so it overlaps the frusta's own mesh a
// little and adds no triangle where the blend changes nothing. Throws
// std::invalid_argument when cell_m is not > 0 or the grid would pass
// kMaxCrotchGridCells a side. Preconditions: crotch.h's (the crotch is find_crotches'
// for these frusta).
TriangleMesh crotch_fillet_mesh(const Crotch& crotch, std::span<const Frustum> frusta, double cell_m);

// The smallest cell skeleton_fillets meshes a crotch with, as a share of the skeleton's
// extent (the diagonal of skeleton_bounds: joints with their radii, leaves): in a view of
// the whole plant 1000 pixels across, a facet is at least about a pixel.
inline constexpr double kFilletMinCellPerExtent = 1e-3;

// The fillets of `crotches` (find_crotches' for these frusta, all or some of them: a
// renderer that knows its view meshes only those crotch_seen keeps) as one mesh, each at
// cells of k/2 (within about 8 mm of the marched fillet on the test limb, about
// 370 triangles a crotch) but no smaller than kFilletMinCellPerExtent of the skeleton's
// extent (docs/joints.md: the elm's 529 crotches make 81,000 triangles in 0.25 s instead
// of 197,000 in 0.64 s; only its crotches of under about 3 cm are coarser),
// triangle_frustum indexing `frusta`: what the mesh paths and GL append beside the
// frusta's own mesh where SkinOptions::blend_crotches is on. The crotches are meshed on
// `threads` threads (0: every hardware thread; parallel.h) and appended in crotch order:
// the same mesh on any thread count.
// `cell_per_k`: the cell as a share of k (asset_fillets meshes coarser).
TriangleMesh crotch_fillets(std::span<const Crotch> crotches, const Skeleton& skeleton,
                            std::span<const Frustum> frusta, unsigned threads = 0, double cell_per_k = 0.5);
// Every crotch's fillet: crotch_fillets of find_crotches with the default options.
TriangleMesh skeleton_fillets(const Skeleton& skeleton, std::span<const Frustum> frusta, unsigned threads = 0);

// The plant's size on screen an asset's fillets are chosen for: seen whole this many pixels
// across (the extent kFilletMinCellPerExtent's facets are sized for).
inline constexpr double kFilletAssetPixels = 1000;
// The fillets an asset carries (the glTF mesh, docs/gltf.md "Crotches"), for no view in
// particular: those at least kFilletMinPixels wide when the whole plant spans
// kFilletAssetPixels, k >= 2/1000 of the skeleton's extent; the rest move no surface by
// more than half a pixel in such a view. Each at cells of k, nearer the export's 8 facets
// around a stem than k/2: the elm's add 4,998 triangles to its 33,648 (16,324 at k/2).
TriangleMesh asset_fillets(const Skeleton& skeleton, std::span<const Frustum> frusta, unsigned threads = 0);

}  // namespace sylva
