// export_cli_test.cpp — `sylva export` (docs/spec/cli.md, gltf_export.h): every export variant passes
// the Khronos glTF validator (scripts/validate_gltf.mjs: no error, no warning), the
// skeleton survives the round trip, usage errors exit 2; and batches (`--seed A..B`,
// `-o out/p_{seed}.glb`) for export and grow: every seed written, a failing seed named
// without stopping or damaging the others.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "core/io/gltf.h"
#include "core/geometry/skeleton.h"
#include "tests/app/node_script.h"
#include "tests/support/process.h"

namespace {

namespace fs = std::filesystem;

const std::string kSource = SYLVA_SOURCE_DIR;
const std::string kPlant = kSource + "/presets/abop_1_24a.lsys";
const std::string kOtherPlant = kSource + "/presets/abop_1_27_stochastic.lsys";
const std::string kBarkAlbedo = kSource + "/presets/textures/bark.png";
const std::string kBarkHeight = kSource + "/presets/textures/bark_height.png";
// Divides by zero for the seeds whose first rand() is below 1/15.5 (seed 7 among 1..8).
constexpr const char* kSometimesBroken = "derivation length: 1\naxiom: A\nA -> F(1/floor(rand()*15.5))\n";

// Runs the validator harness on `files`. Fails the test (never skips) when node or the
// validator is missing.
ProcessResult validate(const std::vector<std::string>& files) {
  return sylva::test::run_node_script("validate_gltf.mjs", "gltf-validator", files);
}

void expect_valid(const std::vector<std::string>& files) {
  ProcessResult r = validate(files);
  EXPECT_EQ(r.exit_code, 0) << describe(r, 20000);
  for (const std::string& f : files) EXPECT_NE(r.out.find(f + ": 0 errors, 0 warnings"), std::string::npos) << r.out;
}

void expect_ok(const ProcessResult& r) {
  EXPECT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 0) << describe(r);
}

TEST(ExportCli, EveryVariantPassesTheKhronosValidator) {
  TempDir dir;
  const std::string scene = dir.write("forest.scene.json", R"({"format":"sylva-scene","version":1,"plants":[
    {"grammar":")" + kPlant + R"(","seed":1,"position":[0,0,0]},
    {"grammar":")" + kPlant + R"(","seed":1,"position":[3,0,0],"rotate_y_deg":90,"scale":1.5},
    {"grammar":")" + kPlant + R"(","seed":1,"position":[0,0,3],"rotate_y_deg":-45},
    {"grammar":")" + kOtherPlant + R"(","seed":2,"position":[-3,0,0]}]})");
  expect_ok(run_sylva({"grow", kPlant, "-o", dir.file("plant.skel.json")}));
  std::vector<std::string> files;
  for (const std::string& input : {kPlant, dir.file("plant.skel.json"), scene})
    for (const char* ext : {".glb", ".gltf"})
      for (bool mesh : {false, true}) {
        const std::string kind = input == kPlant ? "lsys" : input == scene ? "forest" : "skel";
        std::vector<std::string> args = {"export", input, "-o", dir.file(kind + (mesh ? "_mesh" : "") + ext)};
        if (mesh) args.insert(args.end(), {"--mesh", "--segments-around", "5"});
        files.push_back(args[3]);
        expect_ok(run_sylva(args));
        if (input == scene) {  // the forest once more with EXT_mesh_gpu_instancing
          args[3] = dir.file(kind + (mesh ? "_mesh" : "") + "_instanced" + ext);
          args.push_back("--instancing");
          files.push_back(args[3]);
          expect_ok(run_sylva(args));
        }
      }
  // Textured barks: from the flags for a grammar, from each plant of a scene (paths
  // relative to the scene file; a colour albedo with a height map too).
  for (const char* ext : {".glb", ".gltf"}) {
    files.push_back(dir.file(std::string("lsys_bark") + ext));
    expect_ok(run_sylva({"export", kPlant, "-o", files.back(), "--mesh", "--segments-around", "6", "--bark-albedo",
                         kBarkAlbedo, "--bark-height", kBarkHeight, "--relief-depth", "0.005", "--u-repeat", "2",
                         "--v-per-metre", "3"}));
  }
  fs::create_directories(dir.path() / "textures");
  fs::copy_file(kBarkAlbedo, dir.path() / "textures/bark.png");
  fs::copy_file(kBarkHeight, dir.path() / "textures/bark_height.png");
  const std::string bark_scene = dir.write("bark.scene.json", R"({"format":"sylva-scene","version":1,"plants":[
    {"grammar":")" + kPlant + R"(","seed":1,"bark":{"albedo":"textures/bark.png","height":"textures/bark_height.png",
     "relief_depth":0.01,"u_repeat":2,"v_per_metre":1}},
    {"grammar":")" + kOtherPlant + R"(","seed":2,"position":[2,0,0],
     "bark":{"albedo":[0.4,0.3,0.2],"height":"textures/bark_height.png","u_repeat":3}}]})");
  for (const char* ext : {".glb", ".gltf"}) {
    files.push_back(dir.file(std::string("scene_bark") + ext));
    expect_ok(run_sylva({"export", bark_scene, "-o", files.back(), "--mesh", "--segments-around", "5"}));
  }
  ASSERT_EQ(files.size(), 20u);
  expect_valid(files);
  // The instanced forest holds 2 nodes for 4 plants and reads back as 4 plants.
  const auto forest = sylva::import_gltf_skeletons(dir.file("forest_mesh_instanced.glb"));
  ASSERT_TRUE(forest.ok()) << forest.error().format();
  ASSERT_EQ(forest->size(), 4u);
  EXPECT_EQ((*forest)[1].position_m[0], 3);
  EXPECT_EQ((*forest)[1].scale, 1.5);
  EXPECT_EQ((*forest)[3].name, "abop_1_27_stochastic");
}

