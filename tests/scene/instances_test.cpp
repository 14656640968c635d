// instances_test.cpp — which plants share a skeleton (core/scene/instances.h) and the transform
// each is drawn through, which must put a skeleton's point where place_plant puts it.
#include <gtest/gtest.h>

#include "core/scene/instances.h"
#include "tests/support/test_scenes.h"
#include "tests/support/test_textures.h"

namespace sylva {
namespace {

TEST(PlantInstances, PlantsWithEqualSkeletonsShareAPrototypeAndOthersDoNot) {
  const Scene s = test::instanced_grove();
  const PlantInstances g = plant_instances(s);
  ASSERT_EQ(g.prototype_of_plant.size(), 13u);
  EXPECT_EQ(g.distinct(), 3u);  // the fork, the cylinder, the crooked stem
  EXPECT_EQ(g.prototypes[g.prototype_of_plant[0]], 0u);  // the first plant of each is its prototype
  for (uint32_t p = 0; p < 13; ++p) {
    const uint32_t k = g.prototype_of_plant[p];
    EXPECT_EQ(*s.plants[g.prototypes[k]].skeleton, *s.plants[p].skeleton) << "plant " << p;
  }
  EXPECT_NE(g.prototype_of_plant[0], g.prototype_of_plant[1]);
  EXPECT_EQ(g.prototype_of_plant[0], g.prototype_of_plant[2]);
}

TEST(PlantInstances, AnAnimatedPlantOfTheSameRecipeIsNotMerged) {
  // The same recipe, a skeleton changed (an animation's pose): compared, not assumed.
  Scene s = test::instanced_grove();
  for (ScenePlant& p : s.plants) p.grammar = "fork.lsys", p.seed = 1;
  s.plants[2].skeleton->joints[1].position_m[0] += 0.01;
  const PlantInstances g = plant_instances(s);
  EXPECT_EQ(g.distinct(), 4u);
  EXPECT_NE(g.prototype_of_plant[0], g.prototype_of_plant[2]);
}

TEST(PlantInstances, APlantOfAnotherSkinIsNotMerged) {
  // The same skeleton skinned paper and smooth gives other frusta: not one prototype.
  Scene s = test::instanced_grove();
  s.plants[2].skin = SkinStyle::paper;
  const PlantInstances g = plant_instances(s);
  EXPECT_EQ(g.distinct(), 4u);
  EXPECT_NE(g.prototype_of_plant[0], g.prototype_of_plant[2]);
}

TEST(PlantTransform, TakesASkeletonsPointWherePlacePlantPutsItAndBack) {
  ScenePlant plant;
  plant.skeleton = test::cylinder(0.1, 0, 2);
  plant.skeleton->joints[1].position_m[0] = 0.3;
  plant.skeleton->joints[1].position_m[2] = -0.7;
  plant.position = {12.5, 0.25, -40};
  plant.rotate_y_deg = 71;
  plant.scale = 1.3;
  const Skeleton placed = place_plant(plant);
  const PlantTransform t = PlantTransform::of(plant);
  const auto& local = plant.skeleton->joints[1].position_m;
  const glm::dvec3 world = t.to_world({local[0], local[1], local[2]});
  for (int k = 0; k < 3; ++k) EXPECT_EQ(world[k], placed.joints[1].position_m[k]);  // bit for bit
  const glm::dvec3 back = t.to_local(world);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(back[k], local[k], 1e-14);
  // Normals rotate only: unit stays unit, and unrotate undoes rotate.
  const glm::dvec3 n = t.rotate({0.6, 0, 0.8});
  EXPECT_NEAR(glm::length(n), 1, 1e-15);
  EXPECT_NEAR(t.unrotate(n).x, 0.6, 1e-15);
}

TEST(PlantTransform, TheWorldBoxHoldsTheTurnedAndScaledBox) {
  ScenePlant plant;
  plant.position = {1, 0, 2};
  plant.rotate_y_deg = 45;
  plant.scale = 2;
  const Aabb box = PlantTransform::of(plant).world_box({{-1, 0, -1}, {1, 1, 1}});
  EXPECT_NEAR(box.lo.x, 1 - 2 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(box.hi.z, 2 + 2 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(box.hi.y, 2, 1e-12);
}

}  // namespace
}  // namespace sylva
