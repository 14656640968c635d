// gltf_test.cpp — core/gltf_export.h: what an exported glTF holds (the LINES skeleton,
// accessor bounds, the exact skeleton in node extras, the optional mesh, instancing), the
// round trip back to skeletons, tinygltf 2.7's known writer traps (each guarded on our
// output and cross-checked by loading it with tinygltf), and a corpus of broken files
// that must give clear errors, never a crash.
#include "core/gltf_export.h"

#include <gtest/gtest.h>
#include <tiny_gltf.h>  // declarations only; the implementation is Debian's shared library

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/file_io.h"
#include "core/json.h"
#include "core/skin.h"
#include "core/tessellate.h"
#include "core/turtle.h"
#include "lsystem/grammar.h"

namespace sylva {
namespace {

namespace fs = std::filesystem;

// A branching plant with tapering, materials and a define.
constexpr const char* kGrammar =
    "#define N 3\n"
    "angle: 30\nwidth: 0.1\nderivation length: N\n"
    "axiom: F(1)A\n"
    "A -> !(0.7)'F(0.8)[+F(0.5)A][-/F(0.5)A]F(0.6)A\n";

Skeleton grow_text(const char* text, uint64_t seed = 7) {
  auto g = lsys::parse_grammar(text, "plant.lsys", {});
  EXPECT_TRUE(static_cast<bool>(g)) << (g ? "" : g.error().format());
  lsys::DeriveOptions o;
  o.seed = seed;
  auto r = grow(*g, o, "presets/plant.lsys", {{"N", 3}});
  EXPECT_TRUE(static_cast<bool>(r)) << (r ? "" : r.error().format());
  return r->skeleton;
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
  EXPECT_TRUE(parsed.value) << parsed.error->message;
  out.json = *parsed.value;
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
  ASSERT_FALSE(export_gltf({{"plant", sk}}, dir.file("p.glb")));
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
  ASSERT_FALSE(export_gltf({{"plant", grow_text(kGrammar)}}, dir.file("p.glb"), o));
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

TEST(GltfExport, NoNullEntriesEvenForAPlantWithoutSegments) {
  // Trap: tinygltf writes an empty node as `null`.
  TempFolder dir;
  Skeleton empty;
  Skeleton one_joint;
  one_joint.joints.push_back({{0, 0, 0}, 0.1, 0});
  one_joint.chains.push_back({0, 1, std::nullopt});
  ASSERT_FALSE(export_gltf({{"empty", empty}, {"single", one_joint}, {"plant", grow_text(kGrammar)}}, dir.file("p.gltf")));
  auto parsed = parse_json(slurp(dir.file("p.gltf")));
  ASSERT_TRUE(parsed.value);
  for (const char* array : {"scenes", "nodes", "meshes", "accessors", "bufferViews", "buffers"}) {
    const JsonValue& v = at(*parsed.value, array);
    ASSERT_TRUE(v.is_array()) << array;
    EXPECT_FALSE(v.elements.empty()) << array;  // glTF forbids empty arrays
    for (const JsonValue& e : v.elements) EXPECT_TRUE(e.is_object()) << array;
  }
  const JsonValue& nodes = at(*parsed.value, "nodes");
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
  ASSERT_FALSE(export_gltf({{"elm \"1\"", sk}}, dir.file("p.glb")));
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
  ASSERT_FALSE(export_gltf({{"plant", sk}}, dir.file("p.glb")));
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

TEST(GltfExport, MeshIsASecondTrianglesPrimitiveWithUnitNormalsAndFrustumTexcoords) {
  TempFolder dir;
  const Skeleton sk = grow_text(kGrammar);
  GltfExportOptions o;
  o.mesh = true;
  o.segments_around = 6;
  ASSERT_FALSE(export_gltf({{"plant", sk}}, dir.file("p.glb"), o));
  const Glb glb = read_glb(dir.file("p.glb"));
  const JsonValue& prims = at(at(glb.json, "meshes").elements.at(0), "primitives");
  ASSERT_EQ(prims.elements.size(), 2u);
  const JsonValue& tri = prims.elements[1];
  EXPECT_EQ(at(tri, "mode").text, "4");
  EXPECT_EQ(at(tri, "material").text, "0");
  EXPECT_EQ(at(at(at(glb.json, "materials").elements.at(0), "extras"), "sylva").is_object(), true);
  TessellateOptions to;
  to.segments_around = 6;
  const TriangleMesh tm = tessellate(skin_skeleton(sk), to);
  const auto& attr = at(tri, "attributes");
  const std::vector<double> normals = accessor_values(glb, static_cast<size_t>(at(attr, "NORMAL").number));
  const std::vector<double> uvs = accessor_values(glb, static_cast<size_t>(at(attr, "TEXCOORD_0").number));
  const std::vector<double> indices = accessor_values(glb, static_cast<size_t>(at(tri, "indices").number));
  ASSERT_EQ(normals.size(), tm.normals.size() * 3);
  ASSERT_EQ(uvs.size(), tm.uvs.size() * 2);
  ASSERT_EQ(indices.size(), tm.indices.size());
  for (size_t i = 0; i < tm.uvs.size(); ++i) {
    const double len = std::hypot(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
    EXPECT_NEAR(len, 1.0, 1e-6);
    EXPECT_EQ(uvs[2 * i], static_cast<float>(tm.uvs[i].x));
    EXPECT_EQ(uvs[2 * i + 1], static_cast<float>(tm.uvs[i].y * kGltfTexcoordVPerMetre));
  }
  for (size_t i = 0; i < tm.indices.size(); ++i) EXPECT_EQ(indices[i], tm.indices[i]);
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
      ASSERT_FALSE(export_gltf({plant}, dir.file(name), o));
      GltfImportResult r = import_gltf_skeletons(dir.file(name));
      ASSERT_FALSE(r.error) << *r.error;
      ASSERT_EQ(r.plants.size(), 1u);
      EXPECT_EQ(write_skeleton_json(r.plants[0].skeleton), write_skeleton_json(sk)) << name;
      EXPECT_EQ(r.plants[0].name, "plant");
      for (int k = 0; k < 3; ++k) EXPECT_EQ(r.plants[0].position_m[k], plant.position_m[k]);
      EXPECT_EQ(r.plants[0].rotate_y_deg, 33.3);
      EXPECT_EQ(r.plants[0].scale, 0.75);
    }
}

TEST(GltfExport, SameInputGivesByteIdenticalFiles) {
  TempFolder dir;
  const Skeleton sk = grow_text(kGrammar);
  GltfExportOptions o;
  o.mesh = true;
  ASSERT_FALSE(export_gltf({{"plant", sk}}, dir.file("a.glb"), o));
  ASSERT_FALSE(export_gltf({{"plant", sk}}, dir.file("b.glb"), o));
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
  ASSERT_FALSE(export_gltf(forest, dir.file("f.glb"), o));
  const Glb glb = read_glb(dir.file("f.glb"));
  const JsonValue& used = at(glb.json, "extensionsUsed");
  ASSERT_EQ(used.elements.size(), 1u);
  EXPECT_EQ(used.elements[0].text, "EXT_mesh_gpu_instancing");
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
  GltfImportResult back = import_gltf_skeletons(dir.file("f.glb"));
  ASSERT_FALSE(back.error) << *back.error;
  ASSERT_EQ(back.plants.size(), 4u);
  const char* names[4] = {"a0", "a1", "a2", "b0"};
  const GltfPlant* originals[4] = {&forest[0], &forest[2], &forest[3], &forest[1]};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(back.plants[i].name, names[i]);
    EXPECT_EQ(write_skeleton_json(back.plants[i].skeleton), write_skeleton_json(originals[i]->skeleton));
    for (int k = 0; k < 3; ++k) EXPECT_EQ(back.plants[i].position_m[k], originals[i]->position_m[k]);
    EXPECT_EQ(back.plants[i].rotate_y_deg, originals[i]->rotate_y_deg);
    EXPECT_EQ(back.plants[i].scale, originals[i]->scale);
  }
  // Without instancing every plant is its own node.
  ASSERT_FALSE(export_gltf(forest, dir.file("g.glb")));
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
    ASSERT_FALSE(export_gltf({{"plant", sk, {1, 2, 3}, 30, 2}}, dir.file(name), o));
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string err, warn;
    const bool ok = std::string(name).ends_with(".glb") ? loader.LoadBinaryFromFile(&model, &err, &warn, dir.file(name))
                                                        : loader.LoadASCIIFromFile(&model, &err, &warn, dir.file(name));
    ASSERT_TRUE(ok) << err;
    EXPECT_TRUE(warn.empty()) << warn;
    ASSERT_EQ(model.nodes.size(), 1u);
    ASSERT_EQ(model.meshes.size(), 1u);
    ASSERT_EQ(model.meshes[0].primitives.size(), 2u);
    EXPECT_EQ(model.meshes[0].primitives[0].mode, TINYGLTF_MODE_LINE);
    EXPECT_EQ(model.meshes[0].primitives[1].mode, TINYGLTF_MODE_TRIANGLES);
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
  EXPECT_TRUE(export_gltf({}, path));
  EXPECT_TRUE(export_gltf({{"p", sk, {0, 0, 0}, 0, 0}}, path));  // scale 0
  EXPECT_TRUE(export_gltf({{"p", sk, {NAN, 0, 0}, 0, 1}}, path));
  Skeleton bad = sk;
  bad.joints[1].radius_m = -1;
  auto err = export_gltf({{"p", bad}}, path);
  ASSERT_TRUE(err);
  EXPECT_NE(err->find("joint"), std::string::npos) << *err;
  GltfExportOptions o;
  o.segments_around = 2;
  EXPECT_TRUE(export_gltf({{"p", sk}}, path, o));
  EXPECT_EQ(slurp(path), "old contents");
  EXPECT_TRUE(export_gltf({{"p", sk}}, dir.file("p.obj")));
  EXPECT_FALSE(fs::exists(dir.file("p.obj")));
  EXPECT_TRUE(export_gltf({{"p", sk}}, dir.file("no/such/folder/p.glb")));
  // Only the result is in the folder: no temporary file left behind.
  size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.file(""))) ++entries;
  EXPECT_EQ(entries, 1u);
}

// --- The broken-file corpus ----------------------------------------------------------

// Imports `bytes` written as `name` and expects an error containing `expected`.
void expect_import_error(const TempFolder& dir, const std::string& name, const std::string& bytes,
                         const std::string& expected) {
  GltfImportResult r = import_gltf_skeletons(dir.write(name, bytes));
  ASSERT_TRUE(r.error) << name << " was accepted";
  EXPECT_TRUE(r.plants.empty());
  EXPECT_NE(r.error->find(dir.file(name)), std::string::npos) << *r.error;
  EXPECT_NE(r.error->find(expected), std::string::npos) << name << ": " << *r.error;
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
  GltfImportResult gone = import_gltf_skeletons(dir.file("does-not-exist.glb"));
  ASSERT_TRUE(gone.error);
  EXPECT_NE(gone.error->find("does-not-exist.glb"), std::string::npos);
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
  GltfImportResult ok = import_gltf_skeletons(dir.write("ok.gltf", head + doc + good_source + "," + chains + "}}}]}"));
  ASSERT_FALSE(ok.error) << *ok.error;
  ASSERT_EQ(ok.plants.size(), 1u);
  EXPECT_EQ(ok.plants[0].skeleton.source.seed, 5u);
  EXPECT_EQ(ok.plants[0].name, "p");
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

TEST(GltfImport, EveryTruncationAndRandomCorruptionOfARealFileIsHandled) {
  TempFolder dir;
  ASSERT_FALSE(export_gltf({{"plant", grow_text("angle: 30\naxiom: F[+F]F\n")}}, dir.file("p.glb")));
  const std::string bytes = slurp(dir.file("p.glb"));
  // Every prefix: an error (the header's length no longer matches), never a crash.
  for (size_t n = 0; n < bytes.size(); ++n) {
    GltfImportResult r = import_gltf_skeletons(dir.write("cut.glb", bytes.substr(0, n)));
    ASSERT_TRUE(r.error) << "prefix of " << n << " bytes accepted";
  }
  // Random byte flips: either an error or plants, never a crash (ASan builds check).
  std::mt19937 rng(5);
  for (int trial = 0; trial < 300; ++trial) {
    std::string broken = bytes;
    for (int k = 0; k < 3; ++k)
      broken[std::uniform_int_distribution<size_t>(0, broken.size() - 1)(rng)] = static_cast<char>(rng());
    GltfImportResult r = import_gltf_skeletons(dir.write("flip.glb", broken));
    EXPECT_TRUE(r.error.has_value() != !r.plants.empty());
  }
}

}  // namespace
}  // namespace sylva