// Like grow, export prints one summary line on stdout for each file it writes: what it
// read, the file, its plants, chains and segments, the file's size in bytes and the time.
TEST(ExportCli, PrintsOneSummaryLinePerFileLikeGrow) {
  TempDir dir;
  const std::string scene = dir.write("pair.scene.json", R"({"format":"sylva-scene","version":1,"plants":[
    {"grammar":")" + kPlant + R"(","seed":1,"position":[0,0,0]},
    {"grammar":")" + kOtherPlant + R"(","seed":2,"position":[-3,0,0]}]})");
  expect_ok(run_sylva({"grow", kPlant, "-o", dir.file("plant.skel.json")}));
  const auto grown = sylva::read_skeleton_file(dir.file("plant.skel.json"));
  ASSERT_TRUE(grown) << grown.error().format();
  struct Case {
    std::string input, plants;
  };
  for (const Case& c : {Case{kPlant, "1 plant, "}, Case{dir.file("plant.skel.json"), "1 plant, "},
                        Case{scene, "2 plants, "}}) {
    const std::string out = dir.file("out.glb");
    ProcessResult r = run_sylva({"export", c.input, "-o", out});
    expect_ok(r);
    const std::string bytes = std::to_string(fs::file_size(out)) + " bytes, ";
    EXPECT_EQ(r.out.rfind(c.input + " -> " + out + ": " + c.plants, 0), 0u) << r.out;
    EXPECT_NE(r.out.find(bytes), std::string::npos) << bytes << "\n" << r.out;
    EXPECT_NE(r.out.find(" chains, "), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << "one line:\n" << r.out;
    EXPECT_EQ(r.out.substr(r.out.size() - 4), " ms\n") << r.out;
    if (c.plants == "1 plant, ") {
      EXPECT_NE(r.out.find(std::to_string(grown->chains.size()) + " chains, " +
                           std::to_string(grown->segment_count()) + " segments, "),
                std::string::npos)
          << r.out;
    }
  }
  // A batch: one line per seed.
  ProcessResult r = run_sylva({"export", kPlant, "--seed", "1..3", "-o", dir.file("b/p_{seed}.glb")});
  expect_ok(r);
  for (int seed = 1; seed <= 3; ++seed)
    EXPECT_NE(r.out.find(kPlant + " -> " + dir.file("b/p_" + std::to_string(seed) + ".glb") + ": 1 plant, "),
              std::string::npos)
        << r.out;
}

TEST(ExportCli, ALeafyPlantsMeshPassesTheKhronosValidator) {
  // The leaves' double-sided primitives (gltf_export.h) beside the frusta's.
  TempDir dir;
  const std::string leafy = kSource + "/presets/abop_1_25_bush_leaves.lsys";
  std::vector<std::string> files;
  for (const char* ext : {".glb", ".gltf"}) {
    files.push_back(dir.file(std::string("leafy") + ext));
    expect_ok(run_sylva({"export", leafy, "-o", files.back(), "--mesh", "--segments-around", "4", "-D", "N=4"}));
  }
  expect_valid(files);
}

