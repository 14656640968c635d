// presets_test.cpp — the bundled plants, presets/*.lsys, pinned.
//
// Each preset is grown with `sylva grow` at its own default seed and steps, as a user
// would from the repository root, and its segment count must equal the number measured
// when the preset was made: any change to a preset, to the grammar engine or to the
// turtle that alters a plant shows up here, by name. If a change is meant to alter a
// plant, look at it (scripts/view_skeleton.py), then update the pinned number.
// The Bhagvat et al. 2009 plants must also stay within 15% of the segment counts of the paper's
// Table 1, and every preset must open with the comment block that says what it models,
// where it comes from and which knobs to turn. Polygon leaves (docs/spec/grammar.md `{ . }`) are
// not segments; their number in the skeleton is pinned beside the segments.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "core/geometry/skeleton.h"
#include "tests/support/process.h"

namespace {

namespace fs = std::filesystem;

struct Preset {
  const char* name;             // file stem under presets/
  uint64_t segments;            // pinned: measured at the preset's default seed and steps
  std::optional<double> paper;  // Bhagvat et al. 2009 Table 1 segment count, for the paper's plants
  uint64_t leaves = 0;          // pinned: polygon leaves in the skeleton
};

// Printed by gtest in failure messages and test names.
void PrintTo(const Preset& p, std::ostream* os) { *os << p.name; }

const Preset kPresets[] = {
    // ABOP classics (Prusinkiewicz & Lindenmayer 1990), typed from the book.
    {"abop_1_24a", 3125, std::nullopt},
    {"abop_1_24b", 3125, std::nullopt},
    {"abop_1_24c", 4096, std::nullopt},
    {"abop_1_24d", 4118, std::nullopt},
    {"abop_1_24e", 4118, std::nullopt},
    {"abop_1_24f", 992, std::nullopt},
    {"abop_1_25_bush", 7743, std::nullopt},
    {"abop_1_25_bush_leaves", 3891, std::nullopt, 1284},
    {"abop_1_27_stochastic", 885, std::nullopt},
    {"abop_1_31a_context", 2501, std::nullopt},
    {"abop_2_6_honda", 1023, std::nullopt},
    // Honda's tree in leaf: the book's branching, polygon leaves on its lateral axes.
    {"abop_2_6_honda_leaves", 1023, std::nullopt, 5098},
    {"abop_2_8_ternary", 1457, std::nullopt},
    // The plants of Bhagvat et al. 2009, modelled for sylva; Table 1 gives their segment counts.
    {"saguaro", 30, 30},
    {"aloe_vera", 229, 229, 912},  // a fat keel of frusta under four polygons a segment
    {"elm", 1769, 1833},           // leaves of frusta (the grove scenes' elm)
    {"elm_in_leaf", 1872, 1833, 10627},  // the wood is the segments; leaves are polygons
    {"coconut_palm", 3626, 3713, 8280},  // a frustum and three blades a leaflet, 92 leaflets a frond
    {"pine", 17468, 16997},        // needles of true size (the benchmarks' pine)
    {"pine_dense", 17509, 16997},  // needles drawn as tufts, twice the fascicles
    // A small cactus for the dancing-cacti scene (Bhagvat et al. 2009, Figure 8); its flower's
    // corolla and throat are polygons (2 x 10 petals of three pieces, and an octagon).
    {"cactus", 25, std::nullopt, 61},
    // The well of Bhagvat et al. 2009, Figure 10, one part per PART (presets/scenes/well.scene.json
    // holds all four: 8 segments, tests/grow/paper_scenes_test.cpp); PART 0 is the wall.
    {"well", 1, std::nullopt},
    // Synthetic topiary (Prusinkiewicz, James and Měch 1994): apices that query their
    // position (?P) and are cut outside a ball.
    {"topiary", 21576, std::nullopt, 33723},
    // A fir (Abies): Massart's model, whorls of flat sprays, needles drawn as tufts.
    {"fir", 20342, std::nullopt},
    // A Scots pine (Pinus sylvestris): Rauh's model, a high open crown of tufted limbs on a
    // clear bole, needles in pairs; the count depends on the seed (missing limbs, cones).
    {"scots_pine", 23090, std::nullopt},
};

fs::path presets_dir() { return fs::path(SYLVA_SOURCE_DIR) / "presets"; }

// The number before " segments" in grow's summary line, or nullopt.
std::optional<uint64_t> segments_in_summary(const std::string& out) {
  std::smatch m;
  static const std::regex kSegments(R"((\d+) segments\b)");
  if (!std::regex_search(out, m, kSegments)) return std::nullopt;
  return std::stoull(m[1].str());
}

// The paper's plants cite its authors as the README does (Bhagvat, Jeschke, Cline,
// Wonka 2009), and no preset names anyone else for it.
TEST(PresetSources, ThePapersPlantsCiteItsAuthors) {
  for (const Preset& p : kPresets) {
    const std::string text = read_file(presets_dir() / (std::string(p.name) + ".lsys"));
    EXPECT_EQ(text.find("Kinkelin"), std::string::npos) << p.name;
    if (p.paper) {
      EXPECT_NE(text.find("Bhagvat, Jeschke, Cline, Wonka 2009"), std::string::npos) << p.name;
    }
  }
}

class PresetTest : public ::testing::TestWithParam<Preset> {};

TEST_P(PresetTest, GrowsWithThePinnedSegmentCount) {
  const Preset& p = GetParam();
  TempDir dir;
  const std::string relative = "presets/" + std::string(p.name) + ".lsys";
  const std::string output = dir.file(std::string(p.name) + ".skel.json");

  ProcessResult r = run_sylva({"grow", relative, "-o", output}, SYLVA_SOURCE_DIR, 120);
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_TRUE(fs::exists(output) && fs::file_size(output) > 0) << output;

  std::optional<uint64_t> segments = segments_in_summary(r.out);
  ASSERT_TRUE(segments.has_value()) << "no segment count in grow's summary:\n" << r.out;
  EXPECT_EQ(*segments, p.segments)
      << relative << " changed: look at the plant, then update the pinned count.\n" << r.out;

  sylva::Expected<sylva::Skeleton> skeleton = sylva::read_skeleton_file(output);
  ASSERT_TRUE(skeleton.ok()) << skeleton.error().format();
  EXPECT_EQ(skeleton->leaves.size(), p.leaves) << relative << " changed its leaves: look at the plant, then update.";

  if (p.paper) {
    const double low = 0.85 * *p.paper, high = 1.15 * *p.paper;
    EXPECT_GE(static_cast<double>(*segments), low) << relative << " vs Table 1: " << *p.paper;
    EXPECT_LE(static_cast<double>(*segments), high) << relative << " vs Table 1: " << *p.paper;
  }
}

// A comment line: '#' that is not a directive (#define, #ignore), or a /* comment.
bool is_comment_line(const std::string& line) {
  size_t i = line.find_first_not_of(" \t");
  if (i == std::string::npos) return false;
  if (line.compare(i, 2, "/*") == 0) return true;
  if (line[i] != '#') return false;
  return line.compare(i, 7, "#define") != 0 && line.compare(i, 7, "#ignore") != 0;
}

TEST_P(PresetTest, OpensWithACommentBlockNamingSourceAndKnobs) {
  const Preset& p = GetParam();
  const fs::path path = presets_dir() / (std::string(p.name) + ".lsys");
  const std::string text = read_file(path);

  // The first line is a comment, and the block before the first directive or
  // production says where the plant comes from and lists its knobs.
  const std::string first_line = text.substr(0, text.find('\n'));
  EXPECT_TRUE(is_comment_line(first_line)) << path << " starts with: " << first_line;

  std::string block;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    if (!line.empty() && !is_comment_line(line)) break;
    block += line + "\n";
    start = end + 1;
  }
  EXPECT_NE(block.find("Source:"), std::string::npos) << path << ": no 'Source:' in\n" << block;
  EXPECT_NE(block.find("Knobs"), std::string::npos) << path << ": no 'Knobs' in\n" << block;
}

