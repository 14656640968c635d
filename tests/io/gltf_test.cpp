// gltf_test.cpp — core/io/gltf.h: what an exported glTF holds (the LINES skeleton,
// accessor bounds, the exact skeleton in node extras, the optional mesh, instancing), the
// round trip back to skeletons, tinygltf 2.7's known writer traps (each guarded on our
// output and cross-checked by loading it with tinygltf), and a corpus of broken files
// that must give clear errors, never a crash.
#include "core/io/gltf.h"

#include <gtest/gtest.h>
#include <tiny_gltf.h>  // declarations only; the implementation is Debian's shared library

#include <glm/geometric.hpp>

#include <bit>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <random>
#include <string>
#include <vector>

#include "core/util/file_io.h"
#include "core/util/image_io.h"
#include "core/util/json.h"
#include "core/scene/materials.h"
#include "core/io/normal_map.h"
#include "core/geometry/skin.h"
#include "core/geometry/tessellate.h"
#include "tests/io/tinygltf_read.h"
#include "tests/support/plants.h"

namespace sylva {
namespace {

using test::floats_of;
using test::load_with_tinygltf;

namespace fs = std::filesystem;

// A branching plant with tapering, materials and a define.
constexpr const char* kGrammar =
    "#define N 3\n"
    "angle: 30\nwidth: 0.1\nderivation length: N\n"
    "axiom: F(1)A\n"
    "A -> !(0.7)'F(0.8)[+F(0.5)A][-/F(0.5)A]F(0.6)A\n";

// `text` grown with `seed`, its source recording presets/plant.lsys with N = 3.
Skeleton grow_text(const char* text, uint64_t seed = 7) {
  return test::grown_as(text, seed, "presets/plant.lsys", {{"N", 3}});
}

class TempFolder {
 public:
  TempFolder() {
    std::string pattern = (fs::temp_directory_path() / "sylva-gltf-XXXXXX").string();
    EXPECT_NE(mkdtemp(pattern.data()), nullptr);
    path_ = pattern;
  }
  ~TempFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(file(name), std::ios::binary) << bytes;
    return file(name);
  }

 private:
  fs::path path_;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

uint32_t u32_at(const std::string& bytes, size_t offset) {
  uint32_t v = 0;
  std::memcpy(&v, bytes.data() + offset, 4);
  return v;
}

// A .glb split into its JSON document and binary chunk.
struct Glb {
  JsonValue json;
  std::string bin;
};

Glb read_glb(const std::string& path) {
  const std::string bytes = slurp(path);
  Glb out;
  EXPECT_GE(bytes.size(), 20u);
  EXPECT_EQ(u32_at(bytes, 0), 0x46546C67u);
  EXPECT_EQ(u32_at(bytes, 8), bytes.size());
  const uint32_t json_length = u32_at(bytes, 12);
  EXPECT_EQ(json_length % 4, 0u);
  auto parsed = parse_json(std::string_view(bytes).substr(20, json_length));
  EXPECT_TRUE(parsed.ok()) << parsed.error().format();
  if (parsed) out.json = std::move(*parsed);
  const size_t bin_header = 20 + json_length;
  if (bin_header + 8 <= bytes.size()) {
    EXPECT_EQ(u32_at(bytes, bin_header + 4), 0x004E4942u);
    out.bin = bytes.substr(bin_header + 8, u32_at(bytes, bin_header));
  }
  return out;
}

const JsonValue& at(const JsonValue& v, const char* key) {
  const JsonValue* m = v.find(key);
  if (!m) {
    ADD_FAILURE() << "missing key " << key;
    static const JsonValue null_value;
    return null_value;
  }
  return *m;
}

// The elements of accessor `index` as doubles (float or uint32 components).
std::vector<double> accessor_values(const Glb& glb, size_t index) {
  const JsonValue& a = at(glb.json, "accessors").elements.at(index);
  const JsonValue& view = at(glb.json, "bufferViews").elements.at(static_cast<size_t>(at(a, "bufferView").number));
  const size_t offset = static_cast<size_t>(at(view, "byteOffset").number);
  const size_t length = static_cast<size_t>(at(view, "byteLength").number);
  EXPECT_EQ(offset % 4, 0u);
  EXPECT_LE(offset + length, glb.bin.size());
  std::vector<double> values(length / 4);
  for (size_t i = 0; i < values.size(); ++i) {
    if (at(a, "componentType").number == 5126) {
      float f;
      std::memcpy(&f, glb.bin.data() + offset + 4 * i, 4);
      values[i] = f;
    } else {
      values[i] = u32_at(glb.bin, offset + 4 * i);
    }
  }
  return values;
}

TEST(GltfExport, SkeletonIsALinesPrimitiveWithOnePairPerSegmentFromParentToChildJoint) {
  TempFolder dir;
  const Skeleton sk = grow_text(kGrammar);
  ASSERT_TRUE(export_gltf({{"plant", sk}}, dir.file("p.glb")).ok());
  const Glb glb = read_glb(dir.file("p.glb"));
  const JsonValue& prim = at(at(glb.json, "meshes").elements.at(0), "primitives").elements.at(0);
  // Trap: tinygltf writes "mode": -1 unless Primitive::mode is set.
  EXPECT_EQ(at(prim, "mode").text, "1");
  const std::vector<double> positions = accessor_values(glb, static_cast<size_t>(at(at(prim, "attributes"), "POSITION").number));
  const std::vector<double> radii = accessor_values(glb, static_cast<size_t>(at(at(prim, "attributes"), "_RADIUS").number));
  const std::vector<double> pairs = accessor_values(glb, static_cast<size_t>(at(prim, "indices").number));
  ASSERT_EQ(positions.size(), sk.joints.size() * 3);
  ASSERT_EQ(radii.size(), sk.joints.size());
  for (size_t j = 0; j < sk.joints.size(); ++j) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(positions[3 * j + k], static_cast<float>(sk.joints[j].position_m[k]));
    EXPECT_EQ(radii[j], static_cast<float>(sk.joints[j].radius_m));
  }
  std::vector<double> expected;
  bool saw_branch = false;
  for (const Chain& c : sk.chains)
    for (uint32_t j = 1; j < c.joint_count; ++j) {
      const bool from_parent = j == 1 && c.parent;
      saw_branch |= from_parent;
      expected.push_back(from_parent ? sk.chains[c.parent->chain].first_joint + c.parent->joint : c.first_joint + j - 1);
      expected.push_back(c.first_joint + j);
    }
  EXPECT_TRUE(saw_branch);
  EXPECT_EQ(pairs.size(), 2 * sk.segment_count());
  EXPECT_EQ(pairs, expected);
}

TEST(GltfExport, EveryAccessorHasExactMinAndMax) {
  // Trap: tinygltf never fills accessor min/max; the validator compares them exactly.
  TempFolder dir;
  GltfExportOptions o;
  o.mesh = true;
  ASSERT_TRUE(export_gltf({{"plant", grow_text(kGrammar)}}, dir.file("p.glb"), o).ok());
  const Glb glb = read_glb(dir.file("p.glb"));
  const JsonValue& accessors = at(glb.json, "accessors");
  ASSERT_GE(accessors.elements.size(), 7u);
  for (size_t i = 0; i < accessors.elements.size(); ++i) {
    const JsonValue& a = accessors.elements[i];
    const std::vector<double> values = accessor_values(glb, i);
    const size_t components = at(a, "min").elements.size();
    ASSERT_GT(components, 0u) << "accessor " << i;
    ASSERT_EQ(values.size(), static_cast<size_t>(at(a, "count").number) * components) << "accessor " << i;
    for (size_t k = 0; k < components; ++k) {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (size_t e = k; e < values.size(); e += components) lo = std::min(lo, values[e]), hi = std::max(hi, values[e]);
      EXPECT_EQ(at(a, "min").elements[k].number, lo) << "accessor " << i << " component " << k;
      EXPECT_EQ(at(a, "max").elements[k].number, hi) << "accessor " << i << " component " << k;
    }
  }
}

TEST(GltfExport, ValuesBeyondFloat32AreRefusedNotWrittenAsNull) {
  // A skeleton file may hold 1e39 (beyond float32's 3.4e38): the accessors would hold
  // infinities, which JSON writes as null (an invalid file). Refused, nothing written.
  TempFolder dir;
  for (const double far : {1e39, 2e12}) {
    Skeleton sk;
    sk.joints.push_back({{0, 0, 0}, 0.1, 0});
    sk.joints.push_back({{far, 1, 0}, 0.1, 0});
    sk.chains.push_back({0, 2, std::nullopt});
    const Status written = export_gltf({{"far", sk}}, dir.file("far.gltf"));
    ASSERT_FALSE(written.ok()) << far;
    EXPECT_NE(written.error().message.find("1e12"), std::string::npos) << written.error().message;
    EXPECT_FALSE(std::filesystem::exists(dir.file("far.gltf")));
  }
}

TEST(GltfExport, NoNullEntriesEvenForAPlantWithoutSegments) {
  // Trap: tinygltf writes an empty node as `null`.
  TempFolder dir;
  Skeleton empty;
  Skeleton one_joint;
  one_joint.joints.push_back({{0, 0, 0}, 0.1, 0});
  one_joint.chains.push_back({0, 1, std::nullopt});
  ASSERT_TRUE(export_gltf({{"empty", empty}, {"single", one_joint}, {"plant", grow_text(kGrammar)}}, dir.file("p.gltf")).ok());
  auto parsed = parse_json(slurp(dir.file("p.gltf")));
  ASSERT_TRUE(parsed.ok());
  for (const char* array : {"scenes", "nodes", "meshes", "accessors", "bufferViews", "buffers"}) {
    const JsonValue& v = at(*parsed, array);
    ASSERT_TRUE(v.is_array()) << array;
    EXPECT_FALSE(v.elements.empty()) << array;  // glTF forbids empty arrays
    for (const JsonValue& e : v.elements) EXPECT_TRUE(e.is_object()) << array;
  }
  const JsonValue& nodes = at(*parsed, "nodes");
  ASSERT_EQ(nodes.elements.size(), 3u);
  EXPECT_EQ(nodes.elements[0].find("mesh"), nullptr);
  EXPECT_EQ(at(nodes.elements[0], "name").text, "empty");
  EXPECT_TRUE(at(at(nodes.elements[0], "extras"), "sylva").is_object());
}

TEST(GltfExport, StringsStayStringsSeedIncluded) {
  // Trap: tinygltf's Value("text") becomes a bool. The seed is a string so that every
  // 64-bit value survives JSON readers that hold numbers as doubles.
  TempFolder dir;
  Skeleton sk = grow_text(kGrammar);
  sk.source.seed = std::numeric_limits<uint64_t>::max();
  sk.source.grammar = "presets/ünïcode \"quoted\".lsys";
  ASSERT_TRUE(export_gltf({{"elm \"1\"", sk}}, dir.file("p.glb")).ok());
  const Glb glb = read_glb(dir.file("p.glb"));
  const JsonValue& node = at(glb.json, "nodes").elements.at(0);
  EXPECT_EQ(at(node, "name").text, "elm \"1\"");
  const JsonValue& source = at(at(at(node, "extras"), "sylva"), "source");
  ASSERT_TRUE(at(source, "seed").is_string());
  EXPECT_EQ(at(source, "seed").text, "18446744073709551615");
  ASSERT_TRUE(at(source, "grammar").is_string());
  EXPECT_EQ(at(source, "grammar").text, sk.source.grammar);
  EXPECT_EQ(at(at(glb.json, "asset"), "version").text, "2.0");
}

TEST(GltfExport, ExtrasCarryTheSkinningDataOfEveryFrustum) {
  TempFolder dir;
  const Skeleton sk = grow_text(kGrammar);
  ASSERT_TRUE(export_gltf({{"plant", sk}}, dir.file("p.glb")).ok());
  const Glb glb = read_glb(dir.file("p.glb"));
  const JsonValue& skinning = at(at(at(at(glb.json, "nodes").elements.at(0), "extras"), "sylva"), "skinning");
  const SkinnedSkeleton skinned = skin_skeleton(sk);
  const JsonValue& frusta = at(skinning, "frusta");
  ASSERT_EQ(frusta.elements.size(), skinned.frusta.size());
  for (size_t f = 0; f < skinned.frusta.size(); ++f) {
    const JsonValue& row = frusta.elements[f];
    ASSERT_EQ(row.elements.size(), 8u);
    EXPECT_EQ(row.elements[0].number, skinned.frusta[f].chain);
    EXPECT_EQ(row.elements[1].number, skinned.frusta[f].segment);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(row.elements[3].elements.at(k).number, skinned.frusta[f].shape.lower.normal[k]);
      EXPECT_EQ(row.elements[5].elements.at(k).number, skinned.frusta[f].shape.upper.normal[k]);
    }
    EXPECT_EQ(row.elements[7].number, skinned.frusta[f].u_offset);
  }
}

