// paper_scenes_test.cpp — the paper's scenes in presets/scenes/ (Bhagvat et al. 2009, Table 1 and
// figs. 8–11; README "The paper's scenes"): each reads and grows, and holds the segments
// pinned here (a change to a grammar, the turtle or scatter that moves them must change
// this table and the README's together), close to the paper's count.
#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <string>

#include "core/scene/scene.h"
#include "core/grow/grow.h"
#include "core/scene/scene_json.h"

namespace sylva {
namespace {

struct PaperScene {
  const char* file;
  uint64_t plants;
  uint64_t segments;        // pinned: skeleton segments summed over the plants
  uint64_t paper_segments;  // Table 1
  double tolerance;         // relative distance from the paper's count allowed
};

void PrintTo(const PaperScene& p, std::ostream* os) { *os << p.file; }

class PaperScenes : public testing::TestWithParam<PaperScene> {};

TEST_P(PaperScenes, ReadsGrowsAndHoldsThePinnedSegmentsNearThePapers) {
  const PaperScene& p = GetParam();
  Expected<Scene> scene = read_scene_file(std::string(SYLVA_SOURCE_DIR) + "/presets/scenes/" + p.file);
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  ASSERT_TRUE(grow_scene_plants(*scene).ok());
  uint64_t segments = 0;
  for (const ScenePlant& plant : scene->plants) segments += plant.skeleton->segment_count();
  EXPECT_EQ(scene->plants.size(), p.plants);
  EXPECT_EQ(segments, p.segments);
  EXPECT_LE(std::abs(static_cast<double>(segments) - static_cast<double>(p.paper_segments)),
            p.tolerance * static_cast<double>(p.paper_segments))
      << segments << " segments against the paper's " << p.paper_segments;
}

INSTANTIATE_TEST_SUITE_P(Presets, PaperScenes,
                         testing::Values(PaperScene{"well.scene.json", 4, 8, 8, 0},
                                         PaperScene{"desert.scene.json", 34, 780, 799, 0.05},
                                         PaperScene{"oasis.scene.json", 16, 18569, 18557, 0.01},
                                         PaperScene{"dancing_cacti.scene.json", 100, 2195, 2158, 0.05}),
                         [](const testing::TestParamInfo<PaperScene>& info) {
                           std::string name = info.param.file;
                           name = name.substr(0, name.find('.'));
                           return name;
                         });

}  // namespace
}  // namespace sylva
