// export_rig_cli_test.cpp — `sylva export --mesh --rig [--max-joints N] [--animation]`
// (docs/gltf.md "Rig and wind clip") as users run it: every rigged variant passes the
// Khronos validator with no error or warning; three.js (npm `three`, scripts/three_check.mjs:
// GLTFLoader, AnimationMixer.setTime, SkinnedMesh.getVertexPosition) plays the clip and
// its skinned vertices agree with sylva's own pose of the same rig at the same times,
// placement included; usage errors exit 2 and a clip that moves nothing exits 1, writing
// nothing.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "core/io/gltf.h"
#include "core/io/gltf_rig.h"
#include "core/scene/animate.h"
#include "core/scene/scene_json.h"
#include "core/util/json.h"
#include "tests/app/node_script.h"
#include "tests/app/rig_pose.h"
#include "tests/support/process.h"

namespace {

namespace fs = std::filesystem;
using namespace sylva;
using test::numbers_of;
using test::run_node_script;
using test::placed_scene;
using test::report_after;

const std::string kSource = SYLVA_SOURCE_DIR;
const std::string kElm = kSource + "/presets/elm.lsys";
const std::string kLeafy = kSource + "/presets/abop_2_6_honda_leaves.lsys";

void expect_ok(const ProcessResult& r) {
  EXPECT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 0) << describe(r);
}

TEST(ExportRig, EveryRiggedVariantPassesTheKhronosValidator) {
  TempDir dir;
  const std::string scene = placed_scene(dir, kLeafy, R"({"fps":10,"duration_s":3,"wind":[1,0,1]})");
  std::vector<std::string> files;
  auto exported = [&](std::vector<std::string> args, const std::string& out) {
    args.insert(args.end(), {"--mesh", "--segments-around", "5", "-o", dir.file(out)});
    expect_ok(run_sylva(args));
    files.push_back(dir.file(out));
  };
  exported({"export", kElm, "--rig"}, "elm_rig.glb");
  exported({"export", kElm, "--rig", "--animation"}, "elm_wind.glb");
  exported({"export", kElm, "--rig", "--animation"}, "elm_wind.gltf");
  exported({"export", kElm, "--rig", "--max-joints", "3", "--animation"}, "elm_3.glb");
  exported({"export", kElm, "--rig", "--max-joints", "1024", "--animation"}, "elm_1024.glb");
  exported({"export", kLeafy, "--rig", "--animation", "--extras", "none"}, "leafy.glb");
  exported({"export", kLeafy, "--wind-data"}, "leafy_wind_data.glb");
  exported({"export", kLeafy, "--wind-data", "--rig", "--animation"}, "leafy_wind_data_rig.gltf");
  exported({"export", kElm, "--lod", "3"}, "elm_lod.glb");
  exported({"export", kLeafy, "--lod", "2", "--rig", "--animation", "--wind-data"}, "leafy_lod_rig.glb");
  exported({"export", scene, "--lod", "1", "--wind-data"}, "scene_lod.gltf");
  const std::string forest = dir.write("forest.scene.json", R"({"format":"sylva-scene","version":1,"plants":[
    {"grammar":")" + kLeafy + R"(","seed":1,"position":[0,0,0]},
    {"grammar":")" + kLeafy + R"(","seed":1,"position":[3,0,0],"rotate_y_deg":90}]})");
  exported({"export", forest, "--lod", "2", "--instancing"}, "forest_lod_instanced.glb");
  // The elm's LINES hold 3538 indices, not a multiple of 3: the index-sequence codec.
  exported({"export", kElm, "--rig", "--animation", "--wind-data", "--lod", "3", "--compress", "meshopt"},
           "elm_all_meshopt.glb");
  exported({"export", forest, "--instancing", "--compress", "meshopt"}, "forest_meshopt.gltf");
  exported({"export", scene, "--rig", "--animation"}, "scene.glb");
  exported({"export", scene, "--rig", "--animation", "--extras", "full"}, "scene.gltf");
  ProcessResult r = run_node_script("validate_gltf.mjs", "gltf-validator", files);
  EXPECT_EQ(r.exit_code, 0) << describe(r, 20000);
  for (const std::string& f : files) EXPECT_NE(r.out.find(f + ": 0 errors, 0 warnings"), std::string::npos) << r.out;
  // three.js loads the levels of a rigged plant, each a skinned mesh, and plays the clip.
  ProcessResult three = run_node_script("three_check.mjs", "three", {dir.file("leafy_lod_rig.glb"), "--times", "0,1", "--every", "1000"});
  ASSERT_EQ(three.exit_code, 0) << describe(three, 20000);
  Expected<JsonValue> report = report_after(three.out, "THREE_CHECK ");
  ASSERT_TRUE(report);
  std::vector<std::string> names;
  for (const JsonValue& m : report->find("skinned_meshes")->elements) names.push_back(m.find("name")->text);
  for (const char* level : {"LOD0", "LOD1", "LOD2"})
    EXPECT_TRUE(std::any_of(names.begin(), names.end(), [&](const std::string& n) { return n.find(level) != std::string::npos; }))
        << level;
}

