// grow_scene_test.cpp — a scene's plants grown from their grammars (core/grow/grow.h
// grow_scene_plants): errors at the grammar with a note at the scene key, progress and
// cancellation, each recipe derived once, the seed left out of a grammar without randomness.
#include "core/scene/scene.h"
#include "core/grow/grow.h"
#include "core/scene/materials.h"
#include <gtest/gtest.h>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/geometric.hpp>
#include <random>
#include <set>
#include "core/scene/instances.h"
#include "core/scene/scene_json.h"
#include "tests/support/test_textures.h"

namespace sylva {
namespace {

const std::string kCactusGrammar = std::string(SYLVA_SOURCE_DIR) + "/presets/cactus.lsys";

// A scene of `entry` alone in its scatter list (scene_test.cpp's SceneScatterKey helpers).
Expected<Scene> scene_with_scatter(const std::string& entry) {
  return parse_scene_json(R"({"ground": {"height": -0.5}, "plants": [], "scatter": [)" + entry + "]}", "s.scene.json",
                          "");
}

std::string cactus_entry(const std::string& rest) {
  return R"({"grammar": ")" + kCactusGrammar + R"(", )" + rest + "}";
}

TEST(SceneGrow, AGrammarErrorIsTheGrammarsDiagnosticWithANoteAtTheSceneKey) {
  test::TempFolder dir;
  std::ofstream(dir.file("bad.lsys")) << "axiom: A\nA -> F(foo(2))\n";
  const std::string scene_text =
      "{\"plants\": [\n  {\"grammar\": \"" + std::string(SYLVA_SOURCE_DIR) + "/presets/saguaro.lsys\"},\n"
      "  {\"seed\": 2, \"grammar\": \"bad.lsys\"}\n]}";
  Expected<Scene> scene = parse_scene_json(scene_text, dir.file("forest.scene.json"), dir.path());
  ASSERT_TRUE(scene.ok()) << scene.error().format();
  EXPECT_EQ(scene->plants[1].grammar_loc, (SourceLoc{3, 26}));
  const Status grown = grow_scene_plants(*scene);
  ASSERT_FALSE(grown.ok());
  const Diagnostic& d = grown.error();
  EXPECT_EQ(d.file, dir.file("bad.lsys"));  // the grammar's own file and place
  EXPECT_EQ(d.loc, (SourceLoc{2, 8}));
  EXPECT_EQ(d.source_line, "A -> F(foo(2))");
  ASSERT_EQ(d.notes.size(), 1u);
  EXPECT_EQ(d.notes[0].file, dir.file("forest.scene.json"));  // and where the scene named it
  EXPECT_EQ(d.notes[0].loc, (SourceLoc{3, 26}));
  EXPECT_EQ(d.notes[0].message, "plants[1].grammar names this grammar");
  EXPECT_EQ(d.format(), dir.file("bad.lsys") + ":2:8: error: unknown function 'foo'\nA -> F(foo(2))\n       ^\n" +
                            dir.file("forest.scene.json") + ":3:26: note: plants[1].grammar names this grammar\n");
  EXPECT_TRUE(scene->plants[0].skeleton.has_value());  // the plant before it grew
}

TEST(SceneGrow, AnUnreadableGrammarIsAnErrorAtTheSceneKeyWithTheFilesAsANote) {
  Expected<Scene> scene = parse_scene_json(R"({"plants": [{"grammar": "no/such.lsys"}]})", "s.scene.json", "");
  ASSERT_TRUE(scene.ok());
  const Status grown = grow_scene_plants(*scene);
  ASSERT_FALSE(grown.ok());
  // What to change is the scene's key: the error there, the file's own as a note.
  EXPECT_EQ(grown.error().file, "s.scene.json");
  EXPECT_EQ(grown.error().loc, (SourceLoc{1, 25}));
  EXPECT_EQ(grown.error().message.rfind("plants[0].grammar 'no/such.lsys': ", 0), 0u) << grown.error().message;
  EXPECT_EQ(grown.error().error_number, ENOENT);
  ASSERT_EQ(grown.error().notes.size(), 1u);
  EXPECT_EQ(grown.error().notes[0].file, "no/such.lsys");
  EXPECT_EQ(grown.error().notes[0].loc, SourceLoc{});
}

TEST(SceneGrow, ADefineTheGrammarLacksIsAnErrorAtTheSceneKey) {
  const std::string saguaro = std::string(SYLVA_SOURCE_DIR) + "/presets/saguaro.lsys";
  Expected<Scene> scene =
      parse_scene_json(R"({"plants": [{"grammar": ")" + saguaro + R"(", "defines": {"NO_SUCH": 2}}]})", "s.scene.json", "");
  ASSERT_TRUE(scene.ok());
  const Status grown = grow_scene_plants(*scene);
  ASSERT_FALSE(grown.ok());
  EXPECT_EQ(grown.error().file, "s.scene.json");
  EXPECT_EQ(grown.error().loc, (SourceLoc{1, 25}));
  EXPECT_NE(grown.error().message.find("its defines name NO_SUCH: the grammar has no '#define NO_SUCH'"),
            std::string::npos)
      << grown.error().format();
  ASSERT_EQ(grown.error().notes.size(), 1u);
  EXPECT_EQ(grown.error().notes[0].file, saguaro);
}

TEST(SceneGrow, AFileThatIsNotAGrammarIsNeverQuoted) {
  // A scene naming any readable file (/etc/passwd) as its grammar: the error names the
  // file and says it is not a grammar, and prints nothing of what it holds.
  test::TempFolder dir;
  std::ofstream(dir.file("secrets.txt")) << "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1\n";
  Expected<Scene> scene = parse_scene_json(R"({"plants": [{"grammar": "secrets.txt"}]})",
                                           dir.file("s.scene.json"), dir.path());
  ASSERT_TRUE(scene.ok()) << scene.error().format();
  const Status grown = grow_scene_plants(*scene);
  ASSERT_FALSE(grown.ok());
  const std::string text = grown.error().format();
  EXPECT_EQ(text.find("root"), std::string::npos) << text;
  EXPECT_EQ(text.find("daemon"), std::string::npos) << text;
  EXPECT_NE(text.find("which is not a grammar (a .lsys file): its line 1 is not L-system text"), std::string::npos)
      << text;
  EXPECT_EQ(grown.error().file, dir.file("s.scene.json"));
  EXPECT_TRUE(grown.error().notes.empty());
  EXPECT_FALSE(grown.error().source_line.has_value());
}

TEST(SceneGrow, ReportsProgressPerPlantAndStopsWhenCancelled) {
  Scene scene;
  for (int i = 0; i < 3; ++i) {
    ScenePlant plant;
    plant.grammar = std::string(SYLVA_SOURCE_DIR) + "/presets/saguaro.lsys";
    plant.seed = static_cast<uint64_t>(i);
    scene.plants.push_back(plant);
  }
  std::vector<double> fractions;
  std::atomic<bool> cancel{false};
  Scene copy = scene;
  ASSERT_TRUE(grow_scene_plants(copy, 50'000'000, Progress([&](double f, std::string_view) { fractions.push_back(f); }))
                  .ok());
  ASSERT_FALSE(fractions.empty());
  for (size_t i = 1; i < fractions.size(); ++i) EXPECT_LE(fractions[i - 1], fractions[i]);
  EXPECT_EQ(fractions.back(), 1.0);
  // Cancelled once the first plant is done: the rest stay ungrown, the result says so.
  const Status stopped = grow_scene_plants(scene, 50'000'000, Progress([&](double f, std::string_view) {
    if (f >= 1.0 / 3) cancel.store(true);
  }, &cancel));
  EXPECT_TRUE(stopped.cancelled());
  EXPECT_TRUE(stopped.error().notes.empty());
  EXPECT_TRUE(scene.plants[0].skeleton.has_value());
  EXPECT_FALSE(scene.plants[2].skeleton.has_value());
}

TEST(SceneScatterKey, InstancesOfOneRecipeGrowOnceAndAGrammarErrorNamesTheEntry) {
  auto s = scene_with_scatter(cactus_entry(R"("count": 50, "disc": {"radius": 20}, "plant_seeds": [5, 6])"));
  ASSERT_TRUE(s) << s.error().format();
  ASSERT_TRUE(grow_scene_plants(*s));
  Scene single;
  ScenePlant five;
  five.grammar = kCactusGrammar;
  five.seed = 5;
  single.plants = {five};
  ASSERT_TRUE(grow_scene_plants(single));
  size_t fives = 0;
  for (const ScenePlant& p : s->plants) {
    ASSERT_TRUE(p.skeleton);
    if (*p.seed == 5) {
      ++fives;
      EXPECT_EQ(*p.skeleton, *single.plants.front().skeleton);  // the same plant as grown alone
    }
  }
  EXPECT_GT(fives, 10u);
  // A broken grammar: its own error, with a note at the entry that names it.
  test::TempFolder dir;
  {
    std::ofstream(dir.file("bad.lsys")) << "axiom: F\np1: F -> F[\n";
  }
  auto bad = parse_scene_json(R"({"plants": [], "scatter": [{"grammar": ")" + dir.file("bad.lsys") +
                                  R"(", "count": 3, "disc": {"radius": 5}}]})",
                              "b.scene.json", "");
  ASSERT_TRUE(bad) << bad.error().format();
  Status grown = grow_scene_plants(*bad);
  ASSERT_FALSE(grown);
  ASSERT_EQ(grown.error().notes.size(), 1u) << grown.error().format();
  EXPECT_NE(grown.error().notes[0].message.find("scatter[0].grammar names this grammar"), std::string::npos);
  EXPECT_EQ(grown.error().notes[0].file, "b.scene.json");
}

