// blender_check_test.cpp — `sylva export` files opened by another program: Blender's glTF
// importer (Debian's blender 3.4, installed by scripts/setup.sh) reads every triangle of the
// file, every material with its colour, texture and double-sidedness, and the skeleton in
// the plant node's extras (scripts/blender_check.py compares Blender's scene with the
// file's JSON and prints a report). Skipped where blender is not installed.
#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>
#include <map>
#include <optional>
#include <regex>
#include <tuple>
#include <string>
#include <vector>

#include "tests/app/node_script.h"
#include "tests/app/rig_pose.h"
#include "tests/support/process.h"
#include "tests/support/requirements.h"

namespace {

const std::string kSource = SYLVA_SOURCE_DIR;

bool have_blender() { return std::system("command -v blender >/dev/null 2>&1") == 0; }

// Runs scripts/blender_check.py on `file`; returns the run and its report line's JSON.
ProcessResult blender_check(const std::string& file, std::string* report, const std::vector<std::string>& flags = {}) {
  std::vector<std::string> argv = {"blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                                   kSource + "/scripts/blender_check.py", "--", file};
  argv.insert(argv.end(), flags.begin(), flags.end());
  ProcessResult r = run_process(argv, {}, 240);
  const size_t at = r.out.find("BLENDER_CHECK ");
  *report = at == std::string::npos ? std::string() : r.out.substr(at + 14, r.out.find('\n', at) - at - 14);
  return r;
}

// `sylva export INPUT --mesh -o OUT` (compact extras, the default); false, with the run
// described in a test failure, when it does not succeed.
bool export_mesh(const std::string& input, const std::string& out) {
  ProcessResult exported = run_sylva({"export", input, "--mesh", "-o", out}, {}, 120);
  if (exported.exit_code == 0) return true;
  ADD_FAILURE() << describe(exported);
  return false;
}

// Every "triangles_file": A, "triangles_blender": B pair of the report.
std::vector<std::pair<long, long>> triangle_counts(const std::string& report) {
  std::vector<std::pair<long, long>> counts;
  const std::regex pair(R"("triangles_file": (\d+), "triangles_blender": (\d+))");
  for (auto it = std::sregex_iterator(report.begin(), report.end(), pair); it != std::sregex_iterator(); ++it)
    counts.emplace_back(std::stol((*it)[1]), std::stol((*it)[2]));
  return counts;
}

// Exports `input` with --mesh to `out`, checks it in Blender and expects a clean report
// (exit 0, no problem, every mesh's triangles kept); returns the report ("" on failure).
std::string clean_blender_report(const std::string& input, const std::string& out) {
  if (!export_mesh(input, out)) return {};
  std::string report;
  ProcessResult r = blender_check(out, &report);
  EXPECT_EQ(r.exit_code, 0) << describe(r, 20000);
  EXPECT_NE(report.find(R"("problems": [])"), std::string::npos) << report;
  for (const auto& [in_file, in_blender] : triangle_counts(report)) EXPECT_EQ(in_file, in_blender) << report;
  return report;
}

TEST(BlenderCheck, TheElmInLeafImportsWithEveryTriangleItsDoubleSidedLeavesAndItsSkeleton) {
  if (!have_blender()) SYLVA_SKIP_WITHOUT_TOOL("blender is not installed (scripts/setup.sh installs it)");
  TempDir dir;
  const std::string glb = dir.file("elm.glb");
  ASSERT_TRUE(export_mesh(kSource + "/presets/elm_in_leaf.lsys", glb));
  std::string report;
  ProcessResult r = blender_check(glb, &report);
  ASSERT_EQ(r.exit_code, 0) << describe(r, 20000);
  EXPECT_NE(report.find(R"("problems": [])"), std::string::npos) << report;
  const auto counts = triangle_counts(report);
  ASSERT_EQ(counts.size(), 1u) << report;
  EXPECT_GT(counts[0].first, 100000) << report;  // the wood's frusta and the leaves
  EXPECT_EQ(counts[0].first, counts[0].second) << report;
  EXPECT_NE(report.find(R"("name": "sylva_leaf_material_1", "double_sided": true)"), std::string::npos) << report;
  EXPECT_NE(report.find(R"("name": "sylva_material_0", "double_sided": false)"), std::string::npos) << report;
  // Compact extras (the default) are a nested object Blender keeps as a custom property.
  EXPECT_NE(report.find(R"("format": "sylva-skeleton")"), std::string::npos) << report;
}

TEST(BlenderCheck, TheElmInLeafScenesLeafImageArrivesAsATexturedCutOutInBlender) {
  if (!have_blender()) SYLVA_SKIP_WITHOUT_TOOL("blender is not installed (scripts/setup.sh installs it)");
  TempDir dir;
  const std::string report =
      clean_blender_report(kSource + "/presets/scenes/elm_in_leaf.scene.json", dir.file("elm_leaf.glb"));
  // The table's leaf image: baseColorTexture with alphaMode MASK, which Blender imports
  // as an alpha-clipped textured material; the leaves stay double-sided.
  EXPECT_NE(report.find(R"("name": "sylva_leaf_material_1", "double_sided": true, "blend_method": "CLIP", "textured": true)"),
            std::string::npos)
      << report;
}

TEST(BlenderCheck, ASceneWithBarkAndATableKeepsItsTextureAndItsColoursInBlender) {
  if (!have_blender()) SYLVA_SKIP_WITHOUT_TOOL("blender is not installed (scripts/setup.sh installs it)");
  TempDir dir;
  // A .gltf: JSON with the textures as data URIs.
  const std::string report =
      clean_blender_report(kSource + "/presets/scenes/coconut_palm.scene.json", dir.file("palm.gltf"));
  // The bark's albedo texture is material 0's (wood) only; the fronds keep the table's colour.
  EXPECT_NE(report.find(R"("name": "sylva_material_0", "double_sided": false, "blend_method": "OPAQUE", "textured": true)"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find(R"("name": "sylva_material_1", "double_sided": false, "blend_method": "OPAQUE", "textured": false)"),
            std::string::npos)
      << report;
}

TEST(BlenderCheck, TheDesertsSkinOnSegmentsArrivesTexturedThroughItsOwnUvMap) {
  if (!have_blender()) SYLVA_SKIP_WITHOUT_TOOL("blender is not installed (scripts/setup.sh installs it)");
  TempDir dir;
  // docs/materials.md: the table lays cactus.png on materials 1 and 2 with repeats other
  // than the (absent) barks', so the textures read TEXCOORD_1, which Blender imports as
  // a second UV map; 34 plants, their meshes sharing names ("saguaro", "cactus").
  const std::string report = clean_blender_report(kSource + "/presets/scenes/desert.scene.json", dir.file("desert.glb"));
  for (const char* material : {"sylva_material_1", "sylva_material_2"})
    EXPECT_NE(report.find(std::string(R"("name": ")") + material +
                          R"(", "double_sided": false, "blend_method": "OPAQUE", "textured": true, "uv_map": "UVMap.001")"),
              std::string::npos)
        << material << ": " << report;
  EXPECT_EQ(triangle_counts(report).size(), 34u) << report;
}

// The check is not a formality: a file the validator accepts but Blender reads otherwise
// is a problem. Two materials of one name are valid glTF; Blender renames the second
// ("sylva_material_0.001"), so the leaves no longer have the material the file names.
TEST(BlenderCheck, AFileBlenderReadsOtherwiseThanItSaysIsAProblem) {
  if (!have_blender()) SYLVA_SKIP_WITHOUT_TOOL("blender is not installed (scripts/setup.sh installs it)");
  TempDir dir;
  const std::string gltf = dir.file("elm.gltf");
  ASSERT_TRUE(export_mesh(kSource + "/presets/elm_in_leaf.lsys", gltf));
  std::string text = read_file(gltf);
  const std::string leaf = R"("name":"sylva_leaf_material_1")";
  const size_t at = text.find(leaf);
  ASSERT_NE(at, std::string::npos) << text.substr(0, 2000);
  text.replace(at, leaf.size(), R"("name":"sylva_material_0")");
  write_file(gltf, text);
  std::string report;
  ProcessResult r = blender_check(gltf, &report);
  EXPECT_EQ(r.exit_code, 1) << describe(r, 20000);
  EXPECT_NE(report.find("in Blender"), std::string::npos) << report;
  EXPECT_EQ(report.find(R"("problems": [])"), std::string::npos) << report;
}

// The levels of detail in Blender: one object a level, each with every triangle of its
// mesh, the counts falling strictly, the last two textured cut-out cards.
TEST(BlenderCheck, TheElmsLevelsOfDetailImportWithFallingTriangleCounts) {
  if (!have_blender()) SYLVA_SKIP_WITHOUT_TOOL("blender is not installed (scripts/setup.sh installs it)");
  TempDir dir;
  const std::string glb = dir.file("elm_lod.glb");
  ProcessResult exported = run_sylva({"export", kSource + "/presets/elm_in_leaf.lsys", "--mesh", "--lod", "3", "-o", glb},
                                     {}, 120);
  ASSERT_EQ(exported.exit_code, 0) << describe(exported);
  std::string report;
  ProcessResult r = blender_check(glb, &report);
  ASSERT_EQ(r.exit_code, 0) << describe(r, 20000);
  EXPECT_NE(report.find(R"("problems": [])"), std::string::npos) << report;
  long before = -1;
  for (int level = 0; level <= 3; ++level) {
    const std::regex mesh("\"name\": \"elm_in_leaf_LOD" + std::to_string(level) +
                          R"(", "triangles_file": (\d+), "triangles_blender": (\d+))");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(report, m, mesh)) << "level " << level << ": " << report.substr(0, 3000);
    const long triangles = std::stol(m[2]);
    EXPECT_EQ(std::stol(m[1]), triangles);
    if (before >= 0) {
      EXPECT_LT(triangles, before) << "level " << level;
    }
    before = triangles;
  }
  EXPECT_EQ(before, 4);
  EXPECT_NE(report.find(R"("name": "elm_in_leaf_card_0", "double_sided": true, "blend_method": "CLIP", "textured": true)"),
            std::string::npos)
      << report.substr(0, 4000);
}

// The wind rig in Blender: one armature with the rig's joints, the clip an action of its
// length, and the deformed vertices at three frames where sylva's own pose puts them
// (placement included), the last frame the first.
TEST(BlenderCheck, TheRiggedElmSwaysInBlenderAsSylvaPosesIt) {
  if (!have_blender()) SYLVA_SKIP_WITHOUT_TOOL("blender is not installed (scripts/setup.sh installs it)");
  using namespace sylva;
  TempDir dir;
  const std::string scene =
      test::placed_scene(dir, kSource + "/presets/elm.lsys", R"({"fps":12,"duration_s":3,"wind":[1,0,-0.5],"seed":4})");
  const std::string glb = dir.file("elm.glb");
  ProcessResult exported =
      run_sylva({"export", scene, "--mesh", "--segments-around", "5", "--rig", "--animation", "--wind-data", "-o", glb},
                {}, 120);
  ASSERT_EQ(exported.exit_code, 0) << describe(exported);
  // Blender plays the clip at 24 fps: frames 14, 44 and 72 are keys 7, 22 and 36 (the last).
  std::string text;
  ProcessResult r = blender_check(glb, &text, {"--pose-frames", "14,44,72", "--every", "11"});
  ASSERT_EQ(r.exit_code, 0) << describe(r, 20000);
  Expected<JsonValue> report = parse_json(text);
  ASSERT_TRUE(report) << text.substr(0, 2000);
  EXPECT_TRUE(report->find("problems")->elements.empty()) << text.substr(0, 4000);
  const test::SylvaRigPose sylva(glb, scene);
  const JsonValue& rig = *report->find("rig");
  ASSERT_EQ(rig.find("armatures")->elements.size(), 1u);
  EXPECT_EQ(rig.find("armatures")->elements[0].find("bones")->number, static_cast<double>(sylva.rig().joints.size()));
  ASSERT_EQ(rig.find("actions")->elements.size(), 1u);
  EXPECT_EQ(test::numbers_of(*rig.find("actions")->elements[0].find("frame_range")), (std::vector<double>{0, 72}));
  // The wind data arrives as UV maps 2 and 3.
  EXPECT_NE(text.find(R"("uv_layers": ["UVMap", "UVMap.001", "UVMap.002", "UVMap.003"])"), std::string::npos) << text.substr(0, 3000);

  // Each vertex's weights, by its rest position, from the file as three.js reads it.
  ProcessResult three = test::run_node_script("three_check.mjs", "three", {glb, "--times", "0"});
  ASSERT_EQ(three.exit_code, 0) << describe(three);
  Expected<JsonValue> file = test::report_after(three.out, "THREE_CHECK ");
  ASSERT_TRUE(file);
  const JsonValue& mesh = file->find("skinned_meshes")->elements.at(0);
  const std::vector<double> rest = test::numbers_of(*mesh.find("rest"));
  const std::vector<double> skin = test::numbers_of(*mesh.find("skin"));
  // Blender keeps a few positions 1 ulp off the file's: matched within 1e-6 m, on a grid.
  constexpr double kCell = 1e-4;
  auto cell = [&](double x, double y, double z) {
    return std::tuple(std::llround(x / kCell), std::llround(y / kCell), std::llround(z / kCell));
  };
  std::map<std::tuple<long long, long long, long long>, std::vector<size_t>> grid;
  for (size_t v = 0; v < rest.size() / 3; ++v) grid[cell(rest[3 * v], rest[3 * v + 1], rest[3 * v + 2])].push_back(v);
  // Every file vertex at Blender's rest position: where two rings meet (a chain and its
  // continuation share their cut curve) two vertices of different weights sit at one
  // position, and Blender's vertex is one of them.
  auto vertices_near = [&](const glm::dvec3& p) {
    std::vector<size_t> out;
    const auto [cx, cy, cz] = cell(p.x, p.y, p.z);
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(std::tuple(cx + dx, cy + dy, cz + dz));
          if (it == grid.end()) continue;
          for (size_t v : it->second)
            if (glm::length(glm::dvec3(rest[3 * v], rest[3 * v + 1], rest[3 * v + 2]) - p) < 1e-6) out.push_back(v);
        }
    return out;
  };

  const JsonValue& poses = *rig.find("poses");
  ASSERT_EQ(poses.elements.size(), 3u);
  double worst = 0, moved = 0;
  size_t compared = 0;
  for (const JsonValue& frame : poses.elements) {
    const std::vector<RigJointPose> pose = sylva.pose(frame.find("time_s")->number);
    const std::vector<double> blender_rest = test::numbers_of(*frame.find("rest"));
    const std::vector<double> posed = test::numbers_of(*frame.find("posed"));
    ASSERT_EQ(blender_rest.size(), posed.size());
    for (size_t i = 0; i + 2 < posed.size(); i += 3) {
      const glm::dvec3 p0(blender_rest[i], blender_rest[i + 1], blender_rest[i + 2]);
      const std::vector<size_t> candidates = vertices_near(p0);
      ASSERT_FALSE(candidates.empty()) << "Blender's vertex " << i / 3 << " is at no rest position of the file";
      double nearest = std::numeric_limits<double>::infinity();
      for (size_t v : candidates) {
        const glm::dvec3 expected = sylva.posed(pose, test::weights_of(skin, v), p0);
        nearest = std::min(nearest, glm::length(glm::dvec3(posed[i], posed[i + 1], posed[i + 2]) - expected));
        moved = std::max(moved, glm::length(expected - sylva.placed(p0)));
      }
      worst = std::max(worst, nearest);
      ++compared;
    }
  }
  EXPECT_GT(compared, 3000u);
  EXPECT_GT(moved, 0.05) << "the clip must move the tree";
  // Blender poses in single precision through the bones' own frames: 1e-4 of the
  // height (measured: 7.7e-4 m on this 28 m elm, 2.8e-5 of it).
  EXPECT_LT(worst, 1e-4 * sylva.placed_height_m()) << "Blender and sylva disagree by " << worst << " m";
}

}  // namespace
