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

// presets/light/self_organizing.lsys: the light alone shapes the crown. Grown 12 steps in
// the default sun: every step answered, apices that fall below VMIN stop (so it grows
// fewer internodes than the 2^12 - 1 of a tree whose every apex grows), leaves fall in shade.
TEST(LightSelfOrganizing, TheLightAloneStopsApicesAndShedsLeaves) {
  auto g = lsys::load_grammar(std::string(SYLVA_SOURCE_DIR) + "/presets/light/self_organizing.lsys");
  ASSERT_TRUE(g) << g.error().format();
  lsys::DeriveOptions o;
  o.steps = 12;
  auto grown = grow(*g, o, "self_organizing.lsys", {}, {&cpu_light_oracle()});
  ASSERT_TRUE(grown) << grown.error().format();
  EXPECT_EQ(grown->light.answers, 13u);
  const uint64_t internodes = grown->skeleton.segment_count();
  EXPECT_GT(internodes, 200u);
  EXPECT_LT(internodes, 4095u) << "some apices stopped in shade";
  EXPECT_LT(grown->skeleton.leaves.size(), internodes) << "one leaf per internode, less those that fell";
  for (const GrowQuery& q : grown->queries) EXPECT_TRUE(q.q >= 0 && q.q <= 1);
}

}  // namespace
}  // namespace sylva