INSTANTIATE_TEST_SUITE_P(Bundled, PresetTest, ::testing::ValuesIn(kPresets),
                         [](const ::testing::TestParamInfo<Preset>& info) {
                           return std::string(info.param.name);
                         });

// presets/cpfg/*.l and *_object/: the book's grammars typed as cpfg model files and a vlab
// object (docs/cpfg.md). Each grows
// the skeleton of its .lsys twin joint for joint: an independent check of the cpfg path
// (preprocessor, '-->', statements, homomorphism depth 1, '!' widths) against sylva's own
// format. Positions and materials are equal; a radius may differ in its last bit (a cpfg
// width times 0.05 m, against a radius in metres).
TEST(CpfgPresets, EachGrowsTheSkeletonOfItsLsysTwinExactly) {
  const std::vector<std::string> names = list_dir(presets_dir() / "cpfg");
  ASSERT_FALSE(names.empty());
  size_t checked = 0;
  for (const std::string& name : names) {
    // NAME.l, or a vlab object folder NAME_object: the twin is presets/NAME.lsys.
    const bool object = fs::is_directory(presets_dir() / "cpfg" / name) && name.ends_with("_object");
    if (fs::path(name).extension() != ".l" && !object) continue;
    const std::string stem = object ? name.substr(0, name.size() - 7) : fs::path(name).stem().string();
    if (object && !fs::exists(presets_dir() / (stem + ".lsys"))) continue;  // no twin: its own test below
    ++checked;
    TempDir dir;
    std::optional<sylva::Skeleton> grown[2];
    const std::string sources[2] = {"presets/cpfg/" + name, "presets/" + stem + ".lsys"};
    for (int k = 0; k < 2; ++k) {
      const std::string output = dir.file(std::to_string(k) + ".skel.json");
      ProcessResult r = run_sylva({"grow", sources[k], "-o", output}, SYLVA_SOURCE_DIR, 120);
      ASSERT_EQ(r.exit_code, 0) << describe(r);
      EXPECT_EQ(r.err.find("warning"), std::string::npos) << describe(r);
      sylva::Expected<sylva::Skeleton> sk = sylva::read_skeleton_file(output);
      ASSERT_TRUE(sk.ok()) << sk.error().format();
      grown[k] = std::move(*sk);
    }
    ASSERT_EQ(grown[0]->chains.size(), grown[1]->chains.size()) << name;
    EXPECT_GT(grown[0]->joints.size(), 1000u) << name;
    EXPECT_TRUE(grown[0]->chains == grown[1]->chains) << name;
    ASSERT_EQ(grown[0]->joints.size(), grown[1]->joints.size()) << name;
    for (size_t j = 0; j < grown[0]->joints.size(); ++j) {
      const sylva::Joint &a = grown[0]->joints[j], &b = grown[1]->joints[j];
      for (int k = 0; k < 3; ++k) ASSERT_EQ(a.position_m[k], b.position_m[k]) << name << " joint " << j;
      ASSERT_EQ(a.material, b.material) << name << " joint " << j;
      ASSERT_NEAR(a.radius_m, b.radius_m, 1e-15 * b.radius_m) << name << " joint " << j;
    }
  }
  EXPECT_GE(checked, 3u);  // two model files and a vlab object
}