// Four plants of `grammar_text` with seeds 1, 2, 3 and the grammar's own, grown.
Scene four_seeds(const test::TempFolder& dir, const std::string& grammar_text) {
  std::ofstream(dir.file("g.lsys")) << grammar_text;
  Scene s;
  for (int k = 0; k < 4; ++k) {
    ScenePlant p;
    p.grammar = dir.file("g.lsys");
    if (k < 3) p.seed = static_cast<uint64_t>(k + 1);
    p.position = {2.0 * k, 0, 0};
    s.plants.push_back(p);
  }
  EXPECT_TRUE(grow_scene_plants(s).ok());
  return s;
}

TEST(PlantInstances, AGrammarWithoutRandomnessGrowsOneShapeFromEverySeedAndSharesIt) {
  test::TempFolder dir;
  const Scene s = four_seeds(dir, "seed: 9\naxiom: !(0.1)F(1)[+F(0.5)][-F(0.5)]F(0.8)\n");
  for (uint32_t p = 0; p < 4; ++p) {
    ASSERT_TRUE(s.plants[p].skeleton.has_value());
    EXPECT_EQ(s.plants[p].skeleton->joints, s.plants[0].skeleton->joints) << "plant " << p;
  }
  // Each keeps its own seed in its source (the grammar's `seed:` where it has none).
  EXPECT_EQ(s.plants[0].skeleton->source.seed, 1u);
  EXPECT_EQ(s.plants[2].skeleton->source.seed, 3u);
  EXPECT_EQ(s.plants[3].skeleton->source.seed, 9u);
  const PlantInstances g = plant_instances(s);
  EXPECT_EQ(g.distinct(), 1u);
}

TEST(PlantInstances, AGrammarThatDrawsRandomNumbersGrowsAShapePerSeed) {
  test::TempFolder dir;
  const Scene s = four_seeds(dir, "seed: 9\naxiom: !(0.1)A\nA -> F(uniform(0.5, 1.5))[+F(0.5)]F(0.8)\n");
  EXPECT_NE(s.plants[0].skeleton->joints, s.plants[1].skeleton->joints);
  EXPECT_EQ(s.plants[1].skeleton->source.seed, 2u);
  EXPECT_EQ(s.plants[3].skeleton->source.seed, 9u);
  const PlantInstances g = plant_instances(s);
  EXPECT_EQ(g.distinct(), 4u);
}

}  // namespace
}  // namespace sylva