TEST(GltfExport, MeshIsOneTrianglesPrimitivePerMaterialIndexWithUnitNormalsAndFrustumTexcoords) {
  TempFolder dir;
  const Skeleton sk = grow_text(kGrammar);
  GltfExportOptions o;
  o.mesh = true;
  o.segments_around = 6;
  ASSERT_TRUE(export_gltf({{"plant", sk}}, dir.file("p.glb"), o).ok());
  const Glb glb = read_glb(dir.file("p.glb"));
  const JsonValue& prims = at(at(glb.json, "meshes").elements.at(0), "primitives");
  TessellateOptions to;
  to.segments_around = 6;
  const SkinnedSkeleton skinned = skin_skeleton(sk);
  const TriangleMesh tm = tessellate(skinned, to);
  // The triangles of each material index, in tessellation order.
  std::map<uint32_t, std::vector<uint32_t>> expected;
  for (size_t t = 0; t < tm.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) expected[skinned.frusta[tm.triangle_frustum[t]].material].push_back(tm.indices[3 * t + c]);
  ASSERT_GE(expected.size(), 3u);  // the grammar's ' raises the material index
  ASSERT_EQ(prims.elements.size(), 1 + expected.size());
  const JsonValue& materials = at(glb.json, "materials");
  ASSERT_EQ(materials.elements.size(), expected.size());
  size_t p = 1;
  for (const auto& [material, indices] : expected) {
    const JsonValue& tri = prims.elements[p++];
    EXPECT_EQ(at(tri, "mode").text, "4");
    const JsonValue& m = materials.elements.at(static_cast<size_t>(at(tri, "material").number));
    EXPECT_EQ(at(m, "name").text, "sylva_material_" + std::to_string(material));
    EXPECT_EQ(at(at(at(m, "extras"), "sylva"), "material_index").number, material);
    // No bark: the material's default colour, no texture.
    const JsonValue& factor = at(at(m, "pbrMetallicRoughness"), "baseColorFactor");
    for (int k = 0; k < 3; ++k) EXPECT_EQ(factor.elements.at(k).number, default_material_albedo(material)[k]);
    EXPECT_EQ(m.find("normalTexture"), nullptr);
    EXPECT_EQ(accessor_values(glb, static_cast<size_t>(at(tri, "indices").number)),
              std::vector<double>(indices.begin(), indices.end()));
    // One set of vertex attributes shared by every triangle primitive.
    EXPECT_EQ(at(at(tri, "attributes"), "POSITION").number, at(at(prims.elements[1], "attributes"), "POSITION").number);
    EXPECT_EQ(at(tri, "attributes").find("TANGENT"), nullptr);
  }
  const auto& attr = at(prims.elements[1], "attributes");
  const std::vector<double> normals = accessor_values(glb, static_cast<size_t>(at(attr, "NORMAL").number));
  const std::vector<double> uvs = accessor_values(glb, static_cast<size_t>(at(attr, "TEXCOORD_0").number));
  ASSERT_EQ(normals.size(), tm.normals.size() * 3);
  ASSERT_EQ(uvs.size(), tm.uvs.size() * 2);
  for (size_t i = 0; i < tm.uvs.size(); ++i) {
    const double len = std::hypot(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
    EXPECT_NEAR(len, 1.0, 1e-6);
    EXPECT_EQ(uvs[2 * i], static_cast<float>(tm.uvs[i].x));  // u_repeat = v_per_metre = 1
    EXPECT_EQ(uvs[2 * i + 1], static_cast<float>(tm.uvs[i].y));
  }
}

TEST(GltfImport, RoundTripGivesTheIdenticalSkeletonFileForGlbAndGltf) {
  TempFolder dir;
  Skeleton sk = grow_text(kGrammar, 123456789012345ull);
  sk.source.seed = std::numeric_limits<uint64_t>::max() - 2;
  sk.source.defines = {{"N", 3}, {"ALPHA", 0.1}, {"BIG", 1e300}};
  GltfPlant plant{"plant", sk, {1.5, -0.25, 1e-7}, 33.3, 0.75};
  for (const char* name : {"p.glb", "p.gltf"})
    for (bool mesh : {false, true}) {
      GltfExportOptions o;
      o.mesh = mesh;
      ASSERT_TRUE(export_gltf({plant}, dir.file(name), o).ok());
      Expected<std::vector<GltfPlant>> r = import_gltf_skeletons(dir.file(name));
      ASSERT_TRUE(r.ok()) << r.error().format();
      ASSERT_EQ(r->size(), 1u);
      EXPECT_EQ((*r)[0].skeleton, sk) << name;
      EXPECT_EQ(write_skeleton_json((*r)[0].skeleton), write_skeleton_json(sk)) << name;
      EXPECT_EQ((*r)[0].name, "plant");
      for (int k = 0; k < 3; ++k) EXPECT_EQ((*r)[0].position_m[k], plant.position_m[k]);
      EXPECT_EQ((*r)[0].rotate_y_deg, 33.3);
      EXPECT_EQ((*r)[0].scale, 0.75);
    }
}

TEST(GltfImport, LeavesRoundTripThroughTheNodeExtras) {
  // docs/spec/skeleton.md version 2: a grammar's polygons are leaves, kept in extras.sylva.leaves.
  TempFolder dir;
  const Skeleton sk = grow_text("angle: 60\naxiom: F(2)[&F{.+f.-f.-f.+|+f.-f.}]F'(1){.+f.-f.-f.}\n");
  ASSERT_EQ(sk.leaves.size(), 2u);
  for (const char* name : {"p.glb", "p.gltf"}) {
    ASSERT_TRUE(export_gltf({GltfPlant{"leafy", sk}}, dir.file(name)).ok());
    Expected<std::vector<GltfPlant>> r = import_gltf_skeletons(dir.file(name));
    ASSERT_TRUE(r.ok()) << r.error().format();
    ASSERT_EQ(r->size(), 1u);
    EXPECT_EQ((*r)[0].skeleton, sk) << name;
    EXPECT_EQ(write_skeleton_json((*r)[0].skeleton), write_skeleton_json(sk)) << name;
  }
}

TEST(GltfExport, LeavesGetOneDoubleSidedPrimitivePerMaterialWithUnitNormals) {
  // Two leaves of materials 0 and 1 on wood of material 0 (the '(1) comes after the last
  // F): the LINES skeleton, the frusta's primitive and a leaf primitive per leaf material.
  TempFolder dir;
  const Skeleton sk = grow_text("angle: 60\naxiom: F(2)[&F{.+f.-f.-f.+|+f.-f.}]F'(1){.+f.-f.-f.}\n");
  ASSERT_EQ(sk.leaves.size(), 2u);
  GltfExportOptions o;
  o.mesh = true;
  ASSERT_TRUE(export_gltf({{"leafy", sk}}, dir.file("p.glb"), o).ok());
  const Glb glb = read_glb(dir.file("p.glb"));
  const JsonValue& primitives = at(at(glb.json, "meshes").elements[0], "primitives");
  ASSERT_EQ(primitives.elements.size(), 4u);
  const JsonValue& materials = at(glb.json, "materials");
  std::vector<std::string> leaf_materials;
  size_t leaf_triangles = 0;
  for (const JsonValue& p : primitives.elements) {
    const JsonValue* m = p.find("material");
    if (!m) continue;
    const JsonValue& material = materials.elements[static_cast<size_t>(m->number)];
    const JsonValue* sides = material.find("doubleSided");
    if (!sides) continue;  // the frusta's
    EXPECT_TRUE(sides->boolean);
    leaf_materials.push_back(at(material, "name").text);
    leaf_triangles += static_cast<size_t>(at(at(glb.json, "accessors").elements[static_cast<size_t>(at(p, "indices").number)], "count").number) / 3;
    const std::vector<double> normals = accessor_values(glb, static_cast<size_t>(at(at(p, "attributes"), "NORMAL").number));
    ASSERT_FALSE(normals.empty());
    for (size_t v = 0; v + 2 < normals.size(); v += 3)
      EXPECT_NEAR(std::hypot(normals[v], normals[v + 1], normals[v + 2]), 1, 1e-6);
  }
  EXPECT_EQ(leaf_materials, (std::vector<std::string>{"sylva_leaf_material_0", "sylva_leaf_material_1"}));
  EXPECT_EQ(leaf_triangles, 4u + 2u);  // a hexagon and a quadrilateral
}

// A leaf with a back material of its own (docs/leaves.md "Two colours"): two single-sided
// sheets, its front in its material and its back — copies of its vertices, normals reversed,
// wound the other way — in the back's; every leaf triangle wound counter-clockwise about its
// normals, so each sheet faces where its normals point. The back material round-trips
// through the extras, full and compact.
TEST(GltfExport, ADoubleSidedLeafIsTwoSingleSidedSheetsAndItsBackRoundTrips) {
  TempFolder dir;
  Skeleton sk = grow_text("angle: 60\naxiom: F(2)[&F{.+f.-f.-f.+|+f.-f.}]F'(1){.+f.-f.-f.}\n");
  ASSERT_EQ(sk.leaves.size(), 2u);
  sk.leaves[0].back_material = 5;
  GltfExportOptions o;
  o.mesh = true;
  ASSERT_TRUE(export_gltf({{"leafy", sk}}, dir.file("p.glb"), o).ok());
  const Glb glb = read_glb(dir.file("p.glb"));
  const JsonValue& accessors = at(glb.json, "accessors");
  std::map<std::string, std::pair<bool, size_t>> sheets;  // name → (double-sided, triangles)
  for (const JsonValue& p : at(at(glb.json, "meshes").elements[0], "primitives").elements) {
    const JsonValue* m = p.find("material");
    if (!m) continue;
    const JsonValue& material = at(glb.json, "materials").elements[static_cast<size_t>(m->number)];
    if (!material.find("doubleSided")) continue;  // the frusta's
    const size_t count = static_cast<size_t>(at(accessors.elements[static_cast<size_t>(at(p, "indices").number)], "count").number);
    sheets[at(material, "name").text] = {at(material, "doubleSided").boolean, count / 3};
    const std::vector<double> index = accessor_values(glb, static_cast<size_t>(at(p, "indices").number));
    const std::vector<double> pos = accessor_values(glb, static_cast<size_t>(at(at(p, "attributes"), "POSITION").number));
    const std::vector<double> nrm = accessor_values(glb, static_cast<size_t>(at(at(p, "attributes"), "NORMAL").number));
    for (size_t t = 0; t + 2 < count; t += 3) {
      glm::dvec3 v[3];
      for (int k = 0; k < 3; ++k) {
        const size_t i = static_cast<size_t>(index[t + static_cast<size_t>(k)]);
        v[k] = {pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]};
      }
      const size_t i0 = static_cast<size_t>(index[t]);
      EXPECT_GT(glm::dot(glm::cross(v[1] - v[0], v[2] - v[0]), glm::dvec3(nrm[3 * i0], nrm[3 * i0 + 1], nrm[3 * i0 + 2])), 0)
          << at(material, "name").text << " triangle " << t / 3;
    }
  }
  const std::map<std::string, std::pair<bool, size_t>> want = {{"sylva_leaf_material_0_one_side", {false, 4}},
                                                                {"sylva_leaf_material_5_one_side", {false, 4}},
                                                                {"sylva_leaf_material_1", {true, 2}}};
  EXPECT_EQ(sheets, want);
  for (const GltfExtras extras : {GltfExtras::full, GltfExtras::compact}) {
    o.extras = extras;
    ASSERT_TRUE(export_gltf({{"leafy", sk}}, dir.file("q.glb"), o).ok());
    Expected<std::vector<GltfPlant>> r = import_gltf_skeletons(dir.file("q.glb"));
    ASSERT_TRUE(r.ok()) << r.error().format();
    EXPECT_EQ((*r)[0].skeleton, sk);
  }
}