TEST(ExportCli, ALeafImageCutOutAndOneSidedLeavesBecomeTheirGltfMaterial) {
  // One square leaf of material 2 with the bundled elm leaf (its own alpha: a cut-out),
  // one-sided; material 3's leaf plain. Both files pass the validator.
  TempDir dir;
  const std::string grammar = dir.write(
      "leaf.lsys", "angle: 90\naxiom: !(0.02)F(1)'(2){.+f(1).-f(1).-f(1).}F(1)'(3){.+f(1).-f(1).-f(1).}\n");
  const std::string scene = dir.write("leaf.scene.json", R"({"format":"sylva-scene","version":1,
    "materials":[{"index":2,"albedo":")" + kSource + R"(/presets/textures/elm_leaf.png","two_sided":false}],
    "plants":[{"grammar":"leaf.lsys"}]})");
  std::vector<std::string> files;
  for (const char* ext : {".gltf", ".glb"}) {
    files.push_back(dir.file(std::string("leaf") + ext));
    expect_ok(run_sylva({"export", scene, "-o", files.back(), "--mesh"}));
  }
  expect_valid(files);
  const std::string text = read_file(files[0]);
  const size_t m2 = text.find("\"name\":\"sylva_leaf_material_2\"");
  const size_t m3 = text.find("\"name\":\"sylva_leaf_material_3\"");
  ASSERT_NE(m2, std::string::npos) << text.substr(0, 4000);
  ASSERT_NE(m3, std::string::npos);
  const std::string leaf2 = text.substr(m2, text.find("\"extras\"", m2) - m2);
  const std::string leaf3 = text.substr(m3, text.find("\"extras\"", m3) - m3);
  EXPECT_NE(leaf2.find("\"baseColorTexture\""), std::string::npos) << leaf2;
  EXPECT_NE(leaf2.find("\"alphaMode\":\"MASK\""), std::string::npos) << leaf2;
  EXPECT_NE(leaf2.find("\"alphaCutoff\":0.5"), std::string::npos) << leaf2;
  EXPECT_NE(leaf2.find("\"doubleSided\":false"), std::string::npos) << leaf2;
  EXPECT_EQ(leaf3.find("\"baseColorTexture\""), std::string::npos) << leaf3;
  EXPECT_EQ(leaf3.find("\"alphaMode\""), std::string::npos) << leaf3;
  EXPECT_NE(leaf3.find("\"doubleSided\":true"), std::string::npos) << leaf3;
  EXPECT_NE(text.find("\"TEXCOORD_0\""), std::string::npos);
  // A leaf image that is not there is refused before anything is written, at its key.
  const std::string broken = dir.write("broken.scene.json", R"({"format":"sylva-scene","version":1,
    "materials":[{"index":2,"alpha":"nowhere.png"}],"plants":[{"grammar":"leaf.lsys"}]})");
  const ProcessResult r = run_sylva({"export", broken, "-o", dir.file("broken.glb"), "--mesh"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("broken.scene.json:2:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("materials[0].alpha: no such image file"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("broken.glb")));
}

// --extras compact (the default), full and none, for a leafy grammar and a scatter scene
// with and without instancing: every file passes the validator; compact and full read
// back to the same plants; none is a plain mesh that render refuses clearly;
// EXT_mesh_gpu_instancing is required exactly where it is used.
TEST(ExportCli, EveryExtrasModePassesTheValidatorAndCompactReadsBackLikeFull) {
  TempDir dir;
  const std::string leafy = kSource + "/presets/abop_1_25_bush_leaves.lsys";
  const std::string scatter = dir.write("scatter.scene.json", R"({"format":"sylva-scene","version":1,"plants":[],
    "scatter":[{"grammar":")" + kPlant + R"(","count":12,"seed":1,"plant_seeds":[1,3],"disc":{"centre":[0,0],"radius":10},
                "rotate_y_deg":[0,360],"scale":[0.8,1.2]}]})");
  std::vector<std::string> files;
  struct Case {
    std::string input, name;
    std::vector<std::string> flags;
    bool instanced;
  };
  std::vector<Case> cases;
  for (const char* mode : {"compact", "full", "none"})
    for (const char* ext : {".glb", ".gltf"}) {
      const std::string m = mode;
      cases.push_back({leafy, "leafy_" + m + ext, {"--extras", m, "--mesh", "--segments-around", "4", "-D", "N=3"}, false});
      cases.push_back({scatter, "scatter_" + m + ext, {"--extras", m}, false});
      cases.push_back({scatter, "scatter_inst_" + m + ext, {"--extras", m, "--instancing", "--mesh"}, true});
    }
  cases.push_back({scatter, "scatter_default.glb", {"--instancing", "--mesh"}, true});
  for (const Case& c : cases) {
    std::vector<std::string> args = {"export", c.input, "-o", dir.file(c.name)};
    args.insert(args.end(), c.flags.begin(), c.flags.end());
    expect_ok(run_sylva(args));
    files.push_back(dir.file(c.name));
    // extensionsRequired (and extensionsUsed) exactly when the instancing extension is used.
    const std::string bytes = read_file(dir.file(c.name));
    EXPECT_EQ(bytes.find("\"extensionsRequired\":[\"EXT_mesh_gpu_instancing\"]") != std::string::npos, c.instanced)
        << c.name;
    EXPECT_EQ(bytes.find("EXT_mesh_gpu_instancing") != std::string::npos, c.instanced) << c.name;
  }
  expect_valid(files);
  EXPECT_EQ(read_file(dir.file("scatter_default.glb")), read_file(dir.file("scatter_inst_compact.glb")))
      << "compact is the default";
  for (const char* stem : {"leafy_", "scatter_", "scatter_inst_"})
    for (const char* ext : {".glb", ".gltf"}) {
      SCOPED_TRACE(std::string(stem) + ext);
      const auto full = sylva::import_gltf_skeletons(dir.file(std::string(stem) + "full" + ext));
      const auto compact = sylva::import_gltf_skeletons(dir.file(std::string(stem) + "compact" + ext));
      ASSERT_TRUE(full.ok()) << full.error().format();
      ASSERT_TRUE(compact.ok()) << compact.error().format();
      ASSERT_EQ(full->size(), compact->size());
      for (size_t i = 0; i < full->size(); ++i) {
        EXPECT_EQ((*full)[i].skeleton, (*compact)[i].skeleton);
        EXPECT_EQ((*full)[i].name, (*compact)[i].name);
        for (int k = 0; k < 3; ++k) EXPECT_EQ((*full)[i].position_m[k], (*compact)[i].position_m[k]);
        EXPECT_EQ((*full)[i].rotate_y_deg, (*compact)[i].rotate_y_deg);
        EXPECT_EQ((*full)[i].scale, (*compact)[i].scale);
      }
      EXPECT_LT(std::filesystem::file_size(dir.file(std::string(stem) + "compact" + ext)),
                std::filesystem::file_size(dir.file(std::string(stem) + "full" + ext)));
    }
  const auto scattered = sylva::import_gltf_skeletons(dir.file("scatter_inst_compact.glb"));
  ASSERT_TRUE(scattered.ok());
  EXPECT_EQ(scattered->size(), 12u);
  ProcessResult r = run_sylva({"render", dir.file("leafy_none.glb"), "--backend", "cpu", "-o", dir.file("x.png")});
  EXPECT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("no sylva skeleton"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--extras none"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("x.png")));
  ProcessResult bad = run_sylva({"export", kPlant, "-o", dir.file("y.glb"), "--extras", "tiny"});
  EXPECT_EQ(bad.exit_code, 2) << describe(bad);
  EXPECT_NE(bad.err.find("--extras tiny: expected compact, full or none"), std::string::npos) << bad.err;
  ProcessResult help = run_sylva({"export", "--help"});
  EXPECT_NE(help.out.find("--extras MODE"), std::string::npos) << help.out;
}

TEST(ExportCli, TheValidatorHarnessRejectsErrorsAndWarnings) {
  TempDir dir;
  // An error: mode -1 (what tinygltf writes when Primitive::mode is unset).
  const std::string error_file = dir.write(
      "mode.gltf", R"({"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{},"mode":-1}]}]})");
  ProcessResult r = validate({error_file});
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  // A warning only: an unexpected property.
  const std::string warning_file = dir.write("warn.gltf", R"({"asset":{"version":"2.0"},"unexpected":1})");
  r = validate({warning_file});
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.out.find("warning"), std::string::npos) << r.out;
}