// presets/cpfg/rosette_object (docs/cpfg.md "A two-coloured rosette"): twelve leaves whose
// lengths it reads from leaves.txt with fscanf, each two-sided (dark green material 1 above,
// pale material 2 beneath: its view file's "initial color: 1 2" with its material file), and
// a flower of the view file's tsurface (ten triangles of material 3 on both sides).
TEST(CpfgPresets, TheRosetteObjectReadsItsLeafLengthsAndHasTwoSidedLeaves) {
  TempDir dir;
  const std::string output = dir.file("rosette.skel.json");
  ProcessResult r = run_sylva({"grow", "presets/cpfg/rosette_object", "-o", output}, SYLVA_SOURCE_DIR, 120);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  sylva::Expected<sylva::Skeleton> sk = sylva::read_skeleton_file(output);
  ASSERT_TRUE(sk.ok()) << sk.error().format();
  ASSERT_EQ(sk->leaves.size(), 12u + 10u);
  // leaves.txt's lengths: a leaf's outline is a rhombus of sides l/2 with a 40-degree tip,
  // so its length from base to tip is l·cos(20°).
  const double lengths[12] = {0.16, 0.17, 0.18, 0.185, 0.19, 0.185, 0.18, 0.17, 0.155, 0.14, 0.12, 0.10};
  for (size_t l = 0; l < 12; ++l) {
    const sylva::Leaf& leaf = sk->leaves[l];
    EXPECT_EQ(leaf.material, 1u) << l;
    ASSERT_TRUE(leaf.back_material) << l;
    EXPECT_EQ(*leaf.back_material, 2u) << l;
    ASSERT_EQ(leaf.vertices_m.size(), 4u) << l;
    double longest = 0;
    for (const auto& v : leaf.vertices_m)
      longest = std::max(longest, std::hypot(v[0] - leaf.vertices_m[0][0], v[1] - leaf.vertices_m[0][1],
                                             v[2] - leaf.vertices_m[0][2]));
    EXPECT_NEAR(longest, lengths[l] * std::cos(20 * 3.14159265358979323846 / 180), 1e-9) << l;
  }
  for (size_t l = 12; l < sk->leaves.size(); ++l) {
    EXPECT_EQ(sk->leaves[l].material, 3u);
    EXPECT_FALSE(sk->leaves[l].back_material) << "the flower's both sides are material 3";
    EXPECT_EQ(sk->leaves[l].vertices_m.size(), 3u);
  }
}

