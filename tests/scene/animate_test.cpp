// Tests for core/scene/animate.h: skeletons swaying in the wind (the dancing cacti).
#include "core/scene/animate.h"
#include "core/util/math.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <glm/geometric.hpp>
#include <numbers>
#include <vector>

namespace sylva {
namespace {

using glm::dvec3;

Joint joint(dvec3 p, double radius, uint32_t material = 0) { return Joint{{p.x, p.y, p.z}, radius, material}; }
dvec3 position(const Joint& j) { return {j.position_m[0], j.position_m[1], j.position_m[2]}; }

// A vertical trunk of `segments` 1 m segments from the origin.
Skeleton trunk(int segments) {
  Skeleton sk;
  for (int i = 0; i <= segments; ++i) sk.joints.push_back(joint({0, double(i), 0}, 0.2 - 0.01 * i));
  sk.chains.push_back(Chain{0, uint32_t(segments + 1), std::nullopt});
  return sk;
}

// A trunk of 4 segments with two branches from joints 2 and 3, and a twig on the first
// branch; materials differ so that a mix-up would show.
Skeleton small_tree() {
  Skeleton sk = trunk(4);
  sk.source.grammar = "tree.lsys";
  sk.source.seed = 9;
  sk.source.steps = 3;
  sk.source.defines["N"] = 2;
  const uint32_t b1 = uint32_t(sk.joints.size());
  for (dvec3 p : {dvec3(0, 2, 0), dvec3(0.7, 2.6, 0.1), dvec3(1.3, 3.1, 0.3)}) sk.joints.push_back(joint(p, 0.05, 1));
  sk.chains.push_back(Chain{b1, 3, ChainParent{0, 2}});
  const uint32_t b2 = uint32_t(sk.joints.size());
  for (dvec3 p : {dvec3(0, 3, 0), dvec3(-0.4, 3.5, 0.6)}) sk.joints.push_back(joint(p, 0.04, 2));
  sk.chains.push_back(Chain{b2, 2, ChainParent{0, 3}});
  const uint32_t twig = uint32_t(sk.joints.size());
  for (dvec3 p : {dvec3(0.7, 2.6, 0.1), dvec3(0.75, 2.9, -0.2)}) sk.joints.push_back(joint(p, 0.01, 3));
  sk.chains.push_back(Chain{twig, 2, ChainParent{1, 1}});
  return sk;
}

void expect_same_topology(const Skeleton& a, const Skeleton& b) {
  ASSERT_EQ(a.joints.size(), b.joints.size());
  ASSERT_EQ(a.chains.size(), b.chains.size());
  for (size_t c = 0; c < a.chains.size(); ++c) {
    EXPECT_EQ(a.chains[c].first_joint, b.chains[c].first_joint) << "chain " << c;
    EXPECT_EQ(a.chains[c].joint_count, b.chains[c].joint_count) << "chain " << c;
    EXPECT_EQ(a.chains[c].parent, b.chains[c].parent) << "chain " << c;
  }
  for (size_t i = 0; i < a.joints.size(); ++i) {
    EXPECT_EQ(a.joints[i].radius_m, b.joints[i].radius_m) << "joint " << i;
    EXPECT_EQ(a.joints[i].material, b.joints[i].material) << "joint " << i;
  }
  EXPECT_EQ(a.source.grammar, b.source.grammar);
  EXPECT_EQ(a.source.seed, b.source.seed);
  EXPECT_EQ(a.source.steps, b.source.steps);
  EXPECT_EQ(a.source.defines, b.source.defines);
}

bool bitwise_equal_positions(const Skeleton& a, const Skeleton& b) {
  if (a.joints.size() != b.joints.size()) return false;
  for (size_t i = 0; i < a.joints.size(); ++i)
    if (std::memcmp(a.joints[i].position_m, b.joints[i].position_m, sizeof a.joints[i].position_m) != 0) return false;
  return true;
}

TEST(Animate, SwayingKeepsChainsParentsRadiiMaterialsAndSource) {
  const Skeleton rest = small_tree();
  const Skeleton swayed = sway_skeleton(rest, 0.77, SwayParameters{});
  expect_same_topology(rest, swayed);
  EXPECT_TRUE(validate_skeleton(swayed).ok());
  EXPECT_FALSE(bitwise_equal_positions(rest, swayed)) << "t = 0.77 s must move the plant";
}

TEST(Animate, TimeZeroIsTheRestSkeletonBitForBit) {
  const Skeleton rest = small_tree();
  EXPECT_TRUE(bitwise_equal_positions(rest, sway_skeleton(rest, 0.0, SwayParameters{})));
}

TEST(Animate, ZeroAmplitudesOrNoHorizontalWindAreTheRestSkeletonBitForBit) {
  const Skeleton rest = small_tree();
  SwayParameters still;
  still.amplitude_deg = 0;
  still.branch_amplitude_deg = 0;
  EXPECT_TRUE(bitwise_equal_positions(rest, sway_skeleton(rest, 1.3, still)));
  SwayParameters vertical_wind;
  vertical_wind.wind_direction = {0, 5, 0};
  EXPECT_TRUE(bitwise_equal_positions(rest, sway_skeleton(rest, 1.3, vertical_wind)));
}

TEST(Animate, SegmentLengthsAreKeptAtEveryTime) {
  const Skeleton rest = small_tree();
  SwayParameters strong;
  strong.amplitude_deg = 35;
  strong.branch_amplitude_deg = 25;
  strong.wind_direction = {1, 0.3, -2};
  for (double t : {0.1, 0.55, 1.0, 2.7, 31.4}) {
    const Skeleton swayed = sway_skeleton(rest, t, strong);
    for (const Chain& chain : rest.chains)
      for (uint32_t i = chain.first_joint; i + 1 < chain.first_joint + chain.joint_count; ++i) {
        const double before = glm::length(position(rest.joints[i + 1]) - position(rest.joints[i]));
        const double after = glm::length(position(swayed.joints[i + 1]) - position(swayed.joints[i]));
        EXPECT_NEAR(after, before, 1e-12 * before) << "t " << t << ", joint " << i;
      }
  }
}

TEST(Animate, TheSameInputsGiveTheSameSkeleton) {
  const Skeleton rest = small_tree();
  SwayParameters p;
  p.seed = 42;
  EXPECT_TRUE(bitwise_equal_positions(sway_skeleton(rest, 0.9, p), sway_skeleton(rest, 0.9, p)));
  SwayParameters other = p;
  other.seed = 43;  // other flutter frequencies: the branches move differently
  EXPECT_FALSE(bitwise_equal_positions(sway_skeleton(rest, 0.9, p), sway_skeleton(rest, 0.9, other)));
}

TEST(Animate, TheBaseStaysAndBranchesStayOnTheirParentJoints) {
  const Skeleton rest = small_tree();
  const Skeleton swayed = sway_skeleton(rest, 0.61, SwayParameters{});
  EXPECT_TRUE(std::memcmp(rest.joints[0].position_m, swayed.joints[0].position_m, sizeof(double) * 3) == 0);
  for (size_t c = 1; c < rest.chains.size(); ++c) {
    const ChainParent parent = *rest.chains[c].parent;
    const Joint& anchor = swayed.joints[rest.chains[parent.chain].first_joint + parent.joint];
    const Joint& first = swayed.joints[rest.chains[c].first_joint];
    for (int k = 0; k < 3; ++k) EXPECT_EQ(first.position_m[k], anchor.position_m[k]) << "chain " << c;
  }
}

// A straight trunk at the sway's extreme (t = a quarter period): segment k, starting at
// height k of H = 6, leans toward the wind by A·(1 − (1 − k/6)³), the cantilever's slope.
TEST(Animate, ATrunkBendsTowardTheWindLikeALoadedCantilever) {
  const Skeleton rest = trunk(6);
  SwayParameters p;
  p.wind_direction = {0, 0, -3};  // toward -z
  p.amplitude_deg = 20;
  p.frequency_hz = 0.5;
  const Skeleton swayed = sway_skeleton(rest, 0.5, p);  // sin(2π·0.5·0.5) = 1
  double previous_offset = -1;
  for (int k = 0; k < 6; ++k) {
    const dvec3 d = position(swayed.joints[k + 1]) - position(swayed.joints[k]);
    const double expected_rad = 20 * kPi / 180 * (1 - std::pow(1 - k / 6.0, 3));
    EXPECT_NEAR(std::atan2(-d.z, d.y), expected_rad, 1e-12) << "segment " << k;
    EXPECT_NEAR(d.x, 0, 1e-15) << "segment " << k;
    const double offset = -swayed.joints[k + 1].position_m[2];
    EXPECT_GT(offset, previous_offset) << "the lean grows with height, joint " << k + 1;
    previous_offset = offset;
  }
  // Half a period later the plant leans the other way by as much.
  const Skeleton back = sway_skeleton(rest, 1.5, p);
  EXPECT_NEAR(back.joints[6].position_m[2], -swayed.joints[6].position_m[2], 1e-12);
  EXPECT_NEAR(back.joints[6].position_m[1], swayed.joints[6].position_m[1], 1e-12);
}

// With the bend off, a branch swings rigidly about its attachment: distances between any
// two of its joints are kept, and the trunk does not move.
TEST(Animate, BranchFlutterTurnsABranchRigidlyAndLeavesTheTrunk) {
  const Skeleton rest = small_tree();
  SwayParameters p;
  p.amplitude_deg = 0;
  p.branch_amplitude_deg = 30;
  const Skeleton swayed = sway_skeleton(rest, 0.4, p);
  for (uint32_t i = 0; i < rest.chains[0].joint_count; ++i)
    EXPECT_TRUE(std::memcmp(rest.joints[i].position_m, swayed.joints[i].position_m, sizeof(double) * 3) == 0);
  const Chain& branch = rest.chains[1];
  bool moved = false;
  for (uint32_t i = branch.first_joint; i < branch.first_joint + branch.joint_count; ++i) {
    moved = moved || glm::length(position(swayed.joints[i]) - position(rest.joints[i])) > 1e-3;
    for (uint32_t j = i + 1; j < branch.first_joint + branch.joint_count; ++j) {
      const double before = glm::length(position(rest.joints[j]) - position(rest.joints[i]));
      const double after = glm::length(position(swayed.joints[j]) - position(swayed.joints[i]));
      EXPECT_NEAR(after, before, 1e-12) << "joints " << i << ", " << j;
    }
  }
  EXPECT_TRUE(moved);
}

TEST(Animate, ScenePlantsSwayOutOfStepAndStartAtRest) {
  Scene scene;
  scene.plants.resize(2);
  const std::vector<Skeleton> rest = {trunk(5), trunk(5)};
  sway_scene_plants(scene, rest, 0.0, SwayParameters{});
  for (size_t p = 0; p < 2; ++p) {
    ASSERT_TRUE(scene.plants[p].skeleton.has_value());
    EXPECT_TRUE(bitwise_equal_positions(*scene.plants[p].skeleton, rest[p]));
  }
  sway_scene_plants(scene, rest, 0.8, SwayParameters{});
  expect_same_topology(*scene.plants[0].skeleton, rest[0]);
  EXPECT_FALSE(bitwise_equal_positions(*scene.plants[0].skeleton, rest[0]));
  EXPECT_FALSE(bitwise_equal_positions(*scene.plants[0].skeleton, *scene.plants[1].skeleton))
      << "two identical plants must not move in lockstep";
}

// small_tree with a leaf on the first branch's tip (chain 1, joint 2) and one on no joint.
Skeleton leafy_tree() {
  Skeleton sk = small_tree();
  sk.leaves = {Leaf{ChainParent{1, 2}, 1, {{1.3, 3.1, 0.3}, {1.5, 3.2, 0.3}, {1.4, 3.4, 0.35}}, std::nullopt},
               Leaf{std::nullopt, 1, {{2, 0, 0}, {2.2, 0, 0}, {2.1, 0.1, 0}}, std::nullopt}};
  return sk;
}

TEST(Animate, ALeafTurnsRigidlyWithItsJointAndALeafOnNoJointStays) {
  const Skeleton rest = leafy_tree();
  EXPECT_EQ(sway_skeleton(rest, 0.0, SwayParameters{}), rest);  // t = 0: bit for bit
  SwayParameters strong;
  strong.amplitude_deg = 20;
  strong.branch_amplitude_deg = 25;
  const Skeleton swayed = sway_skeleton(rest, 0.6, strong);
  ASSERT_TRUE(validate_skeleton(swayed).ok()) << validate_skeleton(swayed).error().format();
  ASSERT_EQ(swayed.leaves.size(), 2u);
  const Joint& anchor_rest = rest.joints[rest.chains[1].first_joint + 2];
  const Joint& anchor_swayed = swayed.joints[rest.chains[1].first_joint + 2];
  ASSERT_GT(glm::length(position(anchor_swayed) - position(anchor_rest)), 1e-2) << "the joint must move";
  const auto& before = rest.leaves[0].vertices_m;
  const auto& after = swayed.leaves[0].vertices_m;
  auto at = [](const std::array<double, 3>& v) { return dvec3(v[0], v[1], v[2]); };
  for (size_t i = 0; i < before.size(); ++i) {
    // Each vertex keeps its distance from the joint and from every other vertex.
    EXPECT_NEAR(glm::length(at(after[i]) - position(anchor_swayed)), glm::length(at(before[i]) - position(anchor_rest)),
                1e-12);
    for (size_t j = i + 1; j < before.size(); ++j)
      EXPECT_NEAR(glm::length(at(after[j]) - at(after[i])), glm::length(at(before[j]) - at(before[i])), 1e-12);
  }
  // The leaf's first vertex is the joint itself ('.' right after the F): it follows the
  // joint exactly.
  EXPECT_NEAR(glm::length(at(after[0]) - position(anchor_swayed)), 0, 1e-12);
  EXPECT_EQ(swayed.leaves[1], rest.leaves[1]);
}

}  // namespace
}  // namespace sylva