TEST(GltfExport, SameInputGivesByteIdenticalFiles) {
  TempFolder dir;
  const Skeleton sk = grow_text(kGrammar);
  GltfExportOptions o;
  o.mesh = true;
  ASSERT_TRUE(export_gltf({{"plant", sk}}, dir.file("a.glb"), o).ok());
  ASSERT_TRUE(export_gltf({{"plant", sk}}, dir.file("b.glb"), o).ok());
  EXPECT_EQ(slurp(dir.file("a.glb")), slurp(dir.file("b.glb")));
}

TEST(GltfExport, InstancingPutsIdenticalPlantsOnOneNodeWithExactPlacementsInExtras) {
  TempFolder dir;
  const Skeleton a = grow_text(kGrammar, 1), b = grow_text("axiom: F(2)\n", 1);
  std::vector<GltfPlant> forest = {{"a0", a, {0, 0, 0}, 0, 1},
                                   {"b0", b, {-3, 0, 1}, 10, 1},
                                   {"a1", a, {3, 0, 0}, 90, 1.5},
                                   {"a2", a, {0, 0.5, 3}, -45, 0.5}};
  GltfExportOptions o;
  o.instancing = true;
  o.mesh = true;
  ASSERT_TRUE(export_gltf(forest, dir.file("f.glb"), o).ok());
  const Glb glb = read_glb(dir.file("f.glb"));
  const JsonValue& used = at(glb.json, "extensionsUsed");
  ASSERT_EQ(used.elements.size(), 1u);
  EXPECT_EQ(used.elements[0].text, "EXT_mesh_gpu_instancing");
  // Required: the instances have no fallback placement outside the extension.
  const JsonValue& required = at(glb.json, "extensionsRequired");
  ASSERT_EQ(required.elements.size(), 1u);
  EXPECT_EQ(required.elements[0].text, "EXT_mesh_gpu_instancing");
  const JsonValue& nodes = at(glb.json, "nodes");
  ASSERT_EQ(nodes.elements.size(), 2u);  // a0/a1/a2 share one node, b0 has its own
  EXPECT_EQ(at(nodes.elements[0], "name").text, "a0");
  EXPECT_EQ(nodes.elements[1].find("extensions"), nullptr);
  EXPECT_EQ(at(nodes.elements[1], "translation").elements.at(0).number, -3);
  const JsonValue& attrs = at(at(at(nodes.elements[0], "extensions"), "EXT_mesh_gpu_instancing"), "attributes");
  const std::vector<double> t = accessor_values(glb, static_cast<size_t>(at(attrs, "TRANSLATION").number));
  const std::vector<double> r = accessor_values(glb, static_cast<size_t>(at(attrs, "ROTATION").number));
  const std::vector<double> s = accessor_values(glb, static_cast<size_t>(at(attrs, "SCALE").number));
  const std::vector<double> expect_t = {0, 0, 0, 3, 0, 0, 0, 0.5, 3};
  const std::vector<double> expect_s = {1, 1, 1, 1.5, 1.5, 1.5, 0.5, 0.5, 0.5};
  EXPECT_EQ(t, expect_t);
  EXPECT_EQ(s, expect_s);
  ASSERT_EQ(r.size(), 12u);
  const double angles[3] = {0, 90, -45};
  for (int i = 0; i < 3; ++i) {
    const double half = angles[i] * std::numbers::pi / 360;
    EXPECT_EQ(r[4 * i], 0);
    EXPECT_NEAR(r[4 * i + 1], std::sin(half), 1e-7);
    EXPECT_EQ(r[4 * i + 2], 0);
    EXPECT_NEAR(r[4 * i + 3], std::cos(half), 1e-7);
    EXPECT_NEAR(std::hypot(r[4 * i + 1], r[4 * i + 3]), 1, 1e-7);
  }
  // Each instancing attribute accessor has one element per instance and no target.
  for (const char* name : {"TRANSLATION", "ROTATION", "SCALE"}) {
    const JsonValue& acc = at(glb.json, "accessors").elements.at(static_cast<size_t>(at(attrs, name).number));
    EXPECT_EQ(at(acc, "count").number, 3);
    const JsonValue& view = at(glb.json, "bufferViews").elements.at(static_cast<size_t>(at(acc, "bufferView").number));
    EXPECT_EQ(view.find("target"), nullptr);
  }
  Expected<std::vector<GltfPlant>> imported = import_gltf_skeletons(dir.file("f.glb"));
  ASSERT_TRUE(imported.ok()) << imported.error().format();
  const std::vector<GltfPlant>& back = *imported;
  ASSERT_EQ(back.size(), 4u);
  const char* names[4] = {"a0", "a1", "a2", "b0"};
  const GltfPlant* originals[4] = {&forest[0], &forest[2], &forest[3], &forest[1]};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(back[i].name, names[i]);
    EXPECT_EQ(write_skeleton_json(back[i].skeleton), write_skeleton_json(originals[i]->skeleton));
    for (int k = 0; k < 3; ++k) EXPECT_EQ(back[i].position_m[k], originals[i]->position_m[k]);
    EXPECT_EQ(back[i].rotate_y_deg, originals[i]->rotate_y_deg);
    EXPECT_EQ(back[i].scale, originals[i]->scale);
  }
  // Without instancing every plant is its own node.
  ASSERT_TRUE(export_gltf(forest, dir.file("g.glb")).ok());
  EXPECT_EQ(at(read_glb(dir.file("g.glb")).json, "nodes").elements.size(), 4u);
}

TEST(GltfExport, TinygltfReadsOurFilesWithModeMinMaxAndStringExtras) {
  // The independent second reader: Debian's tinygltf 2.7.
  TempFolder dir;
  Skeleton sk = grow_text(kGrammar);
  sk.source.seed = 9007199254740993ull;  // 2^53 + 1: not a double
  GltfExportOptions o;
  o.mesh = true;
  for (const char* name : {"p.glb", "p.gltf"}) {
    ASSERT_TRUE(export_gltf({{"plant", sk, {1, 2, 3}, 30, 2}}, dir.file(name), o).ok());
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string err, warn;
    const bool ok = std::string(name).ends_with(".glb") ? loader.LoadBinaryFromFile(&model, &err, &warn, dir.file(name))
                                                        : loader.LoadASCIIFromFile(&model, &err, &warn, dir.file(name));
    ASSERT_TRUE(ok) << err;
    EXPECT_TRUE(warn.empty()) << warn;
    ASSERT_EQ(model.nodes.size(), 1u);
    ASSERT_EQ(model.meshes.size(), 1u);
    ASSERT_GE(model.meshes[0].primitives.size(), 2u);
    EXPECT_EQ(model.meshes[0].primitives[0].mode, TINYGLTF_MODE_LINE);
    for (size_t p = 1; p < model.meshes[0].primitives.size(); ++p)
      EXPECT_EQ(model.meshes[0].primitives[p].mode, TINYGLTF_MODE_TRIANGLES);
    for (const tinygltf::Accessor& a : model.accessors) {
      EXPECT_FALSE(a.minValues.empty());
      EXPECT_EQ(a.minValues.size(), a.maxValues.size());
    }
    const tinygltf::Value& seed = model.nodes[0].extras.Get("sylva").Get("source").Get("seed");
    ASSERT_TRUE(seed.IsString());
    EXPECT_EQ(seed.Get<std::string>(), "9007199254740993");
    EXPECT_EQ(model.nodes[0].name, "plant");
    ASSERT_EQ(model.nodes[0].rotation.size(), 4u);
    EXPECT_NEAR(model.nodes[0].rotation[1], std::sin(30 * std::numbers::pi / 360), 1e-15);
  }
}

TEST(GltfExport, RefusesBadInputAndLeavesAnExistingFileUntouched) {
  TempFolder dir;
  const std::string path = dir.write("keep.glb", "old contents");
  const Skeleton sk = grow_text(kGrammar);
  EXPECT_FALSE(export_gltf({}, path).ok());
  EXPECT_FALSE(export_gltf({{"p", sk, {0, 0, 0}, 0, 0}}, path).ok());  // scale 0
  EXPECT_FALSE(export_gltf({{"p", sk, {NAN, 0, 0}, 0, 1}}, path).ok());
  Skeleton bad = sk;
  bad.joints[1].radius_m = -1;
  Status err = export_gltf({{"p", bad}}, path);
  ASSERT_FALSE(err.ok());
  EXPECT_EQ(err.error().file, path);
  EXPECT_NE(err.error().message.find("joint"), std::string::npos) << err.error().format();
  GltfExportOptions o;
  o.segments_around = 2;
  EXPECT_FALSE(export_gltf({{"p", sk}}, path, o).ok());
  EXPECT_EQ(slurp(path), "old contents");
  EXPECT_FALSE(export_gltf({{"p", sk}}, dir.file("p.obj")).ok());
  EXPECT_FALSE(fs::exists(dir.file("p.obj")));
  EXPECT_FALSE(export_gltf({{"p", sk}}, dir.file("no/such/folder/p.glb")).ok());
  // Only the result is in the folder: no temporary file left behind.
  size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.file(""))) ++entries;
  EXPECT_EQ(entries, 1u);
}

// --- Bark: materials, textures, the baked normal map --------------------------------

const std::string kBarkAlbedo = std::string(SYLVA_SOURCE_DIR) + "/presets/textures/bark.png";
const std::string kBarkHeight = std::string(SYLVA_SOURCE_DIR) + "/presets/textures/bark_height.png";

Bark textured_bark() {
  Bark b;
  b.albedo_texture = kBarkAlbedo;
  b.height_texture = kBarkHeight;
  b.relief_depth_m = 0.01;
  b.u_repeat = 2;
  b.v_per_metre = 3;
  return b;
}

// A vertical cylinder of radius `radius_m` from y = 0 to y = 2, in `segments` segments.
Skeleton cylinder(double radius_m, uint32_t segments = 1) {
  Skeleton sk;
  for (uint32_t k = 0; k <= segments; ++k) sk.joints.push_back({{0, 2.0 * k / segments, 0}, radius_m, 0});
  sk.chains = {{0, segments + 1, std::nullopt}};
  return sk;
}