TEST(ExportRig, ThreeJsPlaysTheWindClipAsSylvaPosesTheRig) {
  TempDir dir;
  const std::string scene = placed_scene(dir, kElm, R"({"fps":12,"duration_s":3,"wind":[1,0,-0.5],"seed":4})");
  const std::string glb = dir.file("elm.glb");
  expect_ok(run_sylva(
      {"export", scene, "--mesh", "--segments-around", "5", "--rig", "--animation", "--wind-data", "-o", glb}));
  // Keys 0, 7, 22 and 36 (the last) of 36 intervals.
  const std::vector<double> times = {0, 7.0 / 12, 22.0 / 12, 3};
  ProcessResult r = run_node_script("three_check.mjs", "three", {glb, "--times", "0,0.5833333333333334,1.8333333333333333,3", "--every", "53"});
  ASSERT_EQ(r.exit_code, 0) << describe(r, 20000);
  Expected<JsonValue> report = report_after(r.out, "THREE_CHECK ");
  ASSERT_TRUE(report) << r.out.substr(0, 2000);

  // sylva's side: the plant read back from the file, its rig, the scene's sway.
  const test::SylvaRigPose sylva(glb, scene);
  const Rig* rig = &sylva.rig();
  const JsonValue& meshes = *report->find("skinned_meshes");
  ASSERT_GE(meshes.elements.size(), 1u);
  const JsonValue& mesh = meshes.elements[0];
  EXPECT_EQ(mesh.find("bones")->number, static_cast<double>(rig->joints.size()));
  // The wind data reaches a shader as uv2 and uv3.
  std::vector<std::string> attributes;
  for (const JsonValue& a : mesh.find("attributes")->elements) attributes.push_back(a.text);
  EXPECT_EQ(attributes, (std::vector<std::string>{"normal", "position", "skinIndex", "skinWeight", "uv", "uv1", "uv2",
                                                  "uv3"}));
  const JsonValue& clip = report->find("clips")->elements.at(0);
  EXPECT_EQ(clip.find("name")->text, "wind");
  EXPECT_EQ(clip.find("duration")->number, 3);
  const std::vector<double> rest = numbers_of(*mesh.find("rest"));
  const std::vector<double> skin = numbers_of(*mesh.find("skin"));
  ASSERT_EQ(rest.size() / 3 * 8, skin.size());
  ASSERT_GT(rest.size() / 3, 500u);
  for (size_t v = 0; v < rest.size() / 3; ++v)
    EXPECT_LE(std::count_if(skin.begin() + 8 * v + 4, skin.begin() + 8 * v + 8, [](double w) { return w > 0; }), 2)
        << "vertex " << v;
  const JsonValue& frames = *report->find("frames");
  ASSERT_EQ(frames.elements.size(), times.size());
  double worst = 0, moved = 0, loop = 0;
  const std::vector<double> first = numbers_of(frames.elements[0].find("meshes")->elements[0]);
  for (size_t f = 0; f < times.size(); ++f) {
    const std::vector<RigJointPose> pose = sylva.pose(times[f]);
    const std::vector<double> three = numbers_of(frames.elements[f].find("meshes")->elements[0]);
    ASSERT_EQ(three.size(), rest.size());
    for (size_t v = 0; v < rest.size() / 3; ++v) {
      const glm::dvec3 p0(rest[3 * v], rest[3 * v + 1], rest[3 * v + 2]);
      const glm::dvec3 expected = sylva.posed(pose, test::weights_of(skin, v), p0);
      const glm::dvec3 got(three[3 * v], three[3 * v + 1], three[3 * v + 2]);
      worst = std::max(worst, glm::length(got - expected));
      moved = std::max(moved, glm::length(got - sylva.placed(p0)));
      if (f + 1 == times.size())
        loop = std::max(loop, glm::length(got - glm::dvec3(first[3 * v], first[3 * v + 1], first[3 * v + 2])));
    }
  }
  EXPECT_LT(worst, 1e-4) << "three.js and sylva disagree by " << worst << " m";
  EXPECT_GT(moved, 0.05) << "the clip must move the tree";
  EXPECT_LT(loop, 1e-6) << "the last frame must be the first";
}

