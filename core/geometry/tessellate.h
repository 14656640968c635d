// tessellate.h — the polygon baseline: skinned frusta as triangle meshes (Bhagvat et al. 2009 sec. 4,
// the GS and GS+R columns).
//
// Each frustum becomes a grid on its own surface between its two cutting planes:
// columns along generator lines and rows of equal v (eq. 7), every vertex exactly on the
// analytic cone. Level m follows the paper's GS column: 8·2^m columns × 2^m rows =
// 16·4^m triangles per segment. A chain's first frustum places its columns at texture
// u = i/columns on its lower cut; a frustum that shares its lower cut plane with the one
// below takes that frustum's top-row points as its own bottom row (and its generators
// through them), so the mesh is watertight across joints by construction. Texture
// coordinates are (i/columns, v_m): continuous across joints; they follow the analytic
// u exactly on the first frustum and to within the u-offset alignment of skin.h above. Flat caps become fans. At a tip (radius
// 0) the last row collapses to a point and is emitted as one triangle per column, never a
// zero-area triangle.
//
// Units and frames: world space, metres, Y up (as the skinned skeleton). Normals are unit
// (eq. 8 or exact, as asked); texture coordinates are (u in turns, v_m in metres of arc
// length), the parametrization of skin.h. Triangles are counter-clockwise seen from
// outside.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <span>
#include <stdexcept>
#include <vector>

#include "core/geometry/skin.h"

namespace sylva {

struct TessellateOptions {
  int level = 0;               // m >= 0: 8·2^m columns, 2^m rows (paper's GS levels)
  int segments_around = 0;     // > 0 overrides the columns (glTF export); rows stay 2^m
  NormalMode normals = NormalMode::interpolated;
  bool caps = true;            // emit the flat caps the shapes have
};

struct TriangleMesh {
  std::vector<glm::dvec3> positions;      // metres
  std::vector<glm::dvec3> normals;        // unit, per vertex
  std::vector<glm::dvec2> uvs;            // (u turns, v_m metres)
  std::vector<uint32_t> indices;          // 3 per triangle, counter-clockwise from outside
  std::vector<uint32_t> triangle_frustum; // per triangle: index into SkinnedSkeleton::frusta

  size_t triangle_count() const { return indices.size() / 3; }
  // Bytes held by the arrays (capacity): what the mesh costs in memory.
  size_t memory_bytes() const;
};

// Columns and rows one frustum gets with `options` (columns >= 3, rows >= 1).
int tessellation_columns(const TessellateOptions& options);
int tessellation_rows(const TessellateOptions& options);

// The most a mesh may take (docs/limits.md "Numbers"): its arrays at most kMaxMeshBytes
// (64 bytes a vertex, so its vertices stay far below what 32-bit indices address). A
// mesh past it is refused before anything is allocated for it (MeshTooLarge), naming the
// limit and what to lower.
constexpr uint64_t kMaxMeshBytes = uint64_t{8} << 30;  // 8 GiB
struct MeshTooLarge : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Bytes and vertices tessellate() reserves for `frusta` frusta with `options` (an upper
// bound of what it uses), computed from the counts alone, without overflow.
struct MeshSize {
  uint64_t vertices = 0;
  uint64_t triangles = 0;
  uint64_t bytes = 0;
};
MeshSize tessellation_size(uint64_t frusta, const TessellateOptions& options);
// Throws MeshTooLarge when a mesh of `size`, added to `already_bytes` of meshes already
// built for the same picture, passes the limits.
void check_mesh_fits(const MeshSize& size, uint64_t already_bytes = 0);

// Tessellates every frustum of `skinned`. Deterministic. Throws MeshTooLarge (before
// allocating) when the mesh cannot fit.
TriangleMesh tessellate(const SkinnedSkeleton& skinned, const TessellateOptions& options = {});

// Appends `part` to `into`: its indices shifted past into's vertices, its triangle_frustum
// shifted by `frustum_offset` (so per-plant meshes index one scene-wide frustum array).
void append_mesh(TriangleMesh& into, const TriangleMesh& part, uint32_t frustum_offset);

// A displacement in metres at texture coordinates (u turns, v_m metres of arc length).
using HeightFn = std::function<double(double u, double v_m)>;

// The GS+R displacement of a relief (relief.h): d·clamp(H(u·u_repeat, v_m·v_per_metre), 0, 1)
// metres, H clamped as the relief marcher clamps it; an empty function when depth_m is not
// > 0 (no relief, nothing to displace). `height_at(s, t)` is H; what it reads must outlive
// the function.
template <class Height>
HeightFn relief_displacement(Height height_at, double depth_m, double u_repeat, double v_per_metre) {
  if (!(depth_m > 0)) return {};
  return [height_at, depth_m, u_repeat, v_per_metre](double u, double v_m) {
    return depth_m * std::clamp(static_cast<double>(height_at(u * u_repeat, v_m * v_per_metre)), 0.0, 1.0);
  };
}

// The paper's GS+R: `mesh` with every vertex moved along its normal by height_m(u, v_m)
// (positive: outward), normals recomputed from the displaced surface as angle-weighted
// sums of face normals (area weights would depend on the split of each grid quad into
// two triangles and tilt a cylinder's normals by 7.9° at level 0). Cracks cannot open: vertices that coincide in `mesh` (the seam
// columns u = 0 and u = 1, the rows two frusta share at a joint, a tip row, a cap's rim and
// the side's rim) are all moved by one vector, that of the first side vertex among them in
// vertex order (for a rim: the side's), so they coincide afterwards whatever height_m
// does — even where it is discontinuous (a texture whose u repeat is not a whole number).
// Caps stay in their cut planes, as the relief solid's do (relief.h): a cap's centre does
// not move, its rim moves with the side. Normals are shared across coincident vertices
// where their original normals agree (seams, joints with eq. 8 normals, tips) and kept
// apart where they do not (a cap's rim against the side: the crease stays).
// The relief solid of relief.h lifts the surface radially (distance from the axis
// r(y) + d·H); a move δ along a cone's normal lifts it radially by δ/cos φ (φ the cone's
// half-angle): the same for a cylinder, 0.5% more at φ = 6°. Deterministic; triangles, uvs and triangle_frustum are
// unchanged.
// `scale`, if not empty, holds one factor per vertex that multiplies height_m there (the
// renderer thins the relief of twigs and needles: relief.h's max_depth_per_radius).
TriangleMesh displace(const TriangleMesh& mesh, const HeightFn& height_m, std::span<const double> scale = {});

}  // namespace sylva
