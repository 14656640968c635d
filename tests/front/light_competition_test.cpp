// presets/light/competition.lsys in the light (docs/light.md): what issue 28 asks a botanist
// to see, measured on the skeletons — grown beside a neighbour the crown leans away from
// it, and in a stand the shaded lower branches are shed (the lowest leaf rises) and the
// trees keep fewer leaves. Grown with the front ends' photon oracle (app/front/light.h),
// 10 steps and 300,000 photons an answer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/vec3.hpp>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "app/front/light.h"
#include "core/grow/grow.h"
#include "core/scene/scene_json.h"

namespace sylva {
namespace {

Scene competition(const std::vector<double>& xs) {
  Scene s;
  s.sun.direction = unit_sun_direction({0.0, 1.0, 0.0});
  LightEnvironment e;
  e.sky = LightSky::sun_overcast;
  e.sun_fraction = 0.5;
  e.photons = 300'000;
  s.environment = e;
  for (double x : xs) {
    ScenePlant p;
    p.grammar = std::string(SYLVA_SOURCE_DIR) + "/presets/light/competition.lsys";
    p.steps = 10;
    p.position = {x, 0, 0};
    s.plants.push_back(p);
  }
  Status grown = grow_scene_plants(s, 10'000'000, {}, &cpu_light_oracle());
  if (!grown) ADD_FAILURE() << grown.error().format();
  return s;
}

struct Crown {
  double centroid_x = 0;  // mean x of the leaves' vertices, relative to the trunk
  double lowest_leaf = std::numeric_limits<double>::infinity();
  size_t leaves = 0;
};

Crown crown_of(const ScenePlant& p) {
  Crown c;
  double sum = 0;
  size_t n = 0;
  for (const Leaf& leaf : p.skeleton->leaves)
    for (const auto& v : leaf.vertices_m) sum += v[0], ++n, c.lowest_leaf = std::min(c.lowest_leaf, v[1]);
  c.centroid_x = n ? sum / static_cast<double>(n) : 0;
  c.leaves = p.skeleton->leaves.size();
  return c;
}

TEST(LightCompetition, ACrownLeansAwayFromItsNeighbourAndAStandShedsItsLowerBranches) {
  const Scene alone = competition({0});
  const Scene pair = competition({-1.2, 1.2});
  const Scene stand = competition({-2.4, -1.2, 0, 1.2, 2.4});
  const Crown a = crown_of(alone.plants[0]);
  const Crown left = crown_of(pair.plants[0]), right = crown_of(pair.plants[1]);
  const Crown middle = crown_of(stand.plants[2]);
  ASSERT_GT(a.leaves, 50u);
  // The pair's crowns lean apart: the left one's leaves lie to the left of the lone
  // tree's, the right one's to the right (measured at this seed: 6 and 10 cm).
  EXPECT_LT(left.centroid_x, a.centroid_x - 0.03) << left.centroid_x << " vs alone " << a.centroid_x;
  EXPECT_GT(right.centroid_x, a.centroid_x + 0.03) << right.centroid_x << " vs alone " << a.centroid_x;
  EXPECT_GT(right.centroid_x - left.centroid_x, 0.1);
  // Crowding costs leaves, and the middle of a stand loses its lowest ones.
  EXPECT_LT(left.leaves, a.leaves);
  EXPECT_LT(middle.leaves, left.leaves);
  EXPECT_GT(middle.lowest_leaf, a.lowest_leaf + 0.3) << middle.lowest_leaf << " vs alone " << a.lowest_leaf;
  std::printf("alone: %zu leaves, lowest %.2f m, centroid %.3f; pair: %zu/%zu leaves, centroids %.3f/%.3f; "
              "stand middle: %zu leaves, lowest %.2f m\n",
              a.leaves, a.lowest_leaf, a.centroid_x, left.leaves, right.leaves, left.centroid_x, right.centroid_x,
              middle.leaves, middle.lowest_leaf);
}

// presets/scenes/sapling_gap.scene.json: under a canopy with one gap (centred at x = 2.25,
// z = 0, 4 m up) the sapling's tip moves toward the gap; in the open it grows straight up.
TEST(LightSapling, UnderACanopyItGrowsTowardTheGap) {
  auto read = read_scene_file(std::string(SYLVA_SOURCE_DIR) + "/presets/scenes/sapling_gap.scene.json");
  ASSERT_TRUE(read) << read.error().format();
  Scene open = *read;
  open.plants.erase(open.plants.begin());  // the sapling alone, in the same sky
  for (Scene* s : {&*read, &open}) {
    Status grown = grow_scene_plants(*s, 1'000'000, {}, &cpu_light_oracle());
    ASSERT_TRUE(grown) << grown.error().format();
  }
  auto tip = [](const Scene& s) {
    const Joint& j = s.plants.back().skeleton->joints.back();
    return glm::dvec3(j.position_m[0], j.position_m[1], j.position_m[2]);
  };
  const glm::dvec3 under = tip(*read), alone = tip(open);
  std::printf("sapling tip under the gap (%.2f, %.2f, %.2f), in the open (%.2f, %.2f, %.2f)\n", under.x, under.y,
              under.z, alone.x, alone.y, alone.z);
  EXPECT_GT(under.x, 0.6) << "toward the gap";
  EXPECT_LT(std::abs(under.z), 0.3);
  EXPECT_LT(std::hypot(alone.x, alone.z), 0.3) << "the open overcast sky is the same all around";
}

// presets/light/self_organizing.lsys: the light alone shapes the crown, its vigour allocated
// by the extended Borchert–Honda model (Pałubicki et al. 2009) in two passes a step
// (docs/grammar-notes.md "Passes"). Grown 12 steps in the default sun, the word is read
// back: every fork's light is the sum of its children's (the backward pass), every fork's
// vigour is split between them exactly by LAMBDA and their light (the forward pass), the
// root's vigour is ALPHA times the light the whole tree gathers, and the lower crown sheds.
TEST(LightSelfOrganizing, VigourIsAllocatedByBorchertHondaFromTheLightGatheredAlongWholeBranches) {
  auto g = lsys::load_grammar(std::string(SYLVA_SOURCE_DIR) + "/presets/light/self_organizing.lsys");
  ASSERT_TRUE(g) << g.error().format();
  auto define = [&](const char* name) {
    for (const lsys::Define& d : g->defines)
      if (d.name == name) return d.value;
    ADD_FAILURE() << "no #define " << name;
    return 0.0;
  };
  const double lambda = define("LAMBDA"), alpha = define("ALPHA");
  lsys::DeriveOptions o;
  o.steps = 12;
  LightGrowthStats stats;
  auto word = derive_word(*g, o, {&cpu_light_oracle()}, &stats);
  ASSERT_TRUE(word) << word.error().format();
  EXPECT_EQ(stats.answers, 13u) << "one answer a step, whatever its passes";

  // The nodes N(k, a, Q, M, L, v, r, c) and, for each internode, its lateral and main child.
  lsys::SymbolId n_id = 0, turn = 0, roll = 0;
  ASSERT_TRUE(g->symbols.find("N", &n_id));
  turn = lsys::kSymPitchDown;
  roll = lsys::kSymRollRight;
  const lsys::Word& w = *word;
  auto skip = [&](size_t j) {  // the ignore list: & / @Tp
    while (j < w.size() && (w.modules[j].symbol == turn || w.modules[j].symbol == roll ||
                            w.modules[j].symbol == lsys::kSymTropismVector))
      ++j;
    return j;
  };
  auto node = [&](size_t j) { return w.params_of(w.modules[j]); };
  std::vector<size_t> close(w.size(), 0), open;
  for (size_t j = 0; j < w.size(); ++j) {
    if (w.modules[j].symbol == lsys::kSymPush) open.push_back(j);
    if (w.modules[j].symbol == lsys::kSymPop) {
      close[open.back()] = j;
      open.pop_back();
    }
  }
  ASSERT_GE(w.size(), 2u);
  ASSERT_EQ(w.modules[0].symbol, n_id);
  const double* root = node(0);
  ASSERT_EQ(root[0], 3);
  EXPECT_NEAR(root[5], alpha * root[2], 1e-9 * root[5]) << "the root's vigour: ALPHA times the tree's light";
  size_t forks = 0, stubs = 0, buds = 0;
  for (size_t i = 0; i < w.size(); ++i) {
    if (w.modules[i].symbol != n_id) continue;
    const double* p = node(i);
    if (p[0] == 2) ++stubs;
    if (p[0] == 1) ++buds;
    if (p[0] != 0 || p[3] + p[4] == 0) continue;  // an internode grown this step: its children wait a step
    const size_t bracket = skip(i + 1);
    ASSERT_EQ(w.modules[bracket].symbol, lsys::kSymPush) << "an internode is followed by its lateral";
    const size_t lat_at = skip(bracket + 1), main_at = skip(close[bracket] + 1);
    ASSERT_EQ(w.modules[lat_at].symbol, n_id);
    ASSERT_EQ(w.modules[main_at].symbol, n_id);
    const double *lat = node(lat_at), *main = node(main_at);
    if (lat[0] == 2) continue;  // shed this step: its share went with it
    ++forks;
    EXPECT_NEAR(p[2], p[3] + p[4], 1e-9 * p[2]) << "Q is the sum of the children's";
    EXPECT_NEAR(p[3], main[2], 1e-9 * p[3]) << "M is the main child's light";
    EXPECT_NEAR(p[4], lat[2], 1e-9 * (p[4] + 1e-12)) << "L is the lateral's light";
    const double weights = lambda * p[3] + (1 - lambda) * p[4] + 1e-12;
    EXPECT_NEAR(main[5], p[5] * lambda * p[3] / weights, 1e-9 * p[5]) << "the main child's share";
    EXPECT_NEAR(lat[5], p[5] * (1 - lambda) * p[4] / weights, 1e-9 * p[5]) << "the lateral's share";
  }
  std::printf("%zu forks checked, %zu buds, %zu shed stubs, %zu modules\n", forks, buds, stubs, w.size());
  EXPECT_GT(forks, 100u);
  EXPECT_GT(stubs, 10u) << "the shaded lower crown is shed";
  size_t answered = 0;
  for (const lsys::Module& m : w.modules)
    if (m.symbol == lsys::kSymLightQuery) {
      const double q = w.params_of(m)[0];
      EXPECT_TRUE(q >= 0 && q <= 1) << q;
      answered += q < 1;
    }
  EXPECT_GT(answered, buds / 2) << "most buds are shaded a little";
}

}  // namespace
}  // namespace sylva