TEST(ExportRig, UsageErrorsExitTwoAndAClipThatMovesNothingExitsOneWritingNothing) {
  TempDir dir;
  const std::string out = dir.file("p.glb");
  auto usage = [&](std::vector<std::string> args, const std::string& words) {
    args.insert(args.begin(), {"export", kElm, "-o", out});
    ProcessResult r = run_sylva(args);
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_NE(r.err.find(words), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  };
  usage({"--rig"}, "add --mesh");
  usage({"--mesh", "--rig", "--instancing"}, "cannot be combined");
  usage({"--mesh", "--rig", "--max-joints", "0"}, "from 1 to 1024");
  usage({"--mesh", "--rig", "--max-joints", "1025"}, "from 1 to 1024");
  usage({"--mesh", "--rig", "--max-joints", "many"}, "from 1 to 1024");
  usage({"--mesh", "--max-joints", "8"}, "add --rig");
  usage({"--mesh", "--animation"}, "add --rig");
  usage({"--wind-data"}, "add --mesh");
  usage({"--lod", "2"}, "add --mesh");
  usage({"--mesh", "--lod", "0"}, "from 1 to 6");
  usage({"--mesh", "--lod", "7"}, "from 1 to 6");
  usage({"--mesh", "--compress", "zstd"}, "expected meshopt or none");
  const std::string still = placed_scene(dir, kElm, R"({"wind":[0,1,0]})");
  ProcessResult r = run_sylva({"export", still, "--mesh", "--rig", "--animation", "-o", out});
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("moves no joint"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // Two joints: the root and the trunk's base, which the sway never turns.
  r = run_sylva({"export", kElm, "--mesh", "--rig", "--max-joints", "2", "--animation", "-o", out});
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("allow more joints"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// --compress meshopt: smaller, the extension required, and three.js (its WebAssembly
// MeshoptDecoder) decodes exactly the plain file's geometry and plays the same clip; the
// skeleton in extras reads back unchanged.
TEST(ExportCompress, MeshoptIsSmallerAndDecodesInThreeJsToThePlainFilesVertices) {
  TempDir dir;
  const std::string plain = dir.file("plain.glb"), packed = dir.file("packed.glb");
  const std::vector<std::string> flags = {"--mesh", "--segments-around", "5", "--rig", "--animation", "--lod", "2"};
  std::vector<std::string> args = {"export", kLeafy, "-o", plain};
  args.insert(args.end(), flags.begin(), flags.end());
  expect_ok(run_sylva(args));
  args[3] = packed;
  args.insert(args.end(), {"--compress", "meshopt"});
  expect_ok(run_sylva(args));
  const uintmax_t plain_bytes = fs::file_size(plain), packed_bytes = fs::file_size(packed);
  EXPECT_LT(packed_bytes, plain_bytes * 7 / 10) << plain_bytes << " -> " << packed_bytes;
  const std::string text = read_file(packed);
  EXPECT_NE(text.find(R"("extensionsRequired":["EXT_meshopt_compression"])"), std::string::npos);
  EXPECT_EQ(read_file(plain).find("EXT_meshopt_compression"), std::string::npos);

  std::vector<JsonValue> reports;
  for (const std::string& file : {plain, packed}) {
    ProcessResult r = run_node_script("three_check.mjs", "three", {file, "--times", "0,1.25", "--every", "7"});
    ASSERT_EQ(r.exit_code, 0) << describe(r, 20000);
    Expected<JsonValue> report = report_after(r.out, "THREE_CHECK ");
    ASSERT_TRUE(report);
    reports.push_back(std::move(*report));
  }
  const JsonValue& a = *reports[0].find("meshes");
  const JsonValue& b = *reports[1].find("meshes");
  ASSERT_EQ(a.elements.size(), b.elements.size());
  ASSERT_GT(a.elements.size(), 3u);
  for (size_t m = 0; m < a.elements.size(); ++m) {
    EXPECT_EQ(a.elements[m].find("name")->text, b.elements[m].find("name")->text);
    EXPECT_EQ(a.elements[m].find("indices")->number, b.elements[m].find("indices")->number);
    EXPECT_EQ(numbers_of(*a.elements[m].find("positions")), numbers_of(*b.elements[m].find("positions")))
        << a.elements[m].find("name")->text;
  }
  for (size_t f = 0; f < 2; ++f)
    EXPECT_EQ(numbers_of(reports[0].find("frames")->elements[f].find("meshes")->elements[0]),
              numbers_of(reports[1].find("frames")->elements[f].find("meshes")->elements[0]))
        << "frame " << f;
  Expected<std::vector<GltfPlant>> back = import_gltf_skeletons(packed);
  ASSERT_TRUE(back) << back.error().format();
  Expected<std::vector<GltfPlant>> plain_back = import_gltf_skeletons(plain);
  ASSERT_TRUE(plain_back);
  EXPECT_EQ(back->front().skeleton, plain_back->front().skeleton);
}

}  // namespace
