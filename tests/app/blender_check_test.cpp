// blender_check_test.cpp — `sylva export` files opened by another program: Blender's glTF
// importer (Debian's blender 3.4, installed by scripts/setup.sh) reads every triangle of the
// file, every material with its colour, texture and double-sidedness, and the skeleton in
// the plant node's extras (scripts/blender_check.py compares Blender's scene with the
// file's JSON and prints a report). Skipped where blender is not installed.
#include <gtest/gtest.h>

#include <cstdlib>
#include <regex>
#include <string>
#include <vector>

#include "tests/support/process.h"
#include "tests/support/requirements.h"

namespace {

const std::string kSource = SYLVA_SOURCE_DIR;

bool have_blender() { return std::system("command -v blender >/dev/null 2>&1") == 0; }

// Runs scripts/blender_check.py on `file`; returns the run and its report line's JSON.
ProcessResult blender_check(const std::string& file, std::string* report) {
  ProcessResult r = run_process({"blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                                 kSource + "/scripts/blender_check.py", "--", file},
                                {}, 240);
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

}  // namespace