TEST(GltfExport, BarkTexturesGoToTheWoodMaterialOnlyWithAlbedoNormalMapAndUnitTangents) {
  TempFolder dir;
  const Skeleton sk = grow_text(kGrammar);
  const SkinnedSkeleton skinned = skin_skeleton(sk);
  std::set<uint32_t> used;
  for (const Frustum& f : skinned.frusta) used.insert(f.material);
  ASSERT_GE(used.size(), 3u);
  GltfExportOptions o;
  o.mesh = true;
  o.segments_around = 6;
  GltfPlant plant{"plant", sk};
  plant.bark = textured_bark();
  TessellateOptions to;
  to.segments_around = 6;
  const TriangleMesh tm = tessellate(skinned, to);
  const std::string albedo_bytes = slurp(kBarkAlbedo);
  for (const char* name : {"p.glb", "p.gltf"}) {
    ASSERT_TRUE(export_gltf({plant}, dir.file(name), o).ok());
    tinygltf::Model model;
    ASSERT_TRUE(load_with_tinygltf(dir.file(name), &model));
    // One material per material index used; the wood's (0) shows the two images, the
    // others (needles, leaves: materials.h) keep their own colour and no bark.
    ASSERT_EQ(model.materials.size(), used.size()) << name;
    ASSERT_EQ(model.images.size(), 2u) << name;
    ASSERT_EQ(model.textures.size(), 2u) << name;
    size_t k = 0;
    int albedo = -1, normal = -1;
    ASSERT_EQ(*used.begin(), 0u);
    for (uint32_t m : used) {
      const tinygltf::Material& mat = model.materials[k++];
      EXPECT_EQ(mat.name, "sylva_material_" + std::to_string(m));
      const tinygltf::Value& extras = mat.extras.Get("sylva");
      EXPECT_EQ(extras.Get("material_index").GetNumberAsInt(), static_cast<int>(m));
      if (m != 0) {
        EXPECT_EQ(mat.pbrMetallicRoughness.baseColorTexture.index, -1) << m;
        EXPECT_EQ(mat.normalTexture.index, -1) << m;
        const double* rgb = default_material_albedo(m);
        EXPECT_EQ(mat.pbrMetallicRoughness.baseColorFactor, std::vector<double>({rgb[0], rgb[1], rgb[2], 1})) << m;
        EXPECT_FALSE(extras.Has("albedo")) << m;
        EXPECT_FALSE(extras.Has("height")) << m;
        continue;
      }
      albedo = mat.pbrMetallicRoughness.baseColorTexture.index;
      normal = mat.normalTexture.index;
      ASSERT_GE(albedo, 0);
      ASSERT_GE(normal, 0);
      EXPECT_NE(albedo, normal);
      EXPECT_EQ(mat.pbrMetallicRoughness.baseColorFactor, std::vector<double>({1, 1, 1, 1}));
      EXPECT_EQ(extras.Get("albedo").Get<std::string>(), kBarkAlbedo);
      EXPECT_EQ(extras.Get("height").Get<std::string>(), kBarkHeight);
      EXPECT_EQ(extras.Get("relief_depth_m").GetNumberAsDouble(), 0.01);
      EXPECT_EQ(extras.Get("u_repeat").GetNumberAsDouble(), 2);
      EXPECT_EQ(extras.Get("v_per_metre").GetNumberAsDouble(), 3);
      EXPECT_EQ(extras.Get("r_ref_m").GetNumberAsDouble(), bark_reference_radius_m(sk));
    }
    // The albedo is the file itself; the normal map a 512 × 512 map of mostly-up normals.
    const tinygltf::Image& albedo_image = model.images.at(static_cast<size_t>(model.textures.at(static_cast<size_t>(albedo)).source));
    const tinygltf::Image& normal_image = model.images.at(static_cast<size_t>(model.textures.at(static_cast<size_t>(normal)).source));
    EXPECT_EQ(albedo_image.width, 512);
    EXPECT_EQ(albedo_image.height, 512);
    if (std::string(name) == "p.glb") {
      EXPECT_EQ(albedo_image.mimeType, "image/png");
      const tinygltf::BufferView& view = model.bufferViews.at(static_cast<size_t>(albedo_image.bufferView));
      const auto& data = model.buffers.at(0).data;
      EXPECT_EQ(std::string(data.begin() + static_cast<std::ptrdiff_t>(view.byteOffset),
                            data.begin() + static_cast<std::ptrdiff_t>(view.byteOffset + view.byteLength)),
                albedo_bytes);
    }
    ASSERT_EQ(normal_image.width, 512);
    ASSERT_EQ(normal_image.height, 512);
    ASSERT_GE(normal_image.component, 3);
    double mean[3] = {0, 0, 0};
    const size_t texels = 512 * 512;
    for (size_t t = 0; t < texels; ++t)
      for (int c = 0; c < 3; ++c) mean[c] += normal_image.image[t * static_cast<size_t>(normal_image.component) + c] / 255.0 / texels;
    EXPECT_NEAR(mean[0], 0.5, 0.02);
    EXPECT_NEAR(mean[1], 0.5, 0.02);
    EXPECT_GT(mean[2], 0.85);
    // Every triangle primitive carries unit tangents ⊥ the normal, one per vertex.
    const tinygltf::Mesh& mesh = model.meshes.at(0);
    ASSERT_EQ(mesh.primitives.size(), 1 + used.size());
    for (size_t p = 1; p < mesh.primitives.size(); ++p) {
      const auto& attributes = mesh.primitives[p].attributes;
      ASSERT_TRUE(attributes.count("TANGENT")) << p;
      EXPECT_EQ(model.accessors.at(static_cast<size_t>(attributes.at("TANGENT"))).count,
                model.accessors.at(static_cast<size_t>(attributes.at("POSITION"))).count);
      EXPECT_EQ(model.accessors.at(static_cast<size_t>(attributes.at("TANGENT"))).type, TINYGLTF_TYPE_VEC4);
    }
    const auto& attributes = mesh.primitives[1].attributes;
    const std::vector<float> tangents = floats_of(model, attributes.at("TANGENT"));
    const std::vector<float> normals = floats_of(model, attributes.at("NORMAL"));
    const std::vector<float> uvs = floats_of(model, attributes.at("TEXCOORD_0"));
    ASSERT_EQ(tangents.size(), tm.positions.size() * 4);
    ASSERT_EQ(uvs.size(), tm.positions.size() * 2);
    for (size_t v = 0; v < tm.positions.size(); ++v) {
      const float* t = &tangents[4 * v];
      const float* n = &normals[3 * v];
      EXPECT_NEAR(std::hypot(t[0], t[1], t[2]), 1.0, 1e-6) << v;
      EXPECT_TRUE(t[3] == 1.0f || t[3] == -1.0f) << v;
      EXPECT_NEAR(t[0] * n[0] + t[1] * n[1] + t[2] * n[2], 0.0, 1e-5) << v;
      EXPECT_EQ(uvs[2 * v], static_cast<float>(tm.uvs[v].x * 2)) << v;
      EXPECT_EQ(uvs[2 * v + 1], static_cast<float>(tm.uvs[v].y * 3)) << v;
    }
  }
}

TEST(GltfExport, TheBakedNormalMapShadesLikeTheReliefInAGltfViewer) {
  // A cylinder of radius 0.1 m with an analytic height field; a glTF viewer's shading
  // normal (normal map texel, B = cross(N, T)·w) must match the normal of the relief,
  // computed from the mesh's own UV Jacobian — independent of the exporter's conventions.
  TempFolder dir;
  const uint32_t width = 128, height = 64;
  auto h = [](double s, double t) {
    return 0.5 + 0.25 * std::sin(2 * std::numbers::pi * 2 * s) + 0.25 * std::sin(2 * std::numbers::pi * 3 * t);
  };
  auto dh_ds = [](double s) { return 0.25 * 2 * std::numbers::pi * 2 * std::cos(2 * std::numbers::pi * 2 * s); };
  auto dh_dt = [](double t) { return 0.25 * 2 * std::numbers::pi * 3 * std::cos(2 * std::numbers::pi * 3 * t); };
  std::vector<float> heights;
  for (uint32_t j = 0; j < height; ++j)
    for (uint32_t i = 0; i < width; ++i) heights.push_back(static_cast<float>(h((i + 0.5) / width, (j + 0.5) / height)));
  ASSERT_TRUE(write_image_atomically(dir.file("h.exr"), width, height, {"Y"}, heights, {ChannelFormat::float32}, false).ok());
  GltfPlant plant{"cylinder", cylinder(0.1, 50)};  // rows every 4 cm: t sampled at 100 values
  plant.bark.height_texture = dir.file("h.exr");
  plant.bark.relief_depth_m = 0.01;
  plant.bark.u_repeat = 2;
  plant.bark.v_per_metre = 2;
  GltfExportOptions o;
  o.mesh = true;
  o.segments_around = 64;
  ASSERT_TRUE(export_gltf({plant}, dir.file("c.glb"), o).ok());
  tinygltf::Model model;
  ASSERT_TRUE(load_with_tinygltf(dir.file("c.glb"), &model));
  ASSERT_EQ(model.materials.size(), 1u);
  const tinygltf::Image& map = model.images.at(static_cast<size_t>(
      model.textures.at(static_cast<size_t>(model.materials[0].normalTexture.index)).source));
  ASSERT_EQ(map.width, static_cast<int>(width));
  ASSERT_EQ(map.height, static_cast<int>(height));
  const tinygltf::Primitive& prim = model.meshes.at(0).primitives.at(1);
  const std::vector<float> pos = floats_of(model, prim.attributes.at("POSITION"));
  const std::vector<float> nrm = floats_of(model, prim.attributes.at("NORMAL"));
  const std::vector<float> tan = floats_of(model, prim.attributes.at("TANGENT"));
  const std::vector<float> uv = floats_of(model, prim.attributes.at("TEXCOORD_0"));
  const tinygltf::Accessor& index_accessor = model.accessors.at(static_cast<size_t>(prim.indices));
  const tinygltf::BufferView& index_view = model.bufferViews.at(static_cast<size_t>(index_accessor.bufferView));
  std::vector<uint32_t> indices(index_accessor.count);
  std::memcpy(indices.data(), model.buffers[0].data.data() + index_view.byteOffset, indices.size() * 4);
  auto vec = [](const std::vector<float>& a, size_t i, size_t n) {
    return glm::dvec3(a[n * i], a[n * i + 1], n > 2 ? a[n * i + 2] : 0.0);
  };
  size_t checked = 0;
  double worst_deg = 0;
  for (size_t tri = 0; tri + 2 < indices.size(); tri += 3) {
    const uint32_t a = indices[tri], b = indices[tri + 1], c = indices[tri + 2];
    if (std::abs(nrm[3 * a + 1]) > 0.5 || std::abs(nrm[3 * b + 1]) > 0.5 || std::abs(nrm[3 * c + 1]) > 0.5) continue;
    // ∂p/∂s and ∂p/∂t of the triangle: [p_b − p_a, p_c − p_a] = J · [uv_b − uv_a, uv_c − uv_a].
    const glm::dvec3 e1 = vec(pos, b, 3) - vec(pos, a, 3), e2 = vec(pos, c, 3) - vec(pos, a, 3);
    const glm::dvec3 d1 = vec(uv, b, 2) - vec(uv, a, 2), d2 = vec(uv, c, 2) - vec(uv, a, 2);
    const double det = d1.x * d2.y - d2.x * d1.y;
    ASSERT_NE(det, 0.0);
    const glm::dvec3 dp_ds = (e1 * d2.y - e2 * d1.y) / det, dp_dt = (e2 * d1.x - e1 * d2.x) / det;
    // The relief's normal at vertex a, with the gradient at the texel a glTF viewer reads.
    const double s = vec(uv, a, 2).x, t = vec(uv, a, 2).y;
    const uint32_t i = static_cast<uint32_t>(std::floor((s - std::floor(s)) * width)) % width;
    const uint32_t j = static_cast<uint32_t>(std::floor((t - std::floor(t)) * height)) % height;
    const double s_c = (i + 0.5) / width, t_c = (j + 0.5) / height;
    const glm::dvec3 n = glm::normalize(vec(nrm, a, 3));
    const glm::dvec3 expected = glm::normalize(n - 0.01 * dh_ds(s_c) / glm::length(dp_ds) * glm::normalize(dp_ds) -
                                               0.01 * dh_dt(t_c) / glm::length(dp_dt) * glm::normalize(dp_dt));
    // The viewer: n = x·T + y·B + z·N, B = cross(N, T)·w, (x, y, z) = 2·texel − 1.
    const unsigned char* texel = &map.image[(size_t{j} * width + i) * static_cast<size_t>(map.component)];
    const glm::dvec3 tangent_space(texel[0] / 255.0 * 2 - 1, texel[1] / 255.0 * 2 - 1, texel[2] / 255.0 * 2 - 1);
    const glm::dvec3 T(tan[4 * a], tan[4 * a + 1], tan[4 * a + 2]);
    const glm::dvec3 B = glm::cross(n, T) * static_cast<double>(tan[4 * a + 3]);
    const glm::dvec3 shaded = glm::normalize(tangent_space.x * T + tangent_space.y * B + tangent_space.z * n);
    const double angle_deg = std::acos(std::min(1.0, glm::dot(shaded, expected))) * 180 / std::numbers::pi;
    worst_deg = std::max(worst_deg, angle_deg);
    ++checked;
  }
  EXPECT_EQ(checked, 50u * 64 * 2);  // every side triangle
  // The relief tilts normals by up to ~5.7° around and ~5.4° along; a flipped axis would
  // be off by twice that.
  EXPECT_LT(worst_deg, 1.0);
}

