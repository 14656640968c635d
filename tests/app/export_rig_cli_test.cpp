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
  exported({"export", scene, "--rig", "--animation"}, "scene.glb");
  exported({"export", scene, "--rig", "--animation", "--extras", "full"}, "scene.gltf");
  ProcessResult r = run_node_script("validate_gltf.mjs", "gltf-validator", files);
  EXPECT_EQ(r.exit_code, 0) << describe(r, 20000);
  for (const std::string& f : files) EXPECT_NE(r.out.find(f + ": 0 errors, 0 warnings"), std::string::npos) << r.out;
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

}  // namespace