TEST(ExportCli, TheSkeletonSurvivesTheRoundTripExactly) {
  TempDir dir;
  expect_ok(run_sylva({"grow", kOtherPlant, "--seed", "18446744073709551615", "-n", "4", "-o", dir.file("p.skel.json")}));
  expect_ok(run_sylva({"export", dir.file("p.skel.json"), "-o", dir.file("a.glb"), "--mesh"}));
  expect_ok(run_sylva({"export", kOtherPlant, "--seed", "18446744073709551615", "-n", "4", "-o", dir.file("b.gltf")}));
  const std::string expected = read_file(dir.path() / "p.skel.json");
  for (const char* name : {"a.glb", "b.gltf"}) {
    const auto r = sylva::import_gltf_skeletons(dir.file(name));
    ASSERT_TRUE(r.ok()) << r.error().format();
    ASSERT_EQ(r->size(), 1u);
    EXPECT_EQ(sylva::write_skeleton_json((*r)[0].skeleton), expected) << name;
  }
  EXPECT_EQ(sylva::import_gltf_skeletons(dir.file("a.glb"))->at(0).name, "p");
  EXPECT_EQ(sylva::import_gltf_skeletons(dir.file("b.gltf"))->at(0).name, "abop_1_27_stochastic");
}

TEST(ExportCli, RenderingTheExportedFileGivesTheSameDepthImageAsTheGrammar) {
  TempDir dir;
  const std::string saguaro = kSource + "/presets/saguaro.lsys";
  expect_ok(run_sylva({"export", saguaro, "-o", dir.file("saguaro.glb"), "--mesh"}));
  for (const char* input : {"glb", "lsys"}) {
    const std::string in = std::string(input) == "glb" ? dir.file("saguaro.glb") : saguaro;
    expect_ok(run_sylva({"render", in, "--backend", "cpu", "-o", dir.file(std::string("from_") + input + ".exr"),
                         "--aov", "depth", "--width", "96", "--height", "72"}));
  }
  // Images are written reproducibly (fixed metadata), so equal pixels mean equal files.
  const std::string from_glb = read_file(dir.path() / "from_glb.exr");
  EXPECT_FALSE(from_glb.empty());
  EXPECT_TRUE(from_glb == read_file(dir.path() / "from_lsys.exr"));
}

