// gltf_export.h — skeletons to glTF 2.0 (issue 5), and back.
//
// What a file holds (Y up, metres): for each plant, a node named after it carrying
//   - a mesh with one LINES primitive (mode 1): POSITION (with min/max), a float
//     `_RADIUS` attribute, indices as (parent joint, child joint) pairs, one pair per
//     segment — the skeleton, visible in every viewer;
//   - node extras {"sylva": {...}}: the whole skeleton document of skeleton.md (format,
//     version, source with grammar, seed as a *string* (64-bit exact), steps, defines;
//     chains with parents and joints) plus, per segment, the skinning data a renderer
//     needs (cutting plane normals and u offset);
//   - optionally (`mesh`) a second, TRIANGLES primitive of the same mesh (so instancing
//     covers it too): the tessellated frusta (tessellate.h) with NORMAL and TEXCOORD_0 =
//     (u in turns, v_m · kGltfTexcoordVPerMetre), and material 0 "bark" (constant albedo;
//     relief parameters and the UV convention in the material's extras.sylva).
//
// Layout of node extras.sylva (all numbers shortest round-trip decimals):
//   "format", "version", "source" {grammar, seed (decimal string), steps, defines},
//   "chains" — exactly skeleton.md's document;
//   "skinning": {"max_tilt_deg", "columns": [...], "frusta": [[chain, segment, knuckle,
//     lower_normal[3], lower_offset_m, upper_normal[3], upper_offset_m, u_offset], ...]}
//     — skin_skeleton's frusta with default SkinOptions, in its order;
//   "instances": [{"name", "position_m"[3], "rotate_y_deg", "scale"}, ...] — the exact
//     placement of every plant this node draws (one, or several when instanced).
// Vertex i of the LINES primitive is joint i of the skeleton.
// Files are written atomically; .glb is binary glTF, .gltf is JSON with the buffer
// embedded as a data URI. Every file passes the Khronos glTF validator with no errors or
// warnings (checked in CI by scripts/validate_gltf.mjs).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/skeleton.h"

namespace sylva {

// TEXCOORD_0.v = arc length in metres times this (one texture repeat per metre).
inline constexpr double kGltfTexcoordVPerMetre = 1.0;
// Linear RGB base colour of the bark material until bark textures are baked.
inline constexpr double kGltfBarkAlbedo[3] = {0.30, 0.22, 0.15};

// One plant placed in the file.
struct GltfPlant {
  std::string name;             // node name, e.g. "elm" (from the grammar file's stem)
  Skeleton skeleton;            // in the plant's own frame, metres
  double position_m[3] = {0, 0, 0};  // node translation
  double rotate_y_deg = 0;      // node rotation about +Y
  double scale = 1;             // node uniform scale
};

struct GltfExportOptions {
  bool mesh = false;            // also write the tessellated frusta as a triangle mesh
  int segments_around = 8;      // columns around each frustum for the mesh (>= 3)
  bool instancing = false;      // repeated identical plants (equal skeletons) as one node
                                // with EXT_mesh_gpu_instancing (listed in extensionsUsed)
};

// Writes `plants` to `path` (.glb or .gltf by extension). Returns an error message, or
// nothing on success; an existing file is left untouched on failure.
std::optional<std::string> export_gltf(const std::vector<GltfPlant>& plants, const std::string& path,
                                       const GltfExportOptions& options = {});

// Reads the sylva skeletons back from a glTF file's node extras (for `sylva render
// plant.glb`). A file without sylva extras is an error naming the file, not a crash.
struct GltfImportResult {
  std::vector<GltfPlant> plants;
  std::optional<std::string> error;
};
GltfImportResult import_gltf_skeletons(const std::string& path);

}  // namespace sylva
