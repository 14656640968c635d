// Tests for growing in light (docs/spec/light.md, core/grow/grow.h): `?E` answered after the
// axiom and after every step, the answers read through context in the next step, nothing
// traced for a grammar without queries, plants of a scene answered together, `@Tp`, and
// the arity errors. The oracle here is a stand-in whose answers are closed forms of the
// sensor's position, so every expected word is worked out by hand; the photon oracle
// itself is tested in tests/cpu/light_tracer_test.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/grow/grow.h"

namespace sylva {
namespace {

// q = y / 10 at the sensor, the light from +x; counts its calls and the sensors of each.
class HeightLight final : public LightOracle {
 public:
  Expected<std::vector<LightAnswer>> answer(std::span<const Skeleton> plants, std::span<const glm::dvec3> sensors,
                                            const Scene&, int64_t step, LightAnswerStats*) const override {
    ++calls;
    steps.push_back(step);
    sensor_counts.push_back(sensors.size());
    plant_counts.push_back(plants.size());
    std::vector<LightAnswer> out;
    for (const glm::dvec3& p : sensors) out.push_back({p.y / 10, {1, 0, 0}, 0});
    return out;
  }
  mutable int calls = 0;
  mutable std::vector<int64_t> steps;
  mutable std::vector<size_t> sensor_counts, plant_counts;
};

lsys::Grammar parsed(const std::string& text) {
  auto g = lsys::parse_grammar(text, "light.lsys");
  if (!g) ADD_FAILURE() << g.error().format();
  return g ? std::move(*g) : lsys::Grammar{};
}

std::string derived(const lsys::Grammar& g, const LightOracle* oracle, int64_t steps) {
  lsys::DeriveOptions o;
  o.steps = steps;
  auto w = derive_word(g, o, {oracle});
  if (!w) return "error: " + w.error().message;
  return lsys::print_word(*w, g.symbols);
}

TEST(LightGrowth, QueriesAreAnsweredAfterEveryStepAndReadThroughContext) {
  // The apex grows while the light at its query is below 0.25: q is 0 on the axiom's
  // turtle position... then 0.1, 0.2, 0.3 as it climbs one metre a step; at 0.3 it stops.
  const lsys::Grammar g = parsed(
      "module: A\n"
      "axiom: A ?E(0)\n"
      "A > ?E(q) : q < 0.25 -> F(1) A\n");
  HeightLight light;
  EXPECT_EQ(derived(g, &light, 5), "F(1)F(1)F(1)A?E(0.3)");
  EXPECT_EQ(light.calls, 6);  // the axiom and five steps
  EXPECT_EQ(light.steps, (std::vector<int64_t>{0, 1, 2, 3, 4, 5}));
  // The four-parameter query receives the direction the light comes from.
  const lsys::Grammar g4 = parsed("module: A\naxiom: A ?E(0, 0, 0, 0)\nA -> F(1) A\n");
  EXPECT_EQ(derived(g4, &light, 2), "F(1)F(1)A?E(0.2,1,0,0)");
}

TEST(LightGrowth, ACpfgFilesQueriesAreAnsweredTheSameWay) {
  const lsys::Grammar g = parsed("Lsystem: 1\nderivation length: 2\nAxiom: A ?E(0)\nA --> F(1) A\nendlsystem\n");
  HeightLight light;
  EXPECT_EQ(derived(g, &light, 2), "F(1)F(1)A?E(0.2)");
}

TEST(LightGrowth, EveryNthStepAnswersOnlyThen) {
  const lsys::Grammar g = parsed("module: A\naxiom: A ?E(0)\nA -> F(1) A\n");
  HeightLight light;
  Scene scene;
  LightEnvironment e;
  e.every = 2;
  scene.environment = e;
  lsys::DeriveOptions o;
  o.steps = 3;
  auto w = derive_word(g, o, {&light, &scene});
  ASSERT_TRUE(w);
  // Answered at steps 0 and 2: the query keeps step 2's answer through step 3.
  EXPECT_EQ(lsys::print_word(*w, g.symbols), "F(1)F(1)F(1)A?E(0.2)");
  EXPECT_EQ(light.steps, (std::vector<int64_t>{0, 2}));
}

TEST(LightGrowth, AGrammarWithoutQueriesTracesNothing) {
  const lsys::Grammar g = parsed("module: A\naxiom: A\nA -> F(1) [+A] A\n");
  EXPECT_FALSE(grammar_queries_light(g));
  HeightLight light;
  lsys::DeriveOptions o;
  o.steps = 4;
  auto grown = grow(g, o, "light.lsys", {}, {&light});
  ASSERT_TRUE(grown);
  EXPECT_EQ(light.calls, 0);
  EXPECT_EQ(grown->light.answers, 0u);
}

TEST(LightGrowth, AGrammarWithQueriesAndNoLightIsAnError) {
  const lsys::Grammar g = parsed("module: A\naxiom: A ?E(1)\nA -> F A\n");
  EXPECT_TRUE(grammar_queries_light(g));
  const std::string text = derived(g, nullptr, 2);
  EXPECT_NE(text.find("asks for light (?E)"), std::string::npos) << text;
}

TEST(LightGrowth, TheSkeletonGrowsWhereTheAnswersLetIt) {
  const lsys::Grammar g = parsed(
      "module: A\n"
      "axiom: A ?E(0)\n"
      "A > ?E(q) : q < 0.25 -> F(1) A\n");
  HeightLight light;
  lsys::DeriveOptions o;
  o.steps = 8;
  auto grown = grow(g, o, "light.lsys", {}, {&light});
  ASSERT_TRUE(grown) << grown.error().format();
  EXPECT_EQ(grown->skeleton.segment_count(), 3u);  // stopped at 3 m
  EXPECT_EQ(grown->light.answers, 9u);
  EXPECT_EQ(grown->light.queries, 9u);
  // The last answer and where it was asked: the apex at 3 m, q = 0.3.
  ASSERT_EQ(grown->queries.size(), 1u);
  EXPECT_EQ(grown->queries[0].position, glm::dvec3(0, 3, 0));
  EXPECT_DOUBLE_EQ(grown->queries[0].q, 0.3);
}

TEST(LightGrowth, AScenesPlantsAreAnsweredTogether) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sylva_light_growth_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "apex.lsys").string();
  std::ofstream(path) << "module: A\naxiom: A ?E(0)\nA > ?E(q) : q < 0.25 -> F(1) A\nderivation length: 6\n";
  Scene scene;
  for (double x : {0.0, 5.0}) {
    ScenePlant p;
    p.grammar = path;
    p.position = {x, x / 5, 0};  // the second stands 1 m higher: it sees 0.1 more light
    scene.plants.push_back(p);
  }
  HeightLight light;
  ASSERT_TRUE(grow_scene_plants(scene, 1'000'000, {}, &light));
  // Every answer holds both plants' queries (lockstep), and both plants as obstacles.
  EXPECT_EQ(light.calls, 7);
  for (size_t n : light.sensor_counts) EXPECT_EQ(n, 2u);
  for (size_t n : light.plant_counts) EXPECT_EQ(n, 2u);
  // In the world, the higher plant's apex reaches 0.25 one metre sooner.
  EXPECT_EQ(scene.plants[0].skeleton->segment_count(), 3u);
  EXPECT_EQ(scene.plants[1].skeleton->segment_count(), 2u);
  std::filesystem::remove_all(dir);
}