// docs/spec/scene.md "Skin": --skin on render and export over the scene's key, the
// paper's skin in the export's mesh and extras, and the exported file rendering as the
// grammar does under the same skin.
TEST(ExportCli, TheSkinFlagAndTheScenesSkinKeyGiveThePapersSkinEverywhere) {
  TempDir dir;
  const std::string saguaro = kSource + "/presets/saguaro.lsys";
  const std::string scene = dir.write("paper.scene.json", R"({"skin": "paper", "image": {"width": 96, "height": 72},
    "plants": [{"grammar": ")" + saguaro + R"(", "seed": 3}]})");
  const std::string smooth_scene = dir.write("smooth.scene.json", R"({"image": {"width": 96, "height": 72},
    "plants": [{"grammar": ")" + saguaro + R"(", "seed": 3}]})");
  auto depth = [&](const std::string& input, const std::string& out, std::vector<std::string> more = {}) {
    std::vector<std::string> argv = {"render", input, "--backend", "cpu", "-o", dir.file(out), "--aov", "depth",
                                     "--spp", "1"};
    argv.insert(argv.end(), more.begin(), more.end());
    expect_ok(run_sylva(argv));
    return read_file(dir.path() / out);
  };
  const std::string by_key = depth(scene, "key.exr");
  EXPECT_FALSE(by_key.empty());
  EXPECT_EQ(by_key, depth(smooth_scene, "flag.exr", {"--skin", "paper"})) << "--skin paper = the scene's key";
  EXPECT_NE(by_key, depth(smooth_scene, "smooth.exr")) << "the paper's skin changed nothing";
  EXPECT_EQ(depth(scene, "over.exr", {"--skin", "smooth"}), read_file(dir.path() / "smooth.exr"))
      << "--skin smooth overrides the scene's paper";
  // Export: the scene's key and the flag give the same file; extras say which skin.
  expect_ok(run_sylva({"export", scene, "-o", dir.file("key.gltf"), "--mesh", "--extras", "full"}));
  expect_ok(run_sylva({"export", smooth_scene, "-o", dir.file("flag.gltf"), "--mesh", "--extras", "full", "--skin",
                       "paper"}));
  expect_ok(run_sylva({"export", smooth_scene, "-o", dir.file("smooth.gltf"), "--mesh", "--extras", "full"}));
  const std::string key_gltf = read_file(dir.path() / "key.gltf");
  EXPECT_EQ(key_gltf, read_file(dir.path() / "flag.gltf"));
  EXPECT_NE(key_gltf.find("\"skin\":\"paper\""), std::string::npos);
  EXPECT_NE(read_file(dir.path() / "smooth.gltf").find("\"skin\":\"smooth\""), std::string::npos);
  expect_valid({dir.file("key.gltf")});
  // A paper export renders back with the paper's skin (extras' skinning.skin).
  expect_ok(run_sylva({"export", saguaro, "-o", dir.file("paper.glb"), "--skin", "paper", "--seed", "3"}));
  const std::vector<std::string> size = {"--width", "96", "--height", "72"};
  std::vector<std::string> paper_grammar = {"--skin", "paper", "--seed", "3", "--width", "96", "--height", "72"};
  EXPECT_EQ(depth(dir.file("paper.glb"), "glb.exr", size), depth(saguaro, "grammar.exr", paper_grammar));
  EXPECT_NE(read_file(dir.path() / "glb.exr"), depth(saguaro, "grammar_smooth.exr", {"--seed", "3", "--width", "96",
                                                                                       "--height", "72"}));
  ProcessResult bad = run_sylva({"export", saguaro, "-o", dir.file("x.glb"), "--skin", "mitred"});
  EXPECT_EQ(bad.exit_code, 2) << describe(bad);
  EXPECT_NE(bad.err.find("--skin mitred: expected smooth or paper"), std::string::npos) << bad.err;
  bad = run_sylva({"render", saguaro, "-o", dir.file("x.png"), "--skin"});
  EXPECT_EQ(bad.exit_code, 2) << describe(bad);
  EXPECT_FALSE(fs::exists(dir.path() / "x.glb"));
  EXPECT_FALSE(fs::exists(dir.path() / "x.png"));
}

