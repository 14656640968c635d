// gltf.h — the io stage: skeletons to glTF 2.0 (gltf_writer.cpp), and back (gltf_reader.cpp).
//
// What a file holds (Y up, metres): for each plant, a node named after it carrying
//   - a mesh with one LINES primitive (mode 1): POSITION (with min/max), a float
//     `_RADIUS` attribute, indices as (parent joint, child joint) pairs, one pair per
//     segment — the skeleton, visible in every viewer;
//   - node extras {"sylva": {...}}: the whole skeleton document of docs/spec/skeleton.md (format,
//     version, source with grammar, seed as a *string* (64-bit exact), steps, defines;
//     chains with parents and joints; leaves, version 2, when it has any) plus, per segment, the skinning data a renderer
//     needs (cutting plane normals and u offset);
//   - optionally (`mesh`) further TRIANGLES primitives of the same mesh (so instancing
//     covers them too): the tessellated frusta (tessellate.h), one primitive per material
//     index that occurs in the plant (triangles grouped by their frustum's material),
//     all sharing one set of vertex attributes — POSITION, NORMAL, TEXCOORD_0 and, when
//     the bark has a height map, TANGENT — and one material each (below).
//   - with `mesh`, the plant's leaves (docs/spec/skeleton.md "Leaves"; leaf_mesh.h's triangulation)
//     as further TRIANGLES primitives, one per material index the leaves use, in
//     increasing order, sharing one POSITION, NORMAL and TEXCOORD_0 set (each leaf's own
//     vertices, its unit Newell normal at each, its leaf_uvs as (u, 1 − v)); their
//     material "sylva_leaf_material_<k>" is double-sided unless the table makes k
//     one-sided, its baseColorFactor material_look(options.materials, no bark, k) (a
//     leaf is never bark), or 1 under a leaf image of the table (leaf_images.h:
//     baseColorTexture = k's merged RGBA layer as an embedded PNG; alphaMode MASK with
//     alphaCutoff 0.5 for a cut-out), extras.sylva {"material_index", "leaf": true, and
//     "specular" where the table describes k}. A segment of a material with a leaf image
//     has the image's mean albedo (segment_look).
//
// Bark and materials (with `mesh`; without it the bark is ignored and no texture read).
// A plant's `bark` (scene.h, docs/spec/scene.md) covers its wood only, the segments of material 0
// (materials.h); the other materials are plain colours:
//   - TEXCOORD_0 = (u · u_repeat, v_m · v_per_metre): u in turns around the axis, v_m the
//     arc length in metres (skin.h) — the texture repeats as in the renderer. (The
//     defaults u_repeat = v_per_metre = 1 give the raw (u, v_m).)
//   - material "sylva_material_<k>" per material index k used, pbrMetallicRoughness with
//     metallic 0, roughness 0.9. Material 0 with a bark albedo texture: baseColorTexture = that
//     image, embedded byte for byte (a bufferView in .glb, a data URI in .gltf; PNG or
//     JPEG only, as glTF requires), baseColorFactor 1. Without: baseColorFactor = the
//     linear colour material_look(options.materials, bark, k) (scene.h): a bark albedo
//     colour for material 0, else the scene table's albedo, else
//     default_material_albedo(k) (materials.h). A material the table describes also has
//     extras.sylva "specular" (its Blinn–Phong weight, which glTF's metallic–roughness
//     model has no slot for).
//   - a material k whose table entry lays its albedo image on the segments (scene.h
//     segment_texture: `u_repeat` / `v_per_metre`; material 0 only where the bark has no
//     albedo): baseColorTexture = that image embedded byte for byte (PNG or JPEG),
//     baseColorFactor 1, extras.sylva "segment_texture" {"albedo" (path), "u_repeat",
//     "v_per_metre", "texcoord"}; where its repeats differ from the bark's, its primitive's
//     attributes add TEXCOORD_1 = (u · its u_repeat, v_m · its v_per_metre) and the
//     texture reads texCoord 1.
//   - material 0 with a bark height map: normalTexture = a tangent-space normal map baked from it
//     (normal_map.h, 8-bit RGB PNG, glTF's "+X right, +Y up in the image" convention,
//     i.e. X toward increasing s, Y toward decreasing t). glTF cannot follow a radius
//     that changes along the plant, so one texel is measured at r_ref = the plant's
//     median segment radius (a segment's radius: the mean of its two end radii): around,
//     2π·r_ref/(u_repeat·width) metres; along, 1/(v_per_metre·height); relief depth
//     relief_depth_m. Thinner and thicker segments get proportionally weaker and
//     stronger relief around the stem than the renderer's. TANGENT (vec4): xyz the unit
//     direction of increasing s (axis × normal, the circumferential direction), w = ±1
//     chosen so that cross(NORMAL, TANGENT.xyz)·w points toward decreasing t, as the
//     map's +Y does (w = −1 on the lateral surface, where u grows counter-clockwise
//     about the axis). The flat caps carry a tangent ⊥ their normal and the texture's
//     rim coordinates; their relief is not meaningful.
//   - the material's extras.sylva holds "material_index" and, for material 0, the raw
//     relief parameters: "albedo" (path as given, or [r, g, b]) and "height" (path as
//     given) when the bark has them, "relief_depth_m", "u_repeat", "v_per_metre",
//     "r_ref_m" (with a height map), and "texcoord_0", the UV convention in words.
//   Identical materials and images are written once. A missing or unreadable texture,
//   or an albedo that is neither PNG nor JPEG, is an error naming the file, and nothing
//   is written.
//
// Layout of node extras.sylva (all numbers shortest round-trip decimals):
//   "format", "version", "source" {grammar, seed (decimal string), steps, defines},
//   "chains" — exactly docs/spec/skeleton.md's document;
//   "skinning": {"max_tilt_deg", "columns": [...], "frusta": [[chain, segment, knuckle,
//     lower_normal[3], lower_offset_m, upper_normal[3], upper_offset_m, u_offset], ...]}
//     — skin_skeleton's frusta with default SkinOptions styled by the plant's skin, in
//     its order, and "skin": "smooth" or "paper" (which of the two);
//   "instances": [{"name", "position_m"[3], "rotate_y_deg", "scale"}, ...] — the exact
//     placement of every plant this node draws (one, or several when instanced).
// Extras "compact" (GltfExtras::compact, `sylva export`'s default): "format", "version"
// and "source" as above; "chains", "leaves", "skinning.frusta" and "instances" become
// objects {"count": n, NAME: bufferView index, ...} whose bufferViews (in buffer 0, no
// target, no accessor, 8-byte aligned) hold raw little-endian float64 ("f64") or uint32
// ("u32") values, so every double reads back bit for bit:
//   "chains"    {"count" C, "joint_count" u32[C], "parent" u32[2C] (chain, joint;
//                4294967295 twice for a root), "joints" f64[4J] (x, y, z, radius),
//                "material" u32[J]}, J = the sum of joint_count;
//   "leaves"    {"count" L, "vertex_count" u32[L], "joint" u32[2L] (as "parent"),
//                "material" u32[L], "vertices" f64[3V]}, V = the sum of vertex_count;
//                left out without leaves;
//   "skinning"  {"max_tilt_deg", "skin", "columns", "frusta": {"count" F, "ids" u32[3F] (chain,
//                segment, knuckle 0/1), "planes" f64[9F] (the other columns in order)}};
//   "instances" {"count" K, "names" [K strings], "placement" f64[5K] (position_m[3],
//                rotate_y_deg, scale)}.
// A bufferView key is left out when its count is 0 (glTF has no empty bufferViews).
// The reader takes an array-valued "chains" as "full" (files written before "compact"
// existed), an object-valued one as "compact".
// Vertex i of the LINES primitive is joint i of the skeleton.
// For engines (docs/gltf.md; each needs `mesh`):
//   - `rig`: the triangles leave the plant's mesh for a skinned mesh NAME_skin on a scene
//     root node; the joints (gltf_rig.h) are nodes NAME_rig (a child of the plant's node),
//     NAME_joint_j; JOINTS_0 unsigned byte (short past 256 joints), WEIGHTS_0
//     normalized unsigned short summing to exactly 1, at most two used;
//   - `animation`: one animation "wind", LINEAR rotation channels on the joints;
//   - `wind_data`: TEXCOORD_1 (TEXCOORD_0's accessor unless a texture has its own),
//     TEXCOORD_2 = (pivot.x, pivot.y), TEXCOORD_3 = (pivot.z, level + phase);
//   - `lod`: nodes NAME_LOD0 … NAME_LODN (gltf_lod.h) instead of the plant's triangles,
//     children of its node (or skinned roots with `rig`), the last two cards with
//     materials NAME_card_i (MASK, double-sided, an embedded PNG);
//   - `compress` meshopt: the accessors' bufferViews encoded (EXT_meshopt_compression,
//     required), their plain bytes in a fallback buffer 1 the file does not hold.
// Files are written atomically; .glb is binary glTF, .gltf is JSON with the buffer
// embedded as a data URI. Every file passes the Khronos glTF validator with no errors or
// warnings (checked in CI by scripts/validate_gltf.mjs).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/scene/animate.h"
#include "core/scene/scene.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skin.h"
#include "core/io/gltf_lod.h"
#include "core/io/gltf_rig.h"
#include "core/util/diagnostic.h"