TEST(GltfExport, WithoutTexturesMaterialsTakeTheTableColourAndABarkColourReplacesMaterialZero) {
  TempFolder dir;
  GltfPlant plant{"plant", grow_text(kGrammar)};
  plant.bark.albedo_rgb = glm::dvec3(0.5, 0.4, 0.3);
  GltfExportOptions o;
  o.mesh = true;
  ASSERT_TRUE(export_gltf({plant}, dir.file("p.glb"), o).ok());
  const Glb glb = read_glb(dir.file("p.glb"));
  for (const char* absent : {"images", "textures", "samplers"}) EXPECT_EQ(glb.json.find(absent), nullptr) << absent;
  const JsonValue& materials = at(glb.json, "materials");
  ASSERT_GE(materials.elements.size(), 3u);
  for (const JsonValue& m : materials.elements) {
    const uint32_t index = static_cast<uint32_t>(at(at(at(m, "extras"), "sylva"), "material_index").number);
    const JsonValue& factor = at(at(m, "pbrMetallicRoughness"), "baseColorFactor");
    const double* table = default_material_albedo(index);
    const glm::dvec3 expected = index == 0 ? glm::dvec3(0.5, 0.4, 0.3) : glm::dvec3(table[0], table[1], table[2]);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(factor.elements.at(k).number, expected[k]) << index;
    EXPECT_EQ(m.find("normalTexture"), nullptr);
  }
  for (const JsonValue& prim : at(at(glb.json, "meshes").elements.at(0), "primitives").elements)
    EXPECT_EQ(at(prim, "attributes").find("TANGENT"), nullptr);
}

TEST(GltfExport, TheScenesMaterialTableGivesOneSharedMaterialPerEntry) {
  // docs/materials.md: a table entry's albedo and specular weight; a bark colour still
  // comes first on the wood; two plants with different barks share every material the
  // bark does not cover.
  TempFolder dir;
  GltfPlant plain{"plain", grow_text(kGrammar)};
  GltfPlant barked = plain;
  barked.name = "barked";
  barked.position_m[0] = 3;
  barked.bark.albedo_rgb = glm::dvec3(0.5, 0.4, 0.3);
  GltfExportOptions o;
  o.mesh = true;
  o.materials = {{0, {glm::dvec3(0.1, 0.2, 0.3), 0.25}}, {1, {glm::dvec3(0.6, 0.1, 0.5), 0}}};
  std::set<uint32_t> used;
  for (const Frustum& f : skin_skeleton(plain.skeleton).frusta) used.insert(f.material);
  ASSERT_TRUE(used.count(0) && used.count(1) && used.size() >= 3);
  ASSERT_TRUE(export_gltf({plain, barked}, dir.file("p.glb"), o).ok());
  const Glb glb = read_glb(dir.file("p.glb"));
  const JsonValue& materials = at(glb.json, "materials");
  ASSERT_EQ(materials.elements.size(), used.size() + 1);  // material 0 twice: table and bark
  std::map<uint32_t, int> seen;
  for (const JsonValue& m : materials.elements) {
    const JsonValue& extras = at(at(m, "extras"), "sylva");
    const uint32_t index = static_cast<uint32_t>(at(extras, "material_index").number);
    ++seen[index];
    const JsonValue& factor = at(at(m, "pbrMetallicRoughness"), "baseColorFactor");
    const glm::dvec3 rgb(factor.elements.at(0).number, factor.elements.at(1).number, factor.elements.at(2).number);
    if (index == 0) {
      EXPECT_TRUE(rgb == glm::dvec3(0.1, 0.2, 0.3) || rgb == glm::dvec3(0.5, 0.4, 0.3)) << rgb.x;
      EXPECT_EQ(at(extras, "specular").number, 0.25);
    } else if (index == 1) {
      EXPECT_EQ(rgb, glm::dvec3(0.6, 0.1, 0.5));
      EXPECT_EQ(at(extras, "specular").number, 0);
    } else {
      const double* d = default_material_albedo(index);
      EXPECT_EQ(rgb, glm::dvec3(d[0], d[1], d[2])) << index;
      EXPECT_EQ(extras.find("specular"), nullptr) << index;  // not in the table
    }
  }
  EXPECT_EQ(seen[0], 2);
  EXPECT_EQ(seen[1], 1);
}

TEST(GltfExport, TheTablesImageOnSegmentsIsABaseColorTextureWithItsOwnTexcoords) {
  // docs/materials.md: an entry with an albedo image and repeats textures its segments;
  // where its repeats differ from the bark's TEXCOORD_0, its primitive reads TEXCOORD_1.
  // Entry 0's image covers the wood of a plant without a bark albedo only.
  TempFolder dir;
  const std::string tiles = std::string(SYLVA_SOURCE_DIR) + "/presets/textures/tiles.png";
  const std::string cactus = std::string(SYLVA_SOURCE_DIR) + "/presets/textures/cactus.png";
  GltfPlant plain{"plain", grow_text(kGrammar)};
  GltfPlant barked = plain;
  barked.name = "barked";
  barked.position_m[0] = 3;
  barked.bark = textured_bark();  // bark.png, u_repeat 2, v_per_metre 3
  GltfExportOptions o;
  o.mesh = true;
  o.segments_around = 6;
  o.materials[1].albedo_image = tiles;
  o.materials[1].segment_repeat = SceneMaterial::Repeat{4, 5};
  o.materials[0].albedo_image = cactus;
  o.materials[0].segment_repeat = SceneMaterial::Repeat{2, 3};
  TessellateOptions to;
  to.segments_around = 6;
  const TriangleMesh tm = tessellate(skin_skeleton(plain.skeleton), to);
  ASSERT_TRUE(export_gltf({plain, barked}, dir.file("p.glb"), o).ok());
  tinygltf::Model model;
  ASSERT_TRUE(load_with_tinygltf(dir.file("p.glb"), &model));
  auto image_bytes = [&](int texture) {
    const tinygltf::Image& image = model.images.at(static_cast<size_t>(model.textures.at(static_cast<size_t>(texture)).source));
    const tinygltf::BufferView& view = model.bufferViews.at(static_cast<size_t>(image.bufferView));
    const auto& data = model.buffers.at(0).data;
    return std::string(data.begin() + static_cast<std::ptrdiff_t>(view.byteOffset),
                       data.begin() + static_cast<std::ptrdiff_t>(view.byteOffset + view.byteLength));
  };
  ASSERT_EQ(model.meshes.size(), 2u);
  size_t checked = 0;
  for (const tinygltf::Mesh& mesh : model.meshes) {
    const bool is_barked = mesh.name == "barked";
    const double bark_u = is_barked ? 2 : 1, bark_v = is_barked ? 3 : 1;
    for (const tinygltf::Primitive& prim : mesh.primitives) {
      if (prim.mode != TINYGLTF_MODE_TRIANGLES) continue;
      const tinygltf::Material& mat = model.materials.at(static_cast<size_t>(prim.material));
      const int index = mat.extras.Get("sylva").Get("material_index").GetNumberAsInt();
      const tinygltf::TextureInfo& base = mat.pbrMetallicRoughness.baseColorTexture;
      if (index > 1) {
        EXPECT_EQ(base.index, -1) << mesh.name << " " << index;
        EXPECT_FALSE(prim.attributes.count("TEXCOORD_1")) << mesh.name << " " << index;
        continue;
      }
      ASSERT_GE(base.index, 0) << mesh.name << " " << index;
      // Which image, with which repeats: the bark's on the barked wood, else the table's.
      const bool bark = is_barked && index == 0;
      const std::string file = bark ? kBarkAlbedo : index == 0 ? cactus : tiles;
      EXPECT_EQ(image_bytes(base.index), slurp(file)) << mesh.name << " " << index;
      const double u_repeat = bark ? 2 : index == 0 ? 2 : 4, v_per_metre = bark ? 3 : index == 0 ? 3 : 5;
      const bool own = u_repeat != bark_u || v_per_metre != bark_v;
      EXPECT_EQ(base.texCoord, own ? 1 : 0) << mesh.name << " " << index;
      ASSERT_EQ(prim.attributes.count("TEXCOORD_1"), own ? 1u : 0u) << mesh.name << " " << index;
      EXPECT_EQ(mat.extras.Get("sylva").Has("segment_texture"), !bark) << mesh.name << " " << index;
      const std::vector<float> st = floats_of(model, prim.attributes.at(own ? "TEXCOORD_1" : "TEXCOORD_0"));
      ASSERT_EQ(st.size(), tm.uvs.size() * 2);
      for (size_t v = 0; v < tm.uvs.size(); ++v) {
        EXPECT_EQ(st[2 * v], static_cast<float>(tm.uvs[v].x * u_repeat)) << v;
        EXPECT_EQ(st[2 * v + 1], static_cast<float>(tm.uvs[v].y * v_per_metre)) << v;
      }
      ++checked;
    }
  }
  EXPECT_EQ(checked, 4u);  // materials 0 and 1 of both plants
}

TEST(GltfExport, TheReferenceRadiusIsTheMedianSegmentRadius) {
  EXPECT_DOUBLE_EQ(bark_reference_radius_m(cylinder(0.1)), 0.1);
  Skeleton sk;
  sk.joints = {{{0, 0, 0}, 0.4, 0}, {{0, 1, 0}, 0.3, 0}, {{0, 2, 0}, 0.2, 0}, {{0, 3, 0}, 0.1, 0}, {{0, 4, 0}, 0.0, 0}};
  sk.chains = {{0, 5, std::nullopt}};
  EXPECT_DOUBLE_EQ(bark_reference_radius_m(sk), (0.25 + 0.15) / 2);  // 0.35, 0.25, 0.15, 0.05
  EXPECT_EQ(bark_reference_radius_m(Skeleton{}), 0.0);
}