TEST(ExportCli, RenderingAGltfWithoutSylvaExtrasIsAClearError) {
  TempDir dir;
  const std::string plain = dir.write("plain.gltf", R"({"asset":{"version":"2.0"},"nodes":[{"name":"x"}]})");
  ProcessResult r = run_sylva({"render", plain, "--backend", "cpu", "-o", dir.file("x.png")});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("plain.gltf"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "x.png"));
}

TEST(ExportCli, UsageErrorsExitTwoAndInputErrorsExitOne) {
  TempDir dir;
  const std::string skel = dir.file("p.skel.json");
  expect_ok(run_sylva({"grow", kPlant, "-o", skel}));
  const std::vector<std::vector<std::string>> usage = {
      {"export"},
      {"export", kPlant},
      {"export", "-o", dir.file("x.glb")},
      {"export", kPlant, "-o", dir.file("x.obj")},
      {"export", kPlant, "-o", dir.file("x.glb"), "--segments-around", "2"},
      {"export", kPlant, "-o", dir.file("x.glb"), "--segments-around"},
      {"export", kPlant, "-o", dir.file("x.glb"), "--frobnicate"},
      {"export", kPlant, "-o", dir.file("x.glb"), "--seed", "1..4"},
      {"export", kPlant, "-o", dir.file("x_{seed}.glb"), "--seed", "5..1"},
      {"export", kPlant, "-o", dir.file("x_{seed}.glb"), "--seed", "1..x"},
      {"export", kPlant, "-o", dir.file("x_{seed}.glb"), "--seed", "1..2", "--seed", "3"},
      {"export", kPlant, "-o", dir.file("x_{seed}.glb"), "--seed", "0..18446744073709551615"},
      {"export", skel, "-o", dir.file("x.glb"), "-n", "3"},
      {"export", dir.file("model.obj"), "-o", dir.file("x.glb")},
      {"grow", kPlant, "-o", dir.file("x.skel.json"), "--seed", "1..3"},
  };
  for (const auto& args : usage) {
    ProcessResult r = run_sylva(args);
    EXPECT_FALSE(crashed(r)) << describe(r);
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_NE(r.err.find("error"), std::string::npos) << describe(r);
  }
  const std::vector<std::vector<std::string>> input = {
      {"export", dir.file("missing.lsys"), "-o", dir.file("x.glb")},
      {"export", dir.write("broken.lsys", "axiom: F[+F\n"), "-o", dir.file("x.glb")},
      {"export", dir.write("bad.skel.json", "{}"), "-o", dir.file("x.glb")},
      {"export", kPlant, "-o", dir.file("no/such/folder/x.glb")},
  };
  for (const auto& args : input) {
    ProcessResult r = run_sylva(args);
    EXPECT_FALSE(crashed(r)) << describe(r);
    EXPECT_EQ(r.exit_code, 1) << describe(r);
  }
  EXPECT_FALSE(fs::exists(dir.file("x.glb")));
  ProcessResult help = run_sylva({"export", "--help"});
  expect_ok(help);
  EXPECT_NE(help.out.find("--segments-around"), std::string::npos);
  EXPECT_NE(run_sylva({"--help"}).out.find("export"), std::string::npos);
}