namespace sylva {

// One plant placed in the file.
// The most joints the plants read back from one glTF file may hold, instances counted
// (each instance is a copy of its skeleton; docs/limits.md "Inputs"): about 2 GiB.
inline constexpr uint64_t kMaxImportedJoints = 50'000'000;

// How a plant's mesh looked in a file `sylva export --mesh` wrote (its materials
// "sylva_material_k" / "sylva_leaf_material_k" and their extras.sylva), read back so that
// `render plant.glb` draws what the file carries (issue 31 §6). Images are the file's
// embedded PNG or JPEG bytes, shared between the instances that use them.
struct GltfLook {
  struct Image {
    std::string mime;                          // "image/png" or "image/jpeg"
    std::shared_ptr<const std::string> bytes;  // the encoded file
  };
  // The wood (material 0): u_repeat, v_per_metre, relief_depth_m and an albedo colour as
  // the material's extras give them; no paths (below).
  Bark bark;
  std::optional<Image> bark_albedo;       // material 0's baseColorTexture
  std::optional<std::string> bark_height; // extras "height": the path the export was given
                                          //   (the file holds only the normal map baked from it)
  struct Material {
    uint32_t index = 0;                   // the material index k >= 1
    SceneMaterial material;               // colour (baseColorFactor), specular, two_sided,
                                          //   segment repeats; no image paths (below)
    std::optional<Image> image;           // its baseColorTexture: a leaf image (RGBA, the
                                          //   alpha its cut-out) or the segments' image
  };
  std::vector<Material> materials;        // in increasing index
};

struct GltfPlant {
  std::string name;             // node name, e.g. "elm" (from the grammar file's stem)
  Skeleton skeleton;            // in the plant's own frame, metres
  double position_m[3] = {0, 0, 0};  // node translation
  double rotate_y_deg = 0;      // node rotation about +Y
  double scale = 1;             // node uniform scale
  Bark bark = {};               // textures and relief of the mesh (used with `mesh` only)
  SkinStyle skin = SkinStyle::smooth;  // how its chains meet (the frusta of the mesh and of
                                       //   extras' "skinning"; docs/spec/scene.md "Skin")
  std::optional<GltfLook> look = {};   // read back only: the look of the mesh drawn for it
                                       //   (none: the file has no sylva material on it)
};

// How a node's extras.sylva holds the skeleton (docs/gltf.md "Skeleton in extras").
enum class GltfExtras {
  full,     // the layout above, every number as JSON text
  compact,  // the same keys, the large arrays as raw bufferViews (below); bit-exact
  none,     // no node extras: a plain mesh, which cannot be read back as a skeleton
};

// The looping wind clip of a rigged export (docs/gltf.md "Rig and wind clip"): plant i of
// the list sways as plant_sway_parameters(sway, i) does in the renderer, every frequency
// rounded to a whole number of cycles per duration_s (looping_frequency_hz); keys every
// duration_s / ceil(duration_s · fps) seconds, the last one the first's.
struct GltfWindClip {
  SwayParameters sway;      // a scene's animation (sway_parameters_of) or the defaults
  double duration_s = 4;    // (0, 1e6] (as the scene's key)
  double fps = 24;          // (0, 1000]; at most kMaxWindClipKeys keys in all
};
inline constexpr uint64_t kMaxWindClipKeys = 100'000;
// The clip's key intervals: ceil(duration_s · fps), at least 1 (keys = intervals + 1).
uint64_t wind_clip_intervals(const GltfWindClip& clip);
// Why `clip` cannot be written (duration, fps or key count out of range), or nothing.
std::optional<std::string> wind_clip_problem(const GltfWindClip& clip);

// An impostor card's image (LOD, gltf_lod.h): RGBA, 8 bits, sRGB colour, straight alpha,
// rows from the top.
struct CardImage {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;
};
// Renders `plant` (its skeleton in its own frame, its bark) as seen on `card`, from the
// side card.normal points to, the image's right along card.right, width × height pixels
// covering the card exactly. The front end supplies it (app/front/impostor.h: the CPU ray
// caster); core/io renders nothing itself.
using CardRenderer = std::function<Expected<CardImage>(const GltfPlant& plant, const ImpostorCard& card,
                                                       uint32_t width, uint32_t height)>;

// How the file's buffers are stored (docs/gltf.md "Compression").
enum class GltfCompression {
  none,     // plain: no extension required (Blender 3.4, Godot and every viewer read it)
  meshopt,  // EXT_meshopt_compression (required then): the accessors' views encoded by
            // meshoptimizer's lossless codecs; three.js, Babylon and glTFast decode it
};

struct GltfExportOptions {
  bool mesh = false;            // also write the tessellated frusta as a triangle mesh
  int segments_around = 8;      // columns around each frustum for the mesh (>= 3)
  bool instancing = false;      // repeated identical plants (equal skeletons and, with
                                // `mesh`, equal barks) as one node
                                // with EXT_mesh_gpu_instancing (listed in extensionsUsed)
  std::map<uint32_t, SceneMaterial> materials = {};  // the scene's table (with `mesh`)
  GltfExtras extras = GltfExtras::full;  // how node extras.sylva holds the skeleton (above)
  // The wind rig (needs `mesh`, excludes `instancing`): a glTF skin per plant along its
  // first branch orders (gltf_rig.h), at most max_joints joints (1 .. kMaxRigJoints).
  bool rig = false;
  uint32_t max_joints = kDefaultRigJoints;
  std::optional<GltfWindClip> animation = {};  // the looping wind clip (needs `rig`)
  // Per-vertex wind data for shaders (needs `mesh`; docs/gltf.md "Wind data for shaders"):
  // TEXCOORD_2 = (pivot.x, pivot.y), TEXCOORD_3 = (pivot.z, level + phase), TEXCOORD_1
  // then always present (TEXCOORD_0's values where no texture needs its own).
  bool wind_data = false;
  uint64_t wind_seed = 0;  // the sway seed the phases come from (a scene animation's `seed`)
  // Levels of detail (needs `mesh`; gltf_lod.h): 0 none; N in 1 .. kMaxLodLevels writes
  // nodes NAME_LOD0 … NAME_LOD(N−1) re-meshed from the skeleton and NAME_LODN, the
  // impostor cards, card_pixels tall, drawn by card_renderer (required then).
  uint32_t lod = 0;
  uint32_t card_pixels = 256;
  CardRenderer card_renderer = {};
  GltfCompression compress = GltfCompression::none;
  // The skin options each plant's style is applied to (SkinOptions::styled) for its mesh
  // and its levels of detail. With blend_crotches the full mesh (and NAME_LOD0) carries
  // each crotch's fillet (crotch_mesh.h skeleton_fillets, docs/gltf.md "Crotches"); the
  // coarser levels leave them out. Extras' "skinning" stays the default options' frusta.
  SkinOptions skin = {};
};

// Writes `plants` to `path` (.glb or .gltf by extension). An error is a Diagnostic naming
// `path` (or the texture that cannot be read); an existing file is left untouched then.
Status export_gltf(const std::vector<GltfPlant>& plants, const std::string& path,
                   const GltfExportOptions& options = {});

// Checks that the bark's textures can be embedded: the albedo (if a texture) is a
// readable PNG or JPEG, the height map (if any) a readable image. An error names the
// file. export_gltf checks the same; a front end calls this once before a batch.
Status check_bark_textures(const Bark& bark);

// r_ref of the baked normal map: the median over the skinned segments (knuckles left
// out) of the mean of their two end radii, segments of radius 0 at both ends left out;
// 0 when there is none.
double bark_reference_radius_m(const Skeleton& skeleton, SkinStyle skin = SkinStyle::smooth);

// Reads the sylva skeletons back from a glTF file's node extras (for `sylva render
// plant.glb`), "full" or "compact": one plant per node and instance, in node order. A
// file without sylva extras (e.g. written with GltfExtras::none) is an error naming the
// file, not a crash; a bad value is located in the JSON. For "compact" the binary buffer
// is read too (the GLB's BIN chunk, or a .gltf's base64 data URI; no other URI is ever
// resolved), and every bufferView index, offset and length is checked against it and
// against the counts before anything is allocated. Each plant's `look` comes from the
// triangles drawn for its node (its own mesh, else the node NAME_LOD0 or NAME_skin the
// export adds) — the materials sylva wrote, their embedded images (bufferViews of buffer 0
// or data URIs) and their extras; a material or image that is not sylva's shape leaves
// the look without it, an index past its array is an error at its place.
Expected<std::vector<GltfPlant>> import_gltf_skeletons(const std::string& path);

// The same from the file's bytes already in memory (`path` names it in messages): the
// reader import_gltf_skeletons calls, and the one tests/fuzz/gltf_fuzz.cpp feeds.
Expected<std::vector<GltfPlant>> parse_gltf_skeletons(const std::string& bytes, const std::string& path);

}  // namespace sylva
