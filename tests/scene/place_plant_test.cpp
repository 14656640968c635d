// place_plant_test.cpp — a plant placed in the world (core/scene/scene.h place_plant):
// its leaves move, turn and scale with it.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "core/geometry/leaf_mesh.h"
#include "core/scene/scene.h"

namespace sylva {
namespace {

TEST(LeafMesh, APlacedPlantsLeavesMoveRotateAndScaleWithIt) {
  Skeleton sk;
  sk.joints = {{{0, 0, 0}, 0.1, 0}, {{0, 1, 0}, 0.1, 0}};
  sk.chains = {{0, 2, std::nullopt}};
  sk.leaves = {Leaf{ChainParent{0, 1}, 1, {{0, 1, 0}, {1, 1, 0}, {1, 2, 0}}, std::nullopt}};
  ScenePlant plant;
  plant.skeleton = sk;
  plant.position = {10, 0, 0};
  plant.rotate_y_deg = 90;  // x -> −z
  plant.scale = 2;
  const Skeleton placed = place_plant(plant);
  ASSERT_EQ(placed.leaves.size(), 1u);
  const auto& v = placed.leaves[0].vertices_m[1];  // (1, 1, 0) scaled to (2, 2, 0), turned, moved
  EXPECT_NEAR(v[0], 10, 1e-12);
  EXPECT_NEAR(v[1], 2, 1e-12);
  EXPECT_NEAR(v[2], -2, 1e-12);
  LeafMesh mesh;
  append_leaves(mesh, placed, 7);
  ASSERT_EQ(mesh.leaves.size(), 1u);
  EXPECT_EQ(mesh.leaves[0].plant, 7u);
  EXPECT_EQ(mesh.leaves[0].material, 1u);
  EXPECT_EQ(mesh.triangle_count(), 1u);
  EXPECT_EQ(mesh.vertex_leaf, (std::vector<uint32_t>{0, 0, 0}));
  EXPECT_NEAR(glm::length(mesh.leaves[0].normal), 1, 1e-12);
  EXPECT_NEAR(mesh.leaves[0].normal.x, 1, 1e-12);  // +z turned by 90° about y
}

}  // namespace
}  // namespace sylva
