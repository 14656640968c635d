// tessellate.h — the polygon baseline: skinned frusta as triangle meshes (issue 3 §3).
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

#include <cstdint>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <vector>

#include "core/skin.h"

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

// Tessellates every frustum of `skinned`. Deterministic.
TriangleMesh tessellate(const SkinnedSkeleton& skinned, const TessellateOptions& options = {});

}  // namespace sylva