TEST(LightGrowth, TropismVectorBendsTowardIt) {
  // With susceptibility 0.5 and T = +x from @Tp, each F turns the heading toward +x.
  const lsys::Grammar g = parsed("tropism: 0 -1 0 0.5\naxiom: @Tp(1, 0, 0) F F F\n");
  HeightLight light;
  auto grown = grow(g, {}, "light.lsys", {}, {&light});
  ASSERT_TRUE(grown) << grown.error().format();
  const auto& j = grown->skeleton.joints;
  ASSERT_EQ(j.size(), 4u);
  EXPECT_GT(j[3].position_m[0], 0.5);  // toward +x, not down toward the header's −y
  EXPECT_EQ(light.calls, 0);
}

TEST(LightGrowth, QueriesAndTropismVectorsWithOtherArityAreErrorsAtTheirPlace) {
  for (const char* text : {"axiom: A ?E(1, 2)\n", "axiom: A ?E\n", "axiom: F @Tp(1)\n", "A < ?E(a, b) -> F\naxiom: A\n"}) {
    auto g = lsys::parse_grammar(text, "bad.lsys");
    ASSERT_FALSE(g) << text;
    EXPECT_EQ(g.error().loc.line, 1) << text;
    EXPECT_TRUE(g.error().message.find("?E takes") != std::string::npos ||
                g.error().message.find("@Tp takes") != std::string::npos)
        << g.error().message;
  }
}

}  // namespace
}  // namespace sylva