// A cpfg model file is a grammar for every command: render and export take it as they take
// a .lsys (lsys::is_grammar_path), -D included.
TEST(CpfgPresets, RenderAndExportTakeACpfgModelFile) {
  TempDir dir;
  const std::string png = dir.file("fig.png"), glb = dir.file("fig.glb");
  ProcessResult render = run_sylva({"render", "presets/cpfg/abop_1_24d.l", "-D", "N=3", "--width", "48", "--height",
                                    "32", "--backend", "cpu", "-o", png},
                                   SYLVA_SOURCE_DIR, 120);
  EXPECT_EQ(render.exit_code, 0) << describe(render);
  EXPECT_TRUE(fs::exists(png) && fs::file_size(png) > 0);
  ProcessResult exported = run_sylva({"export", "presets/cpfg/abop_1_24d.l", "-D", "N=3", "-o", glb}, SYLVA_SOURCE_DIR, 120);
  EXPECT_EQ(exported.exit_code, 0) << describe(exported);
  EXPECT_NE(exported.out.find("1 plant"), std::string::npos) << describe(exported);
}

// A preset added to presets/ without a pinned count would go untested.
TEST(Presets, EveryPresetFileIsPinned) {
  std::vector<std::string> pinned;
  for (const Preset& p : kPresets) pinned.push_back(std::string(p.name) + ".lsys");
  for (const std::string& name : list_dir(presets_dir())) {
    if (fs::path(name).extension() != ".lsys") continue;
    EXPECT_NE(std::find(pinned.begin(), pinned.end(), name), pinned.end())
        << "presets/" << name << " has no pinned segment count in presets_test.cpp";
  }
  for (const std::string& name : pinned)
    EXPECT_TRUE(fs::exists(presets_dir() / name)) << "presets/" << name << " is missing";
}

}  // namespace