TEST(ExportCli, BarkFlagsNeedAMeshAndAGrammarOrSkeletonAndReadableTextures) {
  TempDir dir;
  const std::string skel = dir.file("p.skel.json");
  expect_ok(run_sylva({"grow", kPlant, "-o", skel}));
  const std::string scene = dir.write("s.scene.json", R"({"format":"sylva-scene","version":1,"plants":[
    {"grammar":")" + kPlant + R"("}]})");
  const std::string out = dir.write("keep.glb", "old contents");
  const std::vector<std::vector<std::string>> usage = {
      {"export", kPlant, "-o", out, "--bark-albedo", kBarkAlbedo},  // no --mesh
      {"export", scene, "-o", out, "--mesh", "--bark-height", kBarkHeight},
      {"export", kPlant, "-o", out, "--mesh", "--u-repeat", "0"},
      {"export", kPlant, "-o", out, "--mesh", "--v-per-metre", "-1"},
      {"export", kPlant, "-o", out, "--mesh", "--relief-depth", "deep"},
      {"export", kPlant, "-o", out, "--mesh", "--relief-depth", "nan"},
      {"export", kPlant, "-o", out, "--mesh", "--bark-height"},
  };
  for (const auto& args : usage) {
    ProcessResult r = run_sylva(args);
    EXPECT_FALSE(crashed(r)) << describe(r);
    EXPECT_EQ(r.exit_code, 2) << describe(r);
  }
  // A missing or unusable texture: exit 1, the file named, the old output untouched.
  const std::string text = dir.write("notes.png", "not an image");
  const std::vector<std::pair<std::vector<std::string>, std::string>> input = {
      {{"export", kPlant, "-o", out, "--mesh", "--bark-albedo", dir.file("missing.png")}, dir.file("missing.png")},
      {{"export", skel, "-o", out, "--mesh", "--bark-height", dir.file("gone.png")}, dir.file("gone.png")},
      {{"export", kPlant, "-o", out, "--mesh", "--bark-albedo", text}, text},
      {{"export", kPlant, "--seed", "1..3", "-o", dir.file("b/p_{seed}.glb"), "--mesh", "--bark-height=" + text}, text},
  };
  for (const auto& [args, file] : input) {
    ProcessResult r = run_sylva(args);
    EXPECT_FALSE(crashed(r)) << describe(r);
    EXPECT_EQ(r.exit_code, 1) << describe(r);
    EXPECT_NE(r.err.find(file), std::string::npos) << describe(r);
  }
  EXPECT_EQ(read_file(out), "old contents");
  EXPECT_FALSE(fs::exists(dir.path() / "b"));  // checked before the batch starts
  // The flags reach the file: the material's extras carry them.
  expect_ok(run_sylva({"export", skel, "-o", dir.file("ok.gltf"), "--mesh", "--bark-height=" + kBarkHeight,
                       "--u-repeat=4", "--v-per-metre", "2.5", "--relief-depth", "0.003"}));
  const std::string gltf = read_file(dir.path() / "ok.gltf");
  EXPECT_NE(gltf.find("\"height\":\"" + kBarkHeight + "\",\"relief_depth_m\":0.003,\"u_repeat\":4,\"v_per_metre\":2.5"),
            std::string::npos);
  EXPECT_NE(gltf.find("\"normalTexture\""), std::string::npos);
  EXPECT_EQ(gltf.find("\"baseColorTexture\""), std::string::npos);
  ProcessResult help = run_sylva({"export", "--help"});
  expect_ok(help);
  for (const char* flag : {"--bark-albedo", "--bark-height", "--relief-depth", "--u-repeat", "--v-per-metre"})
    EXPECT_NE(help.out.find(flag), std::string::npos) << flag;
}