TEST(GltfExport, MissingOrUnusableTexturesAreErrorsNamingTheFileAndNothingIsWritten) {
  TempFolder dir;
  const std::string path = dir.write("keep.glb", "old contents");
  const std::string not_an_image = dir.write("notes.png", "just text");
  const Skeleton sk = grow_text(kGrammar);
  GltfExportOptions o;
  o.mesh = true;
  struct Case {
    std::optional<std::string> albedo, height;
    std::string file, message;
  };
  const std::vector<Case> cases = {
      {dir.file("missing.png"), std::nullopt, dir.file("missing.png"), "albedo"},
      {std::nullopt, dir.file("missing_height.png"), dir.file("missing_height.png"), "height map"},
      {not_an_image, std::nullopt, not_an_image, "PNG or JPEG"},
      {std::nullopt, not_an_image, not_an_image, "height map"},
      {kBarkAlbedo, dir.file("missing_height.png"), dir.file("missing_height.png"), "height map"},
  };
  for (const Case& c : cases) {
    GltfPlant plant{"p", sk};
    plant.bark.albedo_texture = c.albedo;
    plant.bark.height_texture = c.height;
    Status err = export_gltf({plant}, path, o);
    ASSERT_FALSE(err.ok()) << c.file;
    EXPECT_EQ(err.error().file, c.file);
    const std::string text = err.error().format();
    EXPECT_NE(text.find(c.file), std::string::npos) << text;
    EXPECT_NE(text.find(c.message), std::string::npos) << text;
    Status checked = check_bark_textures(plant.bark);
    ASSERT_FALSE(checked.ok());
    EXPECT_EQ(checked.error().format(), text);
    EXPECT_EQ(slurp(path), "old contents");
  }
  // Without a mesh the bark is not used and its textures are not read.
  GltfPlant plant{"p", sk};
  plant.bark.albedo_texture = dir.file("missing.png");
  EXPECT_TRUE(export_gltf({plant}, dir.file("lines.glb")).ok());
  // Bark numbers out of range are refused too.
  plant.bark = Bark{};
  plant.bark.u_repeat = 0;
  EXPECT_FALSE(export_gltf({plant}, path, o).ok());
  EXPECT_EQ(slurp(path), "old contents");
}

TEST(GltfExport, TexturedExportsAreByteIdenticalAndInstancingComparesBarks) {
  TempFolder dir;
  GltfPlant plant{"plant", grow_text(kGrammar)};
  plant.bark = textured_bark();
  GltfExportOptions o;
  o.mesh = true;
  ASSERT_TRUE(export_gltf({plant}, dir.file("a.glb"), o).ok());
  ASSERT_TRUE(export_gltf({plant}, dir.file("b.glb"), o).ok());
  EXPECT_EQ(slurp(dir.file("a.glb")), slurp(dir.file("b.glb")));
  // Two identical plants share a node; the same skeleton with another bark does not, and
  // its wood material is a new one while the images and the other materials (which the
  // bark does not cover, materials.h) are shared.
  GltfPlant other = plant;
  other.bark.v_per_metre = 5;
  GltfPlant moved = plant;
  moved.position_m[0] = 3;
  o.instancing = true;
  ASSERT_TRUE(export_gltf({plant, moved, other}, dir.file("f.glb"), o).ok());
  const Glb glb = read_glb(dir.file("f.glb"));
  EXPECT_EQ(at(glb.json, "nodes").elements.size(), 2u);
  std::set<uint32_t> used;
  for (const Frustum& f : skin_skeleton(plant.skeleton).frusta) used.insert(f.material);
  ASSERT_TRUE(used.count(0));
  EXPECT_EQ(at(glb.json, "materials").elements.size(), used.size() + 1);
  EXPECT_EQ(at(glb.json, "images").elements.size(), 3u);  // albedo, and a normal map per v_per_metre
}

// --- The broken-file corpus ----------------------------------------------------------

// Imports `bytes` written as `name` and expects an error containing `expected`.
void expect_import_error(const TempFolder& dir, const std::string& name, const std::string& bytes,
                         const std::string& expected) {
  Expected<std::vector<GltfPlant>> r = import_gltf_skeletons(dir.write(name, bytes));
  ASSERT_FALSE(r.ok()) << name << " was accepted";
  EXPECT_EQ(r.error().file, dir.file(name));
  const std::string text = r.error().format();
  EXPECT_NE(text.find(dir.file(name)), std::string::npos) << text;
  EXPECT_NE(text.find(expected), std::string::npos) << name << ": " << text;
}

std::string u32_bytes(uint32_t v) {
  std::string s(4, '\0');
  std::memcpy(s.data(), &v, 4);
  return s;
}

TEST(GltfImport, AGltfWithoutSylvaExtrasIsAClearError) {
  TempFolder dir;
  expect_import_error(dir, "plain.gltf",
                      R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"name":"cube"}]})",
                      "no sylva skeleton");
  expect_import_error(dir, "nonodes.gltf", R"({"asset":{"version":"2.0"}})", "no sylva skeleton");
  expect_import_error(dir, "other_extras.gltf",
                      R"({"asset":{"version":"2.0"},"nodes":[{"extras":{"author":"x"}},null,3]})", "no sylva skeleton");
}

TEST(GltfImport, BrokenFilesGiveLocatedErrorsNotCrashes) {
  TempFolder dir;
  expect_import_error(dir, "missing.glb", "", "");  // empty file
  Expected<std::vector<GltfPlant>> gone = import_gltf_skeletons(dir.file("does-not-exist.glb"));
  ASSERT_FALSE(gone.ok());
  EXPECT_NE(gone.error().format().find("does-not-exist.glb"), std::string::npos);
  expect_import_error(dir, "junk.glb", "this is not a model", "not a glTF file");
  expect_import_error(dir, "binary.glb", std::string("\x00\x01\x02\x03\xff", 5), "not a glTF file");
  expect_import_error(dir, "json_array.gltf", "[1,2]", "not a glTF file");
  expect_import_error(dir, "bad_json.gltf", "{\"asset\":{\"version\":\"2.0\"},}", "1:");
  expect_import_error(dir, "no_asset.gltf", "{\"nodes\":[]}", "glTF 2.0");
  expect_import_error(dir, "gltf1.gltf", "{\"asset\":{\"version\":\"1.0\"}}", "glTF 2.0");
  expect_import_error(dir, "nodes_object.gltf", R"({"asset":{"version":"2.0"},"nodes":{}})", "\"nodes\"");
  const std::string head = R"({"asset":{"version":"2.0"},"nodes":[{"name":"p","extras":{"sylva":)";
  expect_import_error(dir, "sylva_string.gltf", head + R"("x"}}]})", "expected an object");
  const std::string chains = R"("chains":[{"parent":null,"joints":[[0,0,0,0.1,0],[0,1,0,0.1,0]]}])";
  const std::string good_source = R"("source":{"grammar":"g.lsys","seed":"5","steps":1,"defines":{}})";
  const std::string doc = R"({"format":"sylva-skeleton","version":1,)";
  // The well-formed control, then one defect at a time.
  Expected<std::vector<GltfPlant>> ok = import_gltf_skeletons(dir.write("ok.gltf", head + doc + good_source + "," + chains + "}}}]}"));
  ASSERT_TRUE(ok.ok()) << ok.error().format();
  ASSERT_EQ(ok->size(), 1u);
  EXPECT_EQ((*ok)[0].skeleton.source.seed, 5u);
  EXPECT_EQ((*ok)[0].name, "p");
  expect_import_error(dir, "seed_number.gltf",
                      head + doc + R"("source":{"grammar":"g","seed":5,"steps":1,"defines":{}},)" + chains + "}}}]}",
                      "seed must be a string");
  expect_import_error(dir, "seed_huge.gltf",
                      head + doc + R"("source":{"grammar":"g","seed":"99999999999999999999","steps":1,"defines":{}},)" +
                          chains + "}}}]}",
                      "seed");
  expect_import_error(dir, "no_chains.gltf", head + doc + good_source + "}}}]}", "missing key \"chains\"");
  expect_import_error(dir, "dangling.gltf",
                      head + doc + good_source +
                          R"(,"chains":[{"parent":[3,0],"joints":[[0,0,0,0.1,0],[0,1,0,0.1,0]]}]}}}]})",
                      "chain 0");
  expect_import_error(dir, "negative_radius.gltf",
                      head + doc + good_source + R"(,"chains":[{"parent":null,"joints":[[0,0,0,-1,0],[0,1,0,0.1,0]]}]}}}]})",
                      "radius");
  expect_import_error(dir, "huge_number.gltf",
                      head + doc + good_source + R"(,"chains":[{"parent":null,"joints":[[1e999,0,0,1,0]]}]}}}]})", "");
  expect_import_error(dir, "bad_format.gltf",
                      head + R"({"format":"other","version":1,)" + good_source + "," + chains + "}}}]}", "format");
  expect_import_error(dir, "bad_instances.gltf", head + doc + good_source + "," + chains + R"(,"instances":[]}}}]})",
                      "instances");
  expect_import_error(dir, "bad_instance_scale.gltf",
                      head + doc + good_source + "," + chains +
                          R"(,"instances":[{"name":"a","position_m":[0,0,0],"rotate_y_deg":0,"scale":-1}]}}}]})",
                      "scale");
  {
    // An instance bomb: 50,001 instance records (~3 MB) of a 1,000-joint skeleton would be
    // 50 million joints (2 GiB) in memory: refused at the instances array, naming the limit.
    std::string joints;
    for (int j = 0; j < 1000; ++j) joints += (j ? ",[0," : "[0,") + std::to_string(j) + ",0,0.1,0]";
    std::string instances;
    for (int k = 0; k < 50001; ++k)
      instances += (k ? "," : "") + std::string(R"({"name":"a","position_m":[0,0,0],"rotate_y_deg":0,"scale":1})");
    expect_import_error(dir, "instance_bomb.gltf",
                        head + doc + good_source + R"(,"chains":[{"parent":null,"joints":[)" + joints + "]}]" +
                            R"(,"instances":[)" + instances + "]}}}]}",
                        "joints, more than the limit of 50000000 for one glTF file");
  }
  expect_import_error(dir, "deep.gltf", std::string(100000, '['), "");
  expect_import_error(dir, "deep_object.gltf", "{\"a\":" + std::string(100000, '['), "");

  // GLB headers and chunks that lie about their sizes.
  const std::string json = R"({"asset":{"version":"2.0"}})";
  auto glb = [&](uint32_t version, uint32_t total, uint32_t json_length, uint32_t type, const std::string& body) {
    return u32_bytes(0x46546C67) + u32_bytes(version) + u32_bytes(total) + u32_bytes(json_length) + u32_bytes(type) + body;
  };
  const uint32_t size = static_cast<uint32_t>(20 + json.size());
  expect_import_error(dir, "v1.glb", glb(1, size, static_cast<uint32_t>(json.size()), 0x4E4F534A, json), "version 1");
  expect_import_error(dir, "short_total.glb", glb(2, size + 100, static_cast<uint32_t>(json.size()), 0x4E4F534A, json),
                      "truncated");
  expect_import_error(dir, "chunk_overflow.glb", glb(2, size, 0xFFFFFFFFu, 0x4E4F534A, json), "runs past the end");
  expect_import_error(dir, "chunk_type.glb", glb(2, size, static_cast<uint32_t>(json.size()), 0x12345678, json),
                      "not JSON");
  expect_import_error(dir, "header_only.glb", u32_bytes(0x46546C67) + u32_bytes(2), "truncated");
  expect_import_error(dir, "valid_glb_no_sylva.glb", glb(2, size, static_cast<uint32_t>(json.size()), 0x4E4F534A, json),
                      "no sylva skeleton");
}