TEST(Batch, ExportSeedRangeWritesOneValidFilePerSeed) {
  TempDir dir;
  ProcessResult r = run_sylva({"export", kOtherPlant, "--seed", "1..8", "-o", dir.file("out/p_{seed}.glb"), "--mesh"});
  expect_ok(r);
  std::vector<std::string> files;
  for (int seed = 1; seed <= 8; ++seed) {
    files.push_back(dir.file("out/p_" + std::to_string(seed) + ".glb"));
    const auto back = sylva::import_gltf_skeletons(files.back());
    ASSERT_TRUE(back.ok()) << back.error().format();
    EXPECT_EQ(back->at(0).skeleton.source.seed, static_cast<uint64_t>(seed));
    EXPECT_NE(r.err.find("seed " + std::to_string(seed) + ": ok"), std::string::npos) << r.err;
  }
  EXPECT_EQ(list_dir(dir.path() / "out").size(), 8u);  // no temporary files left
  EXPECT_NE(r.err.find("8 seeds, 8 written, 0 failed"), std::string::npos) << r.err;
  expect_valid(files);
}

TEST(Batch, AFailingSeedIsNamedAndTheOthersAreStillWritten) {
  TempDir dir;
  const std::string grammar = dir.write("sometimes.lsys", kSometimesBroken);
  // Ground truth, one seed at a time.
  std::set<int> bad;
  for (int seed = 1; seed <= 8; ++seed) {
    ProcessResult one = run_sylva({"grow", grammar, "--seed", std::to_string(seed), "-o", dir.file("one.skel.json")});
    ASSERT_FALSE(crashed(one)) << describe(one);
    if (one.exit_code != 0) bad.insert(seed);
  }
  ASSERT_FALSE(bad.empty()) << "the grammar must fail for some seed of 1..8";
  ASSERT_LT(bad.size(), 8u) << "the grammar must succeed for some seed of 1..8";
  for (const std::string sub : {"export", "grow"}) {
    const std::string ext = sub == "export" ? ".glb" : ".skel.json";
    const std::string out = dir.file(sub + "/p_{seed}" + ext);
    ProcessResult r = run_sylva({sub, grammar, "--seed", "1..8", "-o", out});
    EXPECT_FALSE(crashed(r)) << describe(r);
    EXPECT_EQ(r.exit_code, 1) << describe(r);
    std::vector<std::string> written;
    for (int seed = 1; seed <= 8; ++seed) {
      const std::string file = dir.file(sub + "/p_" + std::to_string(seed) + ext);
      if (bad.count(seed)) {
        EXPECT_FALSE(fs::exists(file)) << file;
        EXPECT_NE(r.err.find("seed " + std::to_string(seed) + ": error: "), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("division by zero"), std::string::npos) << r.err;
      } else {
        EXPECT_TRUE(fs::exists(file)) << file << "\n" << r.err;
        written.push_back(file);
      }
    }
    EXPECT_EQ(list_dir(dir.path() / sub).size(), written.size());
    EXPECT_NE(r.err.find(std::to_string(bad.size()) + " failed: seed " + std::to_string(*bad.begin())), std::string::npos)
        << r.err;
    if (sub == "export") expect_valid(written);
  }
}

TEST(Batch, GrowSeedRangeGivesTheSameFilesAsOneSeedAtATime) {
  TempDir dir;
  expect_ok(run_sylva({"grow", kOtherPlant, "--seed=3..6", "-n", "3", "-o", dir.file("b/x_{seed}.skel.json")}));
  for (int seed = 3; seed <= 6; ++seed) {
    const std::string single = dir.file("single.skel.json");
    expect_ok(run_sylva({"grow", kOtherPlant, "--seed", std::to_string(seed), "-n", "3", "-o", single}));
    EXPECT_EQ(read_file(dir.file("b/x_" + std::to_string(seed) + ".skel.json")), read_file(single)) << seed;
  }
  // One seed with a pattern: the pattern is filled in.
  expect_ok(run_sylva({"grow", kOtherPlant, "--seed", "9", "-o", dir.file("x_{seed}.skel.json")}));
  EXPECT_TRUE(fs::exists(dir.file("x_9.skel.json")));
}

}  // namespace