// Every `step`-th prefix of a real file is an error (the header's length no longer
// matches), and 300 random 3-byte corruptions give an error or valid plants, never a
// crash (ASan builds check).
void expect_cuts_and_flips_handled(const TempFolder& dir, const std::string& bytes, size_t step, unsigned seed) {
  for (size_t n = 0; n < bytes.size(); n += step) {
    Expected<std::vector<GltfPlant>> r = import_gltf_skeletons(dir.write("cut.glb", bytes.substr(0, n)));
    ASSERT_FALSE(r.ok()) << "prefix of " << n << " bytes accepted";
  }
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 300; ++trial) {
    std::string broken = bytes;
    for (int k = 0; k < 3; ++k)
      broken[std::uniform_int_distribution<size_t>(0, broken.size() - 1)(rng)] = static_cast<char>(rng());
    Expected<std::vector<GltfPlant>> r = import_gltf_skeletons(dir.write("flip.glb", broken));
    if (r) {
      EXPECT_FALSE(r->empty());  // plants, or else a located error
      for (const GltfPlant& p : *r) EXPECT_TRUE(validate_skeleton(p.skeleton).ok());
    }
  }
}

TEST(GltfImport, EveryTruncationAndRandomCorruptionOfARealFileIsHandled) {
  TempFolder dir;
  ASSERT_TRUE(export_gltf({{"plant", grow_text("angle: 30\naxiom: F[+F]F\n")}}, dir.file("p.glb")).ok());
  expect_cuts_and_flips_handled(dir, slurp(dir.file("p.glb")), 1, 5);
}


// ---------------------------------------------------------------------------------------
// Extras "compact" and "none" (gltf_export.h, docs/gltf.md).

// The bits of every double of a skeleton (joints and leaf vertices), to compare exactly
// (operator== takes -0 for 0).
std::vector<uint64_t> skeleton_bits(const Skeleton& sk) {
  std::vector<uint64_t> bits;
  auto add = [&](double v) { bits.push_back(std::bit_cast<uint64_t>(v)); };
  for (const Joint& j : sk.joints) {
    for (double x : j.position_m) add(x);
    add(j.radius_m);
    bits.push_back(j.material);
  }
  for (const Leaf& l : sk.leaves)
    for (const auto& v : l.vertices_m)
      for (double x : v) add(x);
  return bits;
}

// A leafy skeleton with doubles that decimal text handles badly: -0, a subnormal, 0.1+0.2.
Skeleton awkward_leafy_skeleton() {
  Skeleton sk = grow_text("angle: 60\naxiom: F(2)[&F{.+f.-f.-f.+|+f.-f.}]!(0.3)F'(1){.+f.-f.-f.}\n", 99);
  EXPECT_EQ(sk.leaves.size(), 2u);
  sk.joints[0].position_m[0] = -0.0;
  sk.joints[0].position_m[2] = 5e-324;
  sk.joints[1].position_m[0] = 0.1 + 0.2;
  sk.joints[1].radius_m = 1.0 / 3.0;
  sk.leaves[0].vertices_m[0][2] += 1e-17;
  sk.source.seed = std::numeric_limits<uint64_t>::max();
  sk.source.defines = {{"N", 3}, {"X", 0.1 + 0.7}};
  EXPECT_TRUE(validate_skeleton(sk).ok());
  return sk;
}

TEST(GltfExtras, CompactRoundTripIsBitExactForLeavesAndInstancesInGlbAndGltf) {
  TempFolder dir;
  const Skeleton leafy = awkward_leafy_skeleton(), other = grow_text(kGrammar, 3);
  // A scatter-like scene: copies of one skeleton (instanced) and another plant.
  std::vector<GltfPlant> scene = {{"leafy", leafy, {0.1, -0.0, 1e-300}, 33.3, 0.7},
                                  {"other", other, {-3, 0, 1}, 10, 1},
                                  {"leafy_b", leafy, {2.0 / 3.0, 0, 3}, -45.5, 1.0 / 7.0},
                                  {"leafy_c", leafy, {5, 0.5, -2}, 359.9, 2.5}};
  for (const char* name : {"s.glb", "s.gltf"})
    for (bool instancing : {false, true})
      for (bool mesh : {false, true}) {
        SCOPED_TRACE(std::string(name) + (instancing ? " instanced" : "") + (mesh ? " mesh" : ""));
        GltfExportOptions o;
        o.extras = GltfExtras::compact;
        o.instancing = instancing;
        o.mesh = mesh;
        ASSERT_TRUE(export_gltf(scene, dir.file(name), o).ok());
        Expected<std::vector<GltfPlant>> r = import_gltf_skeletons(dir.file(name));
        ASSERT_TRUE(r.ok()) << r.error().format();
        ASSERT_EQ(r->size(), scene.size());
        // Instancing groups the copies of `leafy` on the first node: a0, b, c, then other.
        const std::vector<size_t> order = instancing ? std::vector<size_t>{0, 2, 3, 1} : std::vector<size_t>{0, 1, 2, 3};
        for (size_t i = 0; i < order.size(); ++i) {
          const GltfPlant& back = (*r)[i];
          const GltfPlant& original = scene[order[i]];
          EXPECT_EQ(back.name, original.name);
          EXPECT_EQ(back.skeleton, original.skeleton);
          EXPECT_EQ(skeleton_bits(back.skeleton), skeleton_bits(original.skeleton));
          EXPECT_EQ(write_skeleton_json(back.skeleton), write_skeleton_json(original.skeleton));
          for (int k = 0; k < 3; ++k)
            EXPECT_EQ(std::bit_cast<uint64_t>(back.position_m[k]), std::bit_cast<uint64_t>(original.position_m[k]));
          EXPECT_EQ(std::bit_cast<uint64_t>(back.rotate_y_deg), std::bit_cast<uint64_t>(original.rotate_y_deg));
          EXPECT_EQ(std::bit_cast<uint64_t>(back.scale), std::bit_cast<uint64_t>(original.scale));
        }
      }
}

TEST(GltfExtras, CompactKeepsTheKeysWithArraysInUntargetedAlignedBufferViewsAndIsSmallerThanFull) {
  TempFolder dir;
  const Skeleton sk = grow_text(kGrammar);
  GltfExportOptions full, compact;
  compact.extras = GltfExtras::compact;
  ASSERT_TRUE(export_gltf({{"plant", sk}}, dir.file("full.glb"), full).ok());
  ASSERT_TRUE(export_gltf({{"plant", sk}}, dir.file("compact.glb"), compact).ok());
  EXPECT_LT(fs::file_size(dir.file("compact.glb")), fs::file_size(dir.file("full.glb")));
  const Glb glb = read_glb(dir.file("compact.glb"));
  // The JSON is what shrinks: the doubles leave it (their 8 bytes each go to the BIN chunk).
  EXPECT_LT(3 * u32_at(slurp(dir.file("compact.glb")), 12), u32_at(slurp(dir.file("full.glb")), 12));
  const JsonValue& sylva = at(at(at(glb.json, "nodes").elements.at(0), "extras"), "sylva");
  EXPECT_EQ(at(sylva, "format").text, "sylva-skeleton");
  EXPECT_EQ(at(at(sylva, "source"), "seed").text, "7");
  const JsonValue& chains = at(sylva, "chains");
  ASSERT_TRUE(chains.is_object());
  EXPECT_EQ(at(chains, "count").number, static_cast<double>(sk.chains.size()));
  const JsonValue& views = at(glb.json, "bufferViews");
  auto view_of = [&](const JsonValue& index) -> const JsonValue& { return views.elements.at(static_cast<size_t>(index.number)); };
  struct Expect {
    const JsonValue* object;
    const char* key;
    size_t bytes;
  };
  const JsonValue& frusta = at(at(sylva, "skinning"), "frusta");
  const size_t frustum_count = skin_skeleton(sk).frusta.size();
  for (const Expect& e : {Expect{&chains, "joint_count", 4 * sk.chains.size()},
                          Expect{&chains, "parent", 8 * sk.chains.size()},
                          Expect{&chains, "joints", 32 * sk.joints.size()},
                          Expect{&chains, "material", 4 * sk.joints.size()},
                          Expect{&frusta, "ids", 12 * frustum_count},
                          Expect{&frusta, "planes", 72 * frustum_count},
                          Expect{&at(sylva, "instances"), "placement", 40}}) {
    SCOPED_TRACE(e.key);
    const JsonValue& view = view_of(at(*e.object, e.key));
    EXPECT_EQ(at(view, "byteLength").number, static_cast<double>(e.bytes));
    EXPECT_EQ(static_cast<uint64_t>(at(view, "byteOffset").number) % 8, 0u);
    EXPECT_EQ(view.find("target"), nullptr);
  }
  // The joints' view holds the doubles themselves.
  const JsonValue& joints_view = view_of(at(chains, "joints"));
  double first[4];
  std::memcpy(first, glb.bin.data() + static_cast<size_t>(at(joints_view, "byteOffset").number), sizeof first);
  EXPECT_EQ(first[0], sk.joints[0].position_m[0]);
  EXPECT_EQ(first[3], sk.joints[0].radius_m);
  EXPECT_EQ(at(at(sylva, "instances"), "names").elements.at(0).text, "plant");
  // Still one LINES primitive that any viewer shows, and the same skeleton as "full".
  EXPECT_EQ(at(glb.json, "meshes").elements.size(), 1u);
  auto a = import_gltf_skeletons(dir.file("full.glb")), b = import_gltf_skeletons(dir.file("compact.glb"));
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ((*a)[0].skeleton, (*b)[0].skeleton);
}

TEST(GltfExtras, NoneWritesAPlainMeshThatImportRefusesClearly) {
  TempFolder dir;
  GltfExportOptions o;
  o.extras = GltfExtras::none;
  o.mesh = true;
  ASSERT_TRUE(export_gltf({{"plant", grow_text(kGrammar)}}, dir.file("p.glb"), o).ok());
  const Glb glb = read_glb(dir.file("p.glb"));
  EXPECT_EQ(at(glb.json, "nodes").elements.at(0).find("extras"), nullptr);
  const JsonValue& primitives = at(at(glb.json, "meshes").elements.at(0), "primitives");
  ASSERT_GE(primitives.elements.size(), 2u);  // the LINES skeleton, then the triangles
  EXPECT_EQ(at(primitives.elements[0], "mode").number, 1);
  EXPECT_EQ(at(primitives.elements[1], "mode").number, 4);
  Expected<std::vector<GltfPlant>> r = import_gltf_skeletons(dir.file("p.glb"));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().format().find("no sylva skeleton"), std::string::npos) << r.error().format();
  EXPECT_NE(r.error().format().find("--extras none"), std::string::npos) << r.error().format();
}

TEST(GltfExtras, APlantWithoutSegmentsHasViewsButNoAccessorsAndRoundTrips) {
  TempFolder dir;
  Skeleton sk;
  sk.joints = {{{1, 2, 3}, 0.5, 2}};
  sk.chains = {{0, 1, std::nullopt}};
  GltfExportOptions o;
  o.extras = GltfExtras::compact;
  for (const char* name : {"p.glb", "p.gltf"}) {
    ASSERT_TRUE(export_gltf({{"dot", sk}}, dir.file(name), o).ok());
    Expected<std::vector<GltfPlant>> r = import_gltf_skeletons(dir.file(name));
    ASSERT_TRUE(r.ok()) << r.error().format();
    EXPECT_EQ((*r)[0].skeleton, sk);
  }
  EXPECT_EQ(read_glb(dir.file("p.glb")).json.find("accessors"), nullptr);
}

std::string base64_of(std::string_view bytes) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = static_cast<uint8_t>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<uint8_t>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) v |= static_cast<uint8_t>(bytes[i + 2]);
    out += kDigits[v >> 18];
    out += kDigits[v >> 12 & 63];
    out += i + 1 < bytes.size() ? kDigits[v >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[v & 63] : '=';
  }
  return out;
}

template <class T>
std::string raw_bytes(std::initializer_list<T> values) {
  std::string s;
  for (T v : values) s.append(reinterpret_cast<const char*>(&v), sizeof v);
  return s;
}

// A hand-made compact .gltf: one chain of two joints in four bufferViews of buffer 0.
struct CompactCase {
  std::string chains = R"({"count":1,"joint_count":0,"parent":1,"joints":2,"material":3})";
  std::string more;  // further members of extras.sylva, each with a leading comma
  std::string views = R"([{"buffer":0,"byteOffset":0,"byteLength":4},{"buffer":0,"byteOffset":8,"byteLength":8},)"
                      R"({"buffer":0,"byteOffset":16,"byteLength":64},{"buffer":0,"byteOffset":80,"byteLength":8}])";
  std::string bin = raw_bytes<uint32_t>({2, 0}) + raw_bytes<uint32_t>({0xFFFFFFFFu, 0xFFFFFFFFu}) +
                    raw_bytes<double>({0, 0, 0, 0.1, 0, 1, 0, 0.05}) + raw_bytes<uint32_t>({0, 1});
  std::string version = "1";
  std::optional<std::string> uri;  // default: the base64 of bin
  std::optional<size_t> byte_length;

  std::string text() const {
    return R"({"asset":{"version":"2.0"},"nodes":[{"name":"p","extras":{"sylva":{"format":"sylva-skeleton","version":)" +
           version + R"(,"source":{"grammar":"g.lsys","seed":"5","steps":1,"defines":{}},"chains":)" + chains + more +
           R"(}}}],"bufferViews":)" + views + R"(,"buffers":[{"byteLength":)" +
           std::to_string(byte_length.value_or(bin.size())) + R"(,"uri":")" +
           uri.value_or("data:application/octet-stream;base64," + base64_of(bin)) + R"("}]})";
  }
};

TEST(GltfExtras, MalformedCompactExtrasGiveLocatedErrorsNeverACrash) {
  TempFolder dir;
  const CompactCase good;
  Expected<std::vector<GltfPlant>> ok = import_gltf_skeletons(dir.write("ok.gltf", good.text()));
  ASSERT_TRUE(ok.ok()) << ok.error().format();
  ASSERT_EQ((*ok)[0].skeleton.joints.size(), 2u);
  EXPECT_EQ((*ok)[0].skeleton.joints[1].material, 1u);
  EXPECT_EQ((*ok)[0].skeleton.joints[1].radius_m, 0.05);

  struct Bad {
    const char* name;
    CompactCase c;
    const char* expected;
  };
  std::vector<Bad> cases;
  auto add = [&](const char* name, const char* expected, auto&& edit) {
    CompactCase c;
    edit(c);
    cases.push_back({name, c, expected});
  };
  add("view_index_out_of_range", "bufferViews", [](CompactCase& c) { c.chains = R"({"count":1,"joint_count":9,"parent":1,"joints":2,"material":3})"; });
  add("view_index_negative", "bufferViews", [](CompactCase& c) { c.chains = R"({"count":1,"joint_count":-1,"parent":1,"joints":2,"material":3})"; });
  add("view_index_string", "bufferViews", [](CompactCase& c) { c.chains = R"({"count":1,"joint_count":"0","parent":1,"joints":2,"material":3})"; });
  add("view_key_missing", "missing key \"joints\"", [](CompactCase& c) { c.chains = R"({"count":1,"joint_count":0,"parent":1,"material":3})"; });
  add("count_missing", "count must be", [](CompactCase& c) { c.chains = R"({"joint_count":0,"parent":1,"joints":2,"material":3})"; });
  add("count_huge", "count must be", [](CompactCase& c) { c.chains = R"({"count":1e30,"joint_count":0,"parent":1,"joints":2,"material":3})"; });
  // Issue 32: a count of 0 over full views used to read as an empty plant (exit 0).
  add("count_zero_over_full_views", "expected 0 values", [](CompactCase& c) { c.chains = R"({"count":0,"joint_count":0,"parent":1,"joints":2,"material":3})"; });
  add("leaf_count_zero_over_a_full_view", "expected 0 values", [](CompactCase& c) { c.version = "2"; c.more = R"(,"leaves":{"count":0,"vertex_count":0})"; });
  add("count_mismatch", "expected 4 values", [](CompactCase& c) { c.chains = R"({"count":4,"joint_count":0,"parent":1,"joints":2,"material":3})"; });
  add("joint_counts_lie", "expected", [](CompactCase& c) { std::memcpy(c.bin.data(), "\xff\xff\xff\x7f", 4); });
  add("offset_past_end", "runs past the end of buffer 0", [](CompactCase& c) {
    c.views = R"([{"buffer":0,"byteOffset":4000000000,"byteLength":4},{"buffer":0,"byteOffset":8,"byteLength":8},{"buffer":0,"byteOffset":16,"byteLength":64},{"buffer":0,"byteOffset":80,"byteLength":8}])";
  });
  add("length_overflows", "runs past the end of buffer 0", [](CompactCase& c) {
    c.views = R"([{"buffer":0,"byteOffset":8,"byteLength":18446744073709551615},{"buffer":0,"byteOffset":8,"byteLength":8},{"buffer":0,"byteOffset":16,"byteLength":64},{"buffer":0,"byteOffset":80,"byteLength":8}])";
  });
  add("other_buffer", "buffer 0", [](CompactCase& c) {
    c.views = R"([{"buffer":1,"byteLength":4},{"buffer":0,"byteOffset":8,"byteLength":8},{"buffer":0,"byteOffset":16,"byteLength":64},{"buffer":0,"byteOffset":80,"byteLength":8}])";
  });
  add("strided", "byteStride", [](CompactCase& c) {
    c.views = R"([{"buffer":0,"byteLength":4,"byteStride":8},{"buffer":0,"byteOffset":8,"byteLength":8},{"buffer":0,"byteOffset":16,"byteLength":64},{"buffer":0,"byteOffset":80,"byteLength":8}])";
  });
  add("view_not_object", "expected an object", [](CompactCase& c) { c.views = R"([7,{"buffer":0,"byteOffset":8,"byteLength":8},{"buffer":0,"byteOffset":16,"byteLength":64},{"buffer":0,"byteOffset":80,"byteLength":8}])"; });
  add("no_views", "bufferViews", [](CompactCase& c) { c.views = "{}"; });
  add("buffer_longer_than_data", "bytes of data", [](CompactCase& c) { c.byte_length = 1u << 30; });
  add("external_uri", "resolves no other URI", [](CompactCase& c) { c.uri = "/etc/passwd"; });
  add("bad_base64", "not valid base64", [](CompactCase& c) { c.uri = "data:application/octet-stream;base64,AAA*"; });
  add("short_base64", "not valid base64", [](CompactCase& c) { c.uri = "data:application/octet-stream;base64,AAA"; });
  add("nan_joint", "chain 0", [](CompactCase& c) { const double nan = std::nan(""); std::memcpy(c.bin.data() + 16, &nan, 8); });
  add("negative_radius", "radius", [](CompactCase& c) { const double r = -1; std::memcpy(c.bin.data() + 40, &r, 8); });
  add("dangling_parent", "parent", [](CompactCase& c) { std::memset(c.bin.data() + 8, 0, 8); });
  add("half_root_parent", "parent", [](CompactCase& c) { std::memset(c.bin.data() + 8, 0, 4); });
  add("leaves_in_version_1", "version 2", [](CompactCase& c) { c.more = R"(,"leaves":{"count":0})"; });
  add("leaves_array", "expected an object", [](CompactCase& c) { c.version = "2"; c.more = R"(,"leaves":[])"; });
  add("leaf_views_missing", "missing key \"vertex_count\"", [](CompactCase& c) { c.version = "2"; c.more = R"(,"leaves":{"count":1})"; });
  add("instances_count_zero", "at least 1", [](CompactCase& c) { c.more = R"(,"instances":{"count":0,"names":[]})"; });
  add("instances_names_short", "names must be an array of 2", [](CompactCase& c) { c.more = R"(,"instances":{"count":2,"names":["a"],"placement":0})"; });
  add("instances_placement_size", "expected 5 values", [](CompactCase& c) { c.more = R"(,"instances":{"count":1,"names":["a"],"placement":2})"; });
  add("instance_not_finite", "not finite", [](CompactCase& c) {
    c.more = R"(,"instances":{"count":1,"names":["a"],"placement":4})";
    c.views.back() = ',';
    c.views += R"({"buffer":0,"byteOffset":88,"byteLength":40}])";
    c.bin += raw_bytes<double>({0, 0, 0, std::numeric_limits<double>::infinity(), 1});
  });
  add("instance_bad_scale", "scale must be > 0", [](CompactCase& c) {
    c.more = R"(,"instances":{"count":1,"names":["a"],"placement":4})";
    c.views.back() = ',';
    c.views += R"({"buffer":0,"byteOffset":88,"byteLength":40}])";
    c.bin += raw_bytes<double>({0, 0, 0, 0, -2});
  });
  for (const Bad& b : cases) {
    SCOPED_TRACE(b.name);
    expect_import_error(dir, std::string(b.name) + ".gltf", b.c.text(), b.expected);
  }
}

TEST(GltfExtras, CompactGlbWithAMissingOrLyingBinChunkIsAClearError) {
  TempFolder dir;
  GltfExportOptions o;
  o.extras = GltfExtras::compact;
  ASSERT_TRUE(export_gltf({{"plant", grow_text("angle: 30\naxiom: F[+F]F\n")}}, dir.file("p.glb"), o).ok());
  const std::string bytes = slurp(dir.file("p.glb"));
  const uint32_t json_length = u32_at(bytes, 12);
  const size_t bin = 20 + json_length;
  // Without the BIN chunk (the header's total fixed up).
  std::string cut = bytes.substr(0, bin);
  const uint32_t total = static_cast<uint32_t>(cut.size());
  std::memcpy(cut.data() + 8, &total, 4);
  expect_import_error(dir, "no_bin.glb", cut, "no BIN chunk");
  std::string wrong_type = bytes;
  std::memcpy(wrong_type.data() + bin + 4, "XXXX", 4);
  expect_import_error(dir, "bin_type.glb", wrong_type, "not BIN");
  std::string long_chunk = bytes;
  const uint32_t huge = 0xFFFFFFF0u;
  std::memcpy(long_chunk.data() + bin, &huge, 4);
  expect_import_error(dir, "bin_long.glb", long_chunk, "runs past the end of the file");
  // Every prefix and random flips of the compact file (the flips reach the BIN chunk's
  // doubles): errors or valid plants, never a crash.
  expect_cuts_and_flips_handled(dir, bytes, 1, 11);
}

}  // namespace
}  // namespace sylva
