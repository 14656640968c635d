// Tests for core/grow/turtle.h: the 3D turtle of docs/spec/grammar.md ("Turtle commands") and the chain
// building rules of docs/spec/skeleton.md ("How the turtle builds chains").
//
// The frame starts at H = +Y, L = −X, U = +Z (H × L = U). Every expected position below is
// worked out by hand from that frame; sin/cos of multiples of 90° are exact in sylva, so
// right-angle turns give exact coordinates and are compared with EXPECT_EQ. Anything that
// involves other angles is compared with a tolerance of 1e-12.
#include "core/geometry/leaf_mesh.h"
#include "core/grow/turtle.h"
#include "core/grow/grow.h"
#include "lsystem/vlab_object.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace sylva {
namespace {

using Position = std::array<double, 3>;

constexpr double kTolerance = 1e-12;

// Parses `text` as test.lsys and grows it with default options.
sylva::Expected<GrowResult> grow_text(std::string_view text) {
  sylva::Expected<lsys::Grammar> grammar = lsys::parse_grammar(text, "test.lsys", {});
  if (!grammar.ok()) return grammar.error();
  return grow(*grammar, {}, "test.lsys", {});
}

// The skeleton `text` grows into; an empty skeleton (and a test failure) if it does not.
Skeleton skeleton_of(std::string_view text) {
  sylva::Expected<GrowResult> result = grow_text(text);
  if (!result.ok()) {
    ADD_FAILURE() << "grammar failed to grow:\n" << result.error().format();
    return {};
  }
  return std::move(result->skeleton);
}

// The formatted error `text` fails with, or "no error".
std::string grow_error(std::string_view text) {
  sylva::Expected<GrowResult> result = grow_text(text);
  return result.ok() ? "no error" : result.error().format();
}

// Joint `joint` of chain `chain`; callers ASSERT the counts first (at() guards the rest).
const Joint& joint_at(const Skeleton& skeleton, size_t chain, size_t joint) {
  const Chain& c = skeleton.chains.at(chain);
  EXPECT_LT(joint, c.joint_count);
  return skeleton.joints.at(c.first_joint + joint);
}

Position position(const Joint& joint) {
  return {joint.position_m[0], joint.position_m[1], joint.position_m[2]};
}

Position position_at(const Skeleton& skeleton, size_t chain, size_t joint) {
  return position(joint_at(skeleton, chain, joint));
}

// Where the turtle ends after `axiom`, for a word that draws a single chain.
Position tip_of(std::string_view header, std::string_view axiom) {
  const Skeleton skeleton = skeleton_of(std::string(header) + "axiom: " + std::string(axiom) + "\n");
  if (skeleton.chains.size() != 1) {
    ADD_FAILURE() << "expected one chain, got " << skeleton.chains.size();
    return {NAN, NAN, NAN};
  }
  return position(skeleton.joints.back());
}
Position tip_of(std::string_view axiom) { return tip_of("", axiom); }

testing::AssertionResult near(const Position& actual, const Position& expected) {
  for (int k = 0; k < 3; ++k) {
    if (!(std::abs(actual[k] - expected[k]) <= kTolerance)) {
      return testing::AssertionFailure()
             << "(" << actual[0] << ", " << actual[1] << ", " << actual[2] << ") differs from ("
             << expected[0] << ", " << expected[1] << ", " << expected[2] << ") in component " << k
             << " by " << actual[k] - expected[k];
    }
  }
  return testing::AssertionSuccess();
}

std::optional<ChainParent> parent(uint32_t chain, uint32_t joint) { return ChainParent{chain, joint}; }

// ---- moving: F, f, step ----------------------------------------------------------

TEST(TurtleMove, FDrawsOneSegmentAlongPlusYFromTheOrigin) {
  const Skeleton skeleton = skeleton_of("axiom: F\n");
  ASSERT_EQ(skeleton.chains.size(), 1u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 2u);
  EXPECT_EQ(skeleton.chains[0].parent, std::nullopt);
  EXPECT_EQ(position_at(skeleton, 0, 0), (Position{0, 0, 0}));
  EXPECT_EQ(position_at(skeleton, 0, 1), (Position{0, 1, 0}));
  EXPECT_EQ(skeleton.segment_count(), 1u);
}

TEST(TurtleMove, FWithoutParameterMovesTheDefaultStepOfOne) {
  EXPECT_EQ(tip_of("FF"), (Position{0, 2, 0}));
}

TEST(TurtleMove, StepDirectiveSetsTheDefaultLengthOfFAndf) {
  EXPECT_EQ(tip_of("step: 2\n", "F"), (Position{0, 2, 0}));
  const Skeleton skeleton = skeleton_of("step: 2\naxiom: fF\n");
  ASSERT_EQ(skeleton.chains.size(), 1u);
  EXPECT_EQ(position_at(skeleton, 0, 0), (Position{0, 2, 0}));
  EXPECT_EQ(position_at(skeleton, 0, 1), (Position{0, 4, 0}));
}

TEST(TurtleMove, FParameterOverridesTheStep) {
  EXPECT_EQ(tip_of("step: 2\n", "F(2.5)"), (Position{0, 2.5, 0}));
}

TEST(TurtleMove, SmallfMovesWithoutAJointAndTheNextFStartsANewRootChain) {
  const Skeleton skeleton = skeleton_of("axiom: FfF\n");
  ASSERT_EQ(skeleton.chains.size(), 2u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 2u);
  ASSERT_EQ(skeleton.chains[1].joint_count, 2u);
  EXPECT_EQ(position_at(skeleton, 0, 0), (Position{0, 0, 0}));
  EXPECT_EQ(position_at(skeleton, 0, 1), (Position{0, 1, 0}));
  EXPECT_EQ(skeleton.chains[1].parent, std::nullopt);
  EXPECT_EQ(position_at(skeleton, 1, 0), (Position{0, 2, 0}));
  EXPECT_EQ(position_at(skeleton, 1, 1), (Position{0, 3, 0}));
  EXPECT_EQ(skeleton.segment_count(), 2u);
}

TEST(TurtleMove, SmallfInsideABranchStartsARootChainNotAChildOfTheBranchPoint) {
  const Skeleton skeleton = skeleton_of("axiom: F[fF]F\n");
  ASSERT_EQ(skeleton.chains.size(), 2u);
  EXPECT_EQ(skeleton.chains[0].joint_count, 3u);  // the main axis continues after ]
  EXPECT_EQ(skeleton.chains[1].parent, std::nullopt);
  EXPECT_EQ(position_at(skeleton, 1, 0), (Position{0, 2, 0}));
  EXPECT_EQ(position_at(skeleton, 1, 1), (Position{0, 3, 0}));
}

TEST(TurtleMove, ZeroLengthFMakesNoJointAndIsCounted) {
  sylva::Expected<GrowResult> result = grow_text("axiom: FF(0)F\n");
  ASSERT_TRUE(result.ok()) << result.error().format();
  const Skeleton& skeleton = result->skeleton;
  ASSERT_EQ(skeleton.chains.size(), 1u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 3u);
  EXPECT_EQ(position_at(skeleton, 0, 1), (Position{0, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 0, 2), (Position{0, 2, 0}));
  EXPECT_EQ(result->turtle.zero_length_moves, 1u);
}

TEST(TurtleMove, ZeroLengthMovesAreCountedForFAndf) {
  sylva::Expected<GrowResult> result = grow_text("axiom: F(0)Ff(0)F(0)\n");
  ASSERT_TRUE(result.ok()) << result.error().format();
  EXPECT_EQ(result->turtle.zero_length_moves, 3u);
  EXPECT_EQ(result->skeleton.segment_count(), 1u);
}

TEST(TurtleMove, AWordWithoutFGivesAnEmptySkeleton) {
  const Skeleton skeleton = skeleton_of("axiom: +f[A]\n");
  EXPECT_TRUE(skeleton.chains.empty());
  EXPECT_TRUE(skeleton.joints.empty());
}

TEST(TurtleMove, ModulesTheTurtleDoesNotKnowAreIgnored) {
  const Skeleton plain = skeleton_of("axiom: F+F\n");
  const Skeleton with_others = skeleton_of("axiom: AFX+BFC(1,2)\n");
  ASSERT_EQ(with_others.chains.size(), 1u);
  ASSERT_EQ(with_others.joints.size(), plain.joints.size());
  for (size_t j = 0; j < plain.joints.size(); ++j)
    EXPECT_EQ(position(with_others.joints[j]), position(plain.joints[j])) << "joint " << j;
  EXPECT_EQ(position(with_others.joints.back()), (Position{-1, 1, 0}));
}

// ---- turning: + - & ^ \ / | $ and the default angle ------------------------------

TEST(TurtleTurn, PlusTurnsHeadingTowardLeftThatIsMinusX) {
  EXPECT_EQ(tip_of("+(90)F"), (Position{-1, 0, 0}));
}

TEST(TurtleTurn, MinusTurnsHeadingTowardMinusLeftThatIsPlusX) {
  EXPECT_EQ(tip_of("-(90)F"), (Position{1, 0, 0}));
}

TEST(TurtleTurn, PlusIsCounterclockwiseSeenFromPlusZ) {
  // Four quarter turns to the left walk the square (0,1) (-1,1) (-1,0) (0,0).
  const Skeleton skeleton = skeleton_of("axiom: F+(90)F+(90)F+(90)F\n");
  ASSERT_EQ(skeleton.chains.size(), 1u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 5u);
  EXPECT_EQ(position_at(skeleton, 0, 1), (Position{0, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 0, 2), (Position{-1, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 0, 3), (Position{-1, 0, 0}));
  EXPECT_EQ(position_at(skeleton, 0, 4), (Position{0, 0, 0}));
}

TEST(TurtleTurn, AmpersandPitchesHeadingDownTowardMinusUpThatIsMinusZ) {
  EXPECT_EQ(tip_of("&(90)F"), (Position{0, 0, -1}));
}

TEST(TurtleTurn, CaretPitchesHeadingUpTowardUpThatIsPlusZ) {
  EXPECT_EQ(tip_of("^(90)F"), (Position{0, 0, 1}));
}

TEST(TurtleTurn, AmpersandRotatesUpWithHeadingSoTurnsAfterAPitchStayAboutTheNewUp) {
  // &(90): H = −Z, U = +Y, L = −X unchanged; + then turns H toward L.
  EXPECT_EQ(tip_of("&(90)+(90)F"), (Position{-1, 0, 0}));
  // ^(90): H = +Z, U = −Y; a further ^(90) turns H toward the new U.
  EXPECT_EQ(tip_of("^(90)^(90)F"), (Position{0, -1, 0}));
}

TEST(TurtleTurn, BackslashRollsUpTowardLeft) {
  // \(90): U turns toward L, so U = −X and L = −U_old = −Z; H stays +Y.
  EXPECT_EQ(tip_of("\\(90)F"), (Position{0, 1, 0}));
  // & now turns H toward −U = +X.
  EXPECT_EQ(tip_of("\\(90)&(90)F"), (Position{1, 0, 0}));
  // + now turns H toward L = −Z.
  EXPECT_EQ(tip_of("\\(90)+(90)F"), (Position{0, 0, -1}));
}

TEST(TurtleTurn, SlashRollsUpTowardMinusLeft) {
  // /(90): U turns toward −L, so U = +X and L = U_old = +Z; H stays +Y.
  EXPECT_EQ(tip_of("/(90)&(90)F"), (Position{-1, 0, 0}));
  EXPECT_EQ(tip_of("/(90)+(90)F"), (Position{0, 0, 1}));
}

TEST(TurtleTurn, BarTurnsAroundAboutUp) {
  EXPECT_EQ(tip_of("|F"), (Position{0, -1, 0}));
  // About U: U stays +Z, L flips to +X, so + now turns toward +X.
  EXPECT_EQ(tip_of("|+(90)F"), (Position{1, 0, 0}));
  EXPECT_EQ(tip_of("|&(90)F"), (Position{0, 0, -1}));
}

TEST(TurtleTurn, BarIgnoresTheDefaultAngle) {
  EXPECT_EQ(tip_of("angle: 30\n", "|F"), (Position{0, -1, 0}));
}

TEST(TurtleTurn, DollarRollsLeftBackToHorizontal) {
  // &(30) pitches H to (0, cos 30, −sin 30) and keeps L = −X; \(40) rolls L out of the
  // horizontal plane. $ sets L = (Y × H)/|Y × H| = (−1, 0, 0) again, so + turns H there.
  const Position leveled = tip_of("&(30)\\(40)$+(90)F");
  EXPECT_EQ(leveled, (Position{-1, 0, 0}));
  EXPECT_EQ(leveled[1], 0.0);  // L · Y == 0
  // Without $, the rolled L is not horizontal: the same turn climbs or falls.
  const Position rolled = tip_of("&(30)\\(40)+(90)F");
  EXPECT_GT(std::abs(rolled[1]), 0.1);
}

TEST(TurtleTurn, DollarLeavesTheFrameAloneWhenHeadingIsVertical) {
  // H = +Y is parallel to V: no change, so the roll \(90) (L = −Z) survives the $.
  EXPECT_EQ(tip_of("\\(90)$+(90)F"), (Position{0, 0, -1}));
}

TEST(TurtleTurn, DefaultAngleIsNinetyDegrees) {
  EXPECT_EQ(tip_of("+F"), (Position{-1, 0, 0}));
  EXPECT_EQ(tip_of("&F"), (Position{0, 0, -1}));
}

TEST(TurtleTurn, AngleDirectiveSetsTheDefaultForEveryTurn) {
  const double s = std::sin(45 * std::numbers::pi / 180), c = std::cos(45 * std::numbers::pi / 180);
  EXPECT_TRUE(near(tip_of("angle: 45\n", "+F"), {-s, c, 0}));
  EXPECT_TRUE(near(tip_of("angle: 45\n", "-F"), {s, c, 0}));
  EXPECT_TRUE(near(tip_of("angle: 45\n", "&F"), {0, c, -s}));
  EXPECT_TRUE(near(tip_of("angle: 45\n", "^F"), {0, c, s}));
  // Rolls use it too: \ then & (both 45°): U = (−s, 0, c), H turns toward −U.
  EXPECT_TRUE(near(tip_of("angle: 45\n", "\\&F"), {s * s, c, -s * c}));
  EXPECT_TRUE(near(tip_of("angle: 45\n", "/&F"), {-s * s, c, -s * c}));
}

TEST(TurtleTurn, TurnParameterOverridesTheDefaultAngle) {
  EXPECT_EQ(tip_of("angle: 45\n", "+(90)F"), (Position{-1, 0, 0}));
  const double s = std::sin(30 * std::numbers::pi / 180), c = std::cos(30 * std::numbers::pi / 180);
  EXPECT_TRUE(near(tip_of("+(30)F"), {-s, c, 0}));
}

TEST(TurtleTurn, NegativeAnglesTurnTheOtherWay) {
  EXPECT_EQ(tip_of("+(-90)F"), (Position{1, 0, 0}));
  EXPECT_EQ(tip_of("&(-90)F"), (Position{0, 0, 1}));
}

// ---- radius: width, !, !(r) --------------------------------------------------------

TEST(TurtleRadius, DefaultInitialRadiusIsFiveCentimetres) {
  const Skeleton skeleton = skeleton_of("axiom: F\n");
  ASSERT_EQ(skeleton.joints.size(), 2u);
  EXPECT_EQ(skeleton.joints[0].radius_m, 0.05);
  EXPECT_EQ(skeleton.joints[1].radius_m, 0.05);
}

TEST(TurtleRadius, WidthDirectiveIsTheInitialRadius) {
  const Skeleton skeleton = skeleton_of("width: 0.2\naxiom: FF\n");
  ASSERT_EQ(skeleton.joints.size(), 3u);
  for (const Joint& joint : skeleton.joints) EXPECT_EQ(joint.radius_m, 0.2);
}

TEST(TurtleRadius, BangMultipliesTheRadiusByTheDefaultDecrementOfPointSeven) {
  const Skeleton skeleton = skeleton_of("axiom: F!F!F\n");
  ASSERT_EQ(skeleton.joints.size(), 4u);
  EXPECT_EQ(skeleton.joints[0].radius_m, 0.05);
  EXPECT_EQ(skeleton.joints[1].radius_m, 0.05);
  EXPECT_EQ(skeleton.joints[2].radius_m, 0.05 * 0.7);
  EXPECT_EQ(skeleton.joints[3].radius_m, 0.05 * 0.7 * 0.7);
}

TEST(TurtleRadius, WidthDecrementDirectiveSetsTheFactorOfBang) {
  const Skeleton skeleton = skeleton_of("width: 0.2\nwidth decrement: 0.5\naxiom: F!F\n");
  ASSERT_EQ(skeleton.joints.size(), 3u);
  EXPECT_EQ(skeleton.joints[1].radius_m, 0.2);
  EXPECT_EQ(skeleton.joints[2].radius_m, 0.1);
}

TEST(TurtleRadius, BangWithParameterSetsTheRadiusAndTapersOnlyTheNextSegment) {
  // F !(0.5) F: the first segment is 0.05 → 0.05, the second 0.05 → 0.5.
  const Skeleton skeleton = skeleton_of("axiom: F!(0.5)F\n");
  ASSERT_EQ(skeleton.chains.size(), 1u);
  ASSERT_EQ(skeleton.joints.size(), 3u);
  EXPECT_EQ(skeleton.joints[0].radius_m, 0.05);
  EXPECT_EQ(skeleton.joints[1].radius_m, 0.05);
  EXPECT_EQ(skeleton.joints[2].radius_m, 0.5);
}

TEST(TurtleRadius, ZeroRadiusIsAllowedAsATip) {
  const Skeleton skeleton = skeleton_of("axiom: F!(0)F\n");
  ASSERT_EQ(skeleton.joints.size(), 3u);
  EXPECT_EQ(skeleton.joints[2].radius_m, 0.0);
}

TEST(TurtleRadius, ABranchStartsWithTheRadiusInForceAtItsFirstF) {
  // The branch's first joint is the turtle's position with the *current* radius.
  const Skeleton skeleton = skeleton_of("axiom: F[!(0.01)+F]F\n");
  ASSERT_EQ(skeleton.chains.size(), 2u);
  EXPECT_EQ(joint_at(skeleton, 1, 0).radius_m, 0.01);
  EXPECT_EQ(joint_at(skeleton, 1, 1).radius_m, 0.01);
  EXPECT_EQ(joint_at(skeleton, 0, 1).radius_m, 0.05);
}

// ---- material: ', '(i) -------------------------------------------------------------

TEST(TurtleMaterial, JointsCarryTheMaterialOfTheSegmentEndingAtThem) {
  // Segments: F (0), ' F (1), '(3) F (3), ' F (4).
  const Skeleton skeleton = skeleton_of("axiom: F'F'(3)F'F\n");
  ASSERT_EQ(skeleton.chains.size(), 1u);
  ASSERT_EQ(skeleton.joints.size(), 5u);
  EXPECT_EQ(skeleton.joints[0].material, 0u);
  EXPECT_EQ(skeleton.joints[1].material, 0u);
  EXPECT_EQ(skeleton.joints[2].material, 1u);
  EXPECT_EQ(skeleton.joints[3].material, 3u);
  EXPECT_EQ(skeleton.joints[4].material, 4u);
}

TEST(TurtleMaterial, MaterialChangeAfterTheLastFColoursNothing) {
  const Skeleton skeleton = skeleton_of("axiom: FF'(7)\n");
  ASSERT_EQ(skeleton.joints.size(), 3u);
  for (const Joint& joint : skeleton.joints) EXPECT_EQ(joint.material, 0u);
}

// ---- brackets restore the whole turtle state ---------------------------------------

TEST(TurtleBranch, ClosingBracketRestoresPositionFrameRadiusAndMaterial) {
  // Inside the branch: a turn, a roll, a new radius and material; after ] the main axis
  // goes on straight up with radius 0.05 and material 0 (cpfg keeps width and colour in
  // the turtle state).
  const Skeleton skeleton = skeleton_of("axiom: F[+(90)\\(90)!(0.01)'(5)F]F\n");
  ASSERT_EQ(skeleton.chains.size(), 2u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 3u);
  const Joint& after = joint_at(skeleton, 0, 2);
  EXPECT_EQ(position(after), (Position{0, 2, 0}));
  EXPECT_EQ(after.radius_m, 0.05);
  EXPECT_EQ(after.material, 0u);
  EXPECT_EQ(position_at(skeleton, 1, 1), (Position{-1, 1, 0}));
  EXPECT_EQ(joint_at(skeleton, 1, 1).material, 5u);
}

// ---- tropism: tropism: x y z e, @T(e) ------------------------------------------------

// With T = (a, 0, 0), a > 0, and H = (sin θ, cos θ, 0) in the XY plane, H × T = −a cos θ·Z:
// the Rodrigues rotation about −Z by e·a·cos θ turns H toward +X inside the XY plane, so
// θ grows by e·a·cos θ after every F (ABOP 2.2, α = e·|H × T|, angles in radians).
TEST(TurtleTropism, TropismBendsHeadingTowardTAfterEveryF) {
  const Skeleton skeleton = skeleton_of("tropism: 1 0 0 0.5\naxiom: FFF\n");
  ASSERT_EQ(skeleton.chains.size(), 1u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 4u);
  // The first segment is straight: the bend comes after the F.
  EXPECT_EQ(position_at(skeleton, 0, 1), (Position{0, 1, 0}));
  const double theta1 = 0.5;                                // e·|Y × X| = 0.5
  const double theta2 = theta1 + 0.5 * std::cos(theta1);    // e·|H × T| = 0.5 cos θ1
  const Position j2 = {std::sin(theta1), 1 + std::cos(theta1), 0};
  const Position j3 = {j2[0] + std::sin(theta2), j2[1] + std::cos(theta2), 0};
  EXPECT_TRUE(near(position_at(skeleton, 0, 2), j2));
  EXPECT_TRUE(near(position_at(skeleton, 0, 3), j3));
}

TEST(TurtleTropism, TropismAngleScalesWithTheLengthOfT) {
  // T = (2, 0, 0), e = 0.25: α = 0.25·|Y × 2X| = 0.5, the same first bend as above.
  const Skeleton skeleton = skeleton_of("tropism: 2 0 0 0.25\naxiom: FF\n");
  ASSERT_EQ(skeleton.joints.size(), 3u);
  EXPECT_TRUE(near(position(skeleton.joints[2]), {std::sin(0.5), 1 + std::cos(0.5), 0}));
}

TEST(TurtleTropism, TropismOutOfPlaneMatchesRodriguesRotation) {
  // H = Y, T = (1, 0, 1): H × T = (1, 0, −1), |H × T| = √2, α = e·√2, k = (1, 0, −1)/√2.
  // Rodrigues: H' = H cos α + (k × H) sin α + k (k·H)(1 − cos α), with k·H = 0 and
  // k × H = (1, 0, 1)/√2, so H' = (sin α/√2, cos α, sin α/√2).
  const Skeleton skeleton = skeleton_of("tropism: 1 0 1 0.25\naxiom: FF\n");
  ASSERT_EQ(skeleton.joints.size(), 3u);
  const double alpha = 0.25 * std::sqrt(2.0);
  const double side = std::sin(alpha) / std::sqrt(2.0);
  EXPECT_TRUE(near(position(skeleton.joints[2]), {side, 1 + std::cos(alpha), side}));
}

TEST(TurtleTropism, NoBendWhenHeadingIsParallelToT) {
  // T = −Y (gravity) against H = +Y, and T = +Y along it: H × T = 0.
  EXPECT_EQ(tip_of("tropism: 0 -1 0 0.8\n", "FFF"), (Position{0, 3, 0}));
  EXPECT_EQ(tip_of("tropism: 0 1 0 0.8\n", "FFF"), (Position{0, 3, 0}));
}

TEST(TurtleTropism, AtTSetsTheSusceptibility) {
  // The header's e is 0 (no bend) until @T(0.5) gives the first test's bend.
  EXPECT_EQ(tip_of("tropism: 1 0 0 0\n", "FF"), (Position{0, 2, 0}));
  EXPECT_TRUE(near(tip_of("tropism: 1 0 0 0\n", "@T(0.5)FF"), {std::sin(0.5), 1 + std::cos(0.5), 0}));
  // @T(0) switches the header's tropism off.
  EXPECT_EQ(tip_of("tropism: 1 0 0 0.5\n", "@T(0)FF"), (Position{0, 2, 0}));
}

TEST(TurtleTropism, AtTHoldsForTheRestOfTheBranchOnly) {
  const Skeleton skeleton = skeleton_of("tropism: 1 0 0 0\naxiom: F[@T(0.5)FF]FF\n");
  ASSERT_EQ(skeleton.chains.size(), 2u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 4u);
  EXPECT_EQ(position_at(skeleton, 0, 3), (Position{0, 3, 0}));  // main axis: unbent
  ASSERT_EQ(skeleton.chains[1].joint_count, 3u);
  EXPECT_TRUE(near(position_at(skeleton, 1, 2), {std::sin(0.5), 2 + std::cos(0.5), 0}));
}

// ---- chains (docs/spec/skeleton.md) ------------------------------------------------------------

TEST(TurtleChains, MainAxisContinuesThroughABranchPoint) {
  // F[+F]F: chain 0 = (0,0) (0,1) (0,2); chain 1 = (0,1) (−1,1), attached at (0, 1).
  const Skeleton skeleton = skeleton_of("axiom: F[+F]F\n");
  ASSERT_EQ(skeleton.chains.size(), 2u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 3u);
  ASSERT_EQ(skeleton.chains[1].joint_count, 2u);
  EXPECT_EQ(skeleton.chains[0].parent, std::nullopt);
  EXPECT_EQ(skeleton.chains[1].parent, parent(0, 1));
  EXPECT_EQ(position_at(skeleton, 0, 0), (Position{0, 0, 0}));
  EXPECT_EQ(position_at(skeleton, 0, 1), (Position{0, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 0, 2), (Position{0, 2, 0}));
  EXPECT_EQ(position_at(skeleton, 1, 0), (Position{0, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 1, 1), (Position{-1, 1, 0}));
  EXPECT_EQ(skeleton.segment_count(), 3u);
}

TEST(TurtleChains, TwoBranchesAtOneJointAreTwoChainsAttachedThere) {
  const Skeleton skeleton = skeleton_of("axiom: F[+F][-F]F\n");
  ASSERT_EQ(skeleton.chains.size(), 3u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 3u);
  EXPECT_EQ(position_at(skeleton, 0, 2), (Position{0, 2, 0}));
  EXPECT_EQ(skeleton.chains[1].parent, parent(0, 1));
  EXPECT_EQ(position_at(skeleton, 1, 1), (Position{-1, 1, 0}));
  EXPECT_EQ(skeleton.chains[2].parent, parent(0, 1));
  EXPECT_EQ(position_at(skeleton, 2, 0), (Position{0, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 2, 1), (Position{1, 1, 0}));
  EXPECT_EQ(skeleton.segment_count(), 4u);
}

TEST(TurtleChains, NestedBranchesAttachToTheBranchTheyGrowFrom) {
  // F[+F[-F]F]F: chain 0 = (0,0) (0,1) (0,2); chain 1 = (0,1) (−1,1) (−2,1) continues
  // through its own branch point; chain 2 = (−1,1) (−1,2) hangs from chain 1's joint 1.
  const Skeleton skeleton = skeleton_of("axiom: F[+F[-F]F]F\n");
  ASSERT_EQ(skeleton.chains.size(), 3u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 3u);
  ASSERT_EQ(skeleton.chains[1].joint_count, 3u);
  ASSERT_EQ(skeleton.chains[2].joint_count, 2u);
  EXPECT_EQ(skeleton.chains[1].parent, parent(0, 1));
  EXPECT_EQ(skeleton.chains[2].parent, parent(1, 1));
  EXPECT_EQ(position_at(skeleton, 0, 2), (Position{0, 2, 0}));
  EXPECT_EQ(position_at(skeleton, 1, 0), (Position{0, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 1, 1), (Position{-1, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 1, 2), (Position{-2, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 2, 0), (Position{-1, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 2, 1), (Position{-1, 2, 0}));
  EXPECT_EQ(skeleton.segment_count(), 5u);
}

TEST(TurtleChains, BranchGroupInsideABranchLeavesTheMainAxisToTheFAfterTheOuterBracket) {
  // F[[+F]F]F: both F inside the outer brackets are lateral; the last F continues
  // chain 0. chain 1 = +F, chain 2 = the inner straight F, both attached at (0, 1).
  const Skeleton skeleton = skeleton_of("axiom: F[[+F]F]F\n");
  ASSERT_EQ(skeleton.chains.size(), 3u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 3u);
  EXPECT_EQ(position_at(skeleton, 0, 2), (Position{0, 2, 0}));
  EXPECT_EQ(skeleton.chains[1].parent, parent(0, 1));
  EXPECT_EQ(position_at(skeleton, 1, 1), (Position{-1, 1, 0}));
  ASSERT_EQ(skeleton.chains[2].joint_count, 2u);
  EXPECT_EQ(skeleton.chains[2].parent, parent(0, 1));
  EXPECT_EQ(position_at(skeleton, 2, 0), (Position{0, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 2, 1), (Position{0, 2, 0}));
}

TEST(TurtleChains, SecondBranchOfABranchGroupIsLateralNotTheMainAxis) {
  // ABOP Fig. 1.24f writes F-[[X]+X]+F...: in F[[+F]-F]F the -F is a lateral branch
  // (docs/spec/skeleton.md: "a lateral branch is a new chain"), and the main axis continues with the
  // F after the outer ]. chain 0 = (0,0) (0,1) (0,2); chain 1 = +F; chain 2 = -F.
  const Skeleton skeleton = skeleton_of("axiom: F[[+F]-F]F\n");
  ASSERT_EQ(skeleton.chains.size(), 3u);
  ASSERT_EQ(skeleton.chains[0].joint_count, 3u);
  EXPECT_EQ(position_at(skeleton, 0, 2), (Position{0, 2, 0}));
  EXPECT_EQ(skeleton.chains[1].parent, parent(0, 1));
  EXPECT_EQ(position_at(skeleton, 1, 1), (Position{-1, 1, 0}));
  ASSERT_EQ(skeleton.chains[2].joint_count, 2u);
  EXPECT_EQ(skeleton.chains[2].parent, parent(0, 1));
  EXPECT_EQ(position_at(skeleton, 2, 1), (Position{1, 1, 0}));
}

TEST(TurtleChains, EmptyBracketsDoNotBreakTheChain) {
  const Skeleton skeleton = skeleton_of("axiom: F[]F[+]F\n");
  ASSERT_EQ(skeleton.chains.size(), 1u);
  EXPECT_EQ(skeleton.chains[0].joint_count, 4u);
  EXPECT_EQ(position_at(skeleton, 0, 3), (Position{0, 3, 0}));
}

TEST(TurtleChains, BranchBeforeAnyFIsARootChainAndSoIsTheFAfterIt) {
  // [F]F: the turtle stands on no joint at [ and after ], so both chains are roots.
  const Skeleton skeleton = skeleton_of("axiom: [F]F\n");
  ASSERT_EQ(skeleton.chains.size(), 2u);
  EXPECT_EQ(skeleton.chains[0].parent, std::nullopt);
  EXPECT_EQ(skeleton.chains[1].parent, std::nullopt);
  EXPECT_EQ(position_at(skeleton, 0, 0), (Position{0, 0, 0}));
  EXPECT_EQ(position_at(skeleton, 0, 1), (Position{0, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 1, 0), (Position{0, 0, 0}));
  EXPECT_EQ(position_at(skeleton, 1, 1), (Position{0, 1, 0}));
}

TEST(TurtleChains, BranchAfterTurnsStartsFromTheJointNotFromAnEarlierOne) {
  // F+F[&F]: the branch hangs from chain 0's last joint (−1, 1), index 2.
  const Skeleton skeleton = skeleton_of("axiom: F+F[&F]\n");
  ASSERT_EQ(skeleton.chains.size(), 2u);
  EXPECT_EQ(skeleton.chains[1].parent, parent(0, 2));
  EXPECT_EQ(position_at(skeleton, 1, 0), (Position{-1, 1, 0}));
  EXPECT_EQ(position_at(skeleton, 1, 1), (Position{-1, 1, -1}));
}

// ABOP Fig. 1.24f (δ = 22.5°), five steps: every chain invariant of docs/spec/skeleton.md holds.
TEST(TurtleChains, ParentsComeBeforeChildrenAndSegmentsAreOnePerF) {
  const std::string text =
      "angle: 22.5\n"
      "derivation length: 5\n"
      "axiom: X\n"
      "X -> F-[[X]+X]+F[+FX]-X\n"
      "F -> FF\n";
  sylva::Expected<lsys::Grammar> grammar = lsys::parse_grammar(text, "test.lsys", {});
  ASSERT_TRUE(grammar.ok()) << grammar.error().format();
  sylva::Expected<lsys::Word> word = lsys::derive(*grammar);
  ASSERT_TRUE(word.ok()) << word.error().format();
  uint64_t f_count = 0;
  for (const lsys::Module& m : word->modules) f_count += m.symbol == lsys::kSymF;

  sylva::Expected<GrowResult> grown = grow(*grammar, {}, "test.lsys", {});
  ASSERT_TRUE(grown.ok()) << grown.error().format();
  const Skeleton& skeleton = grown->skeleton;
  ASSERT_GT(skeleton.chains.size(), 10u);

  uint64_t segments = 0;
  uint32_t next_joint = 0;
  for (size_t c = 0; c < skeleton.chains.size(); ++c) {
    const Chain& chain = skeleton.chains[c];
    SCOPED_TRACE("chain " + std::to_string(c));
    EXPECT_EQ(chain.first_joint, next_joint);  // chains are contiguous and in order
    EXPECT_GE(chain.joint_count, 2u);
    next_joint += chain.joint_count;
    segments += chain.joint_count - 1;
    if (c == 0) {
      EXPECT_EQ(chain.parent, std::nullopt);
      continue;
    }
    ASSERT_TRUE(chain.parent.has_value());
    ASSERT_LT(chain.parent->chain, c);
    ASSERT_LT(chain.parent->joint, skeleton.chains[chain.parent->chain].joint_count);
    // A branch starts exactly where its parent joint is.
    EXPECT_EQ(position_at(skeleton, c, 0), position_at(skeleton, chain.parent->chain, chain.parent->joint));
  }
  EXPECT_EQ(next_joint, skeleton.joints.size());
  EXPECT_EQ(skeleton.segment_count(), segments);
  EXPECT_EQ(skeleton.segment_count(), f_count);
  EXPECT_TRUE(validate_skeleton(skeleton).ok());
}

TEST(TurtleChains, GrowRecordsTheSourceOfTheSkeleton) {
  const Skeleton skeleton = skeleton_of("seed: 9\nderivation length: 3\naxiom: F\n");
  EXPECT_EQ(skeleton.source.grammar, "test.lsys");
  EXPECT_EQ(skeleton.source.seed, 9u);
  EXPECT_EQ(skeleton.source.steps, 3);
}

// ---- errors ----------------------------------------------------------------------

TEST(TurtleErrors, NegativeRadiusIsAnErrorNamingTheModule) {
  sylva::Expected<GrowResult> result = grow_text("axiom: F!(-1)F\n");
  ASSERT_FALSE(result.ok());
  const std::string message = result.error().format();
  EXPECT_NE(message.find("test.lsys"), std::string::npos) << message;
  EXPECT_NE(message.find("error"), std::string::npos) << message;
  EXPECT_NE(message.find("negative"), std::string::npos) << message;
  EXPECT_NE(message.find("!(-1)"), std::string::npos) << message;
  EXPECT_NE(message.find("module 1"), std::string::npos) << message;  // its index in the word
}

// docs/limits.md: a length like 1e300 is finite, but no renderer can place it.
TEST(TurtleErrors, PositionsAndRadiiBeyondTheLimitAreErrorsNamingTheModule) {
  std::string message = grow_error("axiom: F(1e300)\n");
  EXPECT_NE(message.find("exceeds the limit of 1e12 m"), std::string::npos) << message;
  EXPECT_NE(message.find("F(1e+300)"), std::string::npos) << message;
  message = grow_error("axiom: f(2e12)F\n");
  EXPECT_NE(message.find("exceeds the limit of 1e12 m"), std::string::npos) << message;
  message = grow_error("axiom: !(1e13)F\n");
  EXPECT_NE(message.find("radius exceeds the limit"), std::string::npos) << message;
  EXPECT_TRUE(grow_text("axiom: F(1e11)!(1e11)F\n").ok());
}

// A turtle error points into the grammar: at the one production (or the axiom) that
// writes the module, or, where several could have, a note at each of them.
TEST(TurtleErrors, AreLocatedAtTheProductionThatWritesTheModule) {
  sylva::Expected<GrowResult> result = grow_text("derivation length: 1\naxiom: A\nA -> F!(-1)F\n");
  ASSERT_FALSE(result.ok());
  const Diagnostic& d = result.error();
  EXPECT_EQ(d.loc, (SourceLoc{3, 1})) << d.format();
  EXPECT_EQ(d.source_line, "A -> F!(-1)F") << d.format();
  EXPECT_NE(d.message.find("the radius must be finite and not negative at module 1 (!(-1))"), std::string::npos)
      << d.format();
  EXPECT_EQ(d.format().rfind("test.lsys:3:1: error: turtle: ", 0), 0u) << d.format();

  result = grow_text("axiom: F!(1e13)\n");
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().loc, (SourceLoc{1, 1})) << result.error().format();

  // F is written by the axiom and by two productions: the file, and a note at each.
  result = grow_text("derivation length: 1\naxiom: F(1e300)B\nB -> F\nC -> FF\n");
  ASSERT_FALSE(result.ok());
  const Diagnostic& many = result.error();
  EXPECT_EQ(many.loc, (SourceLoc{0, 0})) << many.format();
  EXPECT_NE(many.message.find("exceeds the limit of 1e12 m"), std::string::npos) << many.format();
  ASSERT_EQ(many.notes.size(), 3u) << many.format();
  EXPECT_EQ(many.notes[0].loc, (SourceLoc{2, 1})) << many.format();
  EXPECT_EQ(many.notes[1].loc, (SourceLoc{3, 1})) << many.format();
  EXPECT_EQ(many.notes[2].loc, (SourceLoc{4, 1})) << many.format();
  EXPECT_EQ(many.notes[1].message, "a module 'F' is written here") << many.format();
}

TEST(TurtleErrors, FractionalMaterialIsAnErrorNamingTheModule) {
  const std::string message = grow_error("axiom: F'(1.5)F\n");
  EXPECT_NE(message.find("material"), std::string::npos) << message;
  EXPECT_NE(message.find("non-negative integer"), std::string::npos) << message;
  EXPECT_NE(message.find("'(1.5)"), std::string::npos) << message;
}

TEST(TurtleErrors, NegativeMaterialIsAnError) {
  const std::string message = grow_error("axiom: F'(-1)F\n");
  EXPECT_NE(message.find("non-negative integer"), std::string::npos) << message;
}

TEST(TurtleErrors, PositionThatOverflowsToInfinityIsAnError) {
  // Stopped at the coordinate limit (docs/limits.md), before the sum overflows.
  const std::string message = grow_error("axiom: F(1e308)F(1e308)\n");
  EXPECT_NE(message.find("position"), std::string::npos) << message;
  EXPECT_NE(message.find("limit"), std::string::npos) << message;
  EXPECT_NE(message.find("module 0"), std::string::npos) << message;  // the first F
}

TEST(TurtleErrors, MoveThatOverflowsWithSmallfIsAnErrorToo) {
  const std::string message = grow_error("axiom: f(1e308)f(1e308)F\n");
  EXPECT_NE(message.find("limit"), std::string::npos) << message;
}

TEST(TurtleErrors, AtTWithoutSusceptibilityIsAnError) {
  const std::string message = grow_error("tropism: 0 -1 0 0.2\naxiom: F@TF\n");
  EXPECT_NE(message.find("@T"), std::string::npos) << message;
  EXPECT_NE(message.find("susceptibility"), std::string::npos) << message;
}

// ---- limits ------------------------------------------------------------------------

TEST(TurtleLimits, MillionNestedBranchesGrowWithoutRecursion) {
  constexpr size_t kDepth = 1'000'000;
  std::string text = "axiom: ";
  text.reserve(text.size() + 3 * kDepth + 1);
  for (size_t i = 0; i < kDepth; ++i) text += "[F";
  text.append(kDepth, ']');
  text += '\n';
  const Skeleton skeleton = skeleton_of(text);
  ASSERT_EQ(skeleton.chains.size(), kDepth);
  EXPECT_EQ(skeleton.joints.size(), 2 * kDepth);
  EXPECT_EQ(skeleton.segment_count(), kDepth);
  // Chain i runs from (0, i) to (0, i + 1) and hangs from the end of chain i − 1.
  EXPECT_EQ(skeleton.chains[0].parent, std::nullopt);
  EXPECT_EQ(skeleton.chains[1].parent, parent(0, 1));
  const uint32_t last = kDepth - 1;
  EXPECT_EQ(skeleton.chains[last].parent, parent(last - 1, 1));
  EXPECT_EQ(position_at(skeleton, last, 0), (Position{0, static_cast<double>(last), 0}));
  EXPECT_EQ(position_at(skeleton, last, 1), (Position{0, static_cast<double>(kDepth), 0}));
}

// ---- progress and cancellation (core/util/progress.h) ---------------------------------

TEST(GrowProgress, DeriveInterpretAndTurtleReportInOrderEndingAtOne) {
  auto grammar = lsys::parse_grammar("derivation length: 14\naxiom: A\nA -> AB\nB -> A\nhomomorphism:\nA -> F\n"
                                     "B -> +F\n", "test.lsys", {});
  ASSERT_TRUE(grammar.ok()) << grammar.error().format();
  std::vector<double> fractions;
  std::vector<std::string> stages;
  lsys::DeriveOptions options;
  options.progress = Progress([&](double f, std::string_view stage) {
    fractions.push_back(f);
    if (stages.empty() || stages.back() != stage) stages.emplace_back(stage);
  });
  ASSERT_TRUE(grow(*grammar, options, "test.lsys", {}).ok());
  for (size_t i = 1; i < fractions.size(); ++i) EXPECT_LE(fractions[i - 1], fractions[i]);
  EXPECT_EQ(fractions.back(), 1.0);
  EXPECT_EQ(stages, (std::vector<std::string>{"derive", "interpret", "turtle"}));
}

TEST(GrowProgress, CancellingMidTurtleStopsWithTheCancelledResult) {
  // 2^18 F: the turtle checks the flag every 64 Ki modules.
  auto grammar = lsys::parse_grammar("derivation length: 18\naxiom: F\nF -> FF\n", "test.lsys", {});
  ASSERT_TRUE(grammar.ok());
  auto word = lsys::derive(*grammar);
  ASSERT_TRUE(word.ok());
  std::atomic<bool> cancel{false};
  double last = 0;
  const Progress progress([&](double f, std::string_view) {
    last = f;
    cancel.store(true);
  }, &cancel);
  Expected<Skeleton> sk = build_skeleton(*word, *grammar, nullptr, progress);
  EXPECT_TRUE(sk.cancelled());
  EXPECT_EQ(last, 0.25);  // the first chunk of four, then stopped
  EXPECT_TRUE(build_skeleton(*word, *grammar).ok());
}

// ---- Polygons and leaves (docs/spec/grammar.md `{ . }`, `G`; docs/spec/skeleton.md "Leaves") ---------------

TEST(TurtleLeaves, GrammarMdsPolygonIsOneLeafOnTheJointTheTurtleStoodOnAndfDoesNotEndTheChain) {
  const Skeleton sk = skeleton_of("angle: 45\naxiom: F{.-f.+f.+f.-|-f.+f.+f.}F\n");
  ASSERT_EQ(sk.leaves.size(), 1u);
  const Leaf& leaf = sk.leaves[0];
  EXPECT_EQ(leaf.joint, parent(0, 1));
  EXPECT_EQ(leaf.material, 0u);
  // One per '.', a '.' right after an f records nothing new, and the last vertex, back at the
  // first up to rounding, is dropped: six.
  ASSERT_EQ(leaf.vertices_m.size(), 6u);
  EXPECT_TRUE(near(leaf.vertices_m[0], {0, 1, 0}));  // '.' right after F: the joint's position
  for (const auto& v : leaf.vertices_m) EXPECT_NEAR(v[2], 0, kTolerance);  // turns about U: the XY plane
  EXPECT_FALSE(leaf_polygon_problem(leaf.vertices_m).has_value());
  // The f moves inside the polygon did not end chain 0: the last F continues it.
  ASSERT_EQ(sk.chains.size(), 1u);
  EXPECT_EQ(sk.chains[0].joint_count, 3u);
}

// ABOP Fig 1.25's leaf as the book types it: as in cpfg, an f inside a polygon records the
// turtle's new position. It is the dotted form's polygon, the same vertices in the same order.
TEST(TurtleLeaves, TheBooksUndottedLeafIsTheDottedFormsPolygon) {
  const Skeleton book = skeleton_of("angle: 22.5\naxiom: F{-f+f+f-|-f+f+f}F\n");
  const Skeleton dotted = skeleton_of("angle: 22.5\naxiom: F{.-f.+f.+f.-|-f.+f.+f.}F\n");
  ASSERT_EQ(book.leaves.size(), 1u);
  ASSERT_EQ(dotted.leaves.size(), 1u);
  const auto& a = book.leaves[0].vertices_m;
  const auto& b = dotted.leaves[0].vertices_m;
  ASSERT_EQ(a.size(), 6u);
  ASSERT_EQ(b.size(), 6u);
  for (size_t k = 0; k < a.size(); ++k) EXPECT_TRUE(near(a[k], b[k])) << "vertex " << k;
  // The petiole is the vertex nearest to where '{' opened: the joint at (0, 1, 0).
  EXPECT_TRUE(near(a[0], {0, 1, 0}));
  EXPECT_FALSE(leaf_polygon_problem(a).has_value());
  ASSERT_EQ(book.chains.size(), 1u);
  EXPECT_EQ(book.chains[0].joint_count, 3u);  // no f inside ended the chain
}

TEST(TurtleLeaves, InsideAPolygonFRecordsAVertexDrawsNoSegmentAndGRecordsNone) {
  const Skeleton sk = skeleton_of("angle: 90\naxiom: F{F+F+G(0.5)F}F\n");
  ASSERT_EQ(sk.leaves.size(), 1u);
  const auto& v = sk.leaves[0].vertices_m;
  ASSERT_EQ(v.size(), 3u);  // after each F; not after G
  // (0,2,0), (-1,2,0), (-1,0.5,0); the nearest to (0,1,0), where '{' opened, is the first.
  EXPECT_TRUE(near(v[0], {0, 2, 0}));
  EXPECT_TRUE(near(v[1], {-1, 2, 0}));
  EXPECT_TRUE(near(v[2], {-1, 0.5, 0}));
  ASSERT_EQ(sk.chains.size(), 1u);
  EXPECT_EQ(sk.segment_count(), 2u);  // the F before '{' and the one after '}'
}

TEST(TurtleLeaves, ThePetioleIsTheVertexNearestToWhereTheBraceOpenedInTheRecordedCyclicOrder) {
  // A unit square walked from the origin: f records (0,1,0), (-1,1,0), (-1,0,0), (0,0,0).
  // The last is where '{' opened, so it becomes the first; the cycle is kept.
  const Skeleton sk = skeleton_of("angle: 90\naxiom: {f+f+f+f}\n");
  ASSERT_EQ(sk.leaves.size(), 1u);
  const auto& v = sk.leaves[0].vertices_m;
  ASSERT_EQ(v.size(), 4u);
  EXPECT_TRUE(near(v[0], {0, 0, 0}));
  EXPECT_TRUE(near(v[1], {0, 1, 0}));
  EXPECT_TRUE(near(v[2], {-1, 1, 0}));
  EXPECT_TRUE(near(v[3], {-1, 0, 0}));
}

TEST(TurtleLeaves, TheMaterialIsTheOneInForceAtTheClosingBrace) {
  const Skeleton sk = skeleton_of("axiom: F'(1){.f.+f.'(3)}\n");
  ASSERT_EQ(sk.leaves.size(), 1u);
  EXPECT_EQ(sk.leaves[0].material, 3u);
}

TEST(TurtleLeaves, APolygonBeforeTheFirstFHangsFromNoJoint) {
  const Skeleton sk = skeleton_of("axiom: {.f.+f.}\n");
  ASSERT_EQ(sk.leaves.size(), 1u);
  EXPECT_EQ(sk.leaves[0].joint, std::nullopt);
  EXPECT_TRUE(sk.chains.empty());
}

TEST(TurtleLeaves, PolygonsNestAndTheInnerClosesFirst) {
  const Skeleton sk = skeleton_of("axiom: F{.f.{.+f.+f.}f.}\n");
  ASSERT_EQ(sk.leaves.size(), 2u);
  EXPECT_EQ(sk.leaves[0].vertices_m.size(), 3u);  // the inner one
  EXPECT_TRUE(near(sk.leaves[0].vertices_m[0], {0, 2, 0}));
  EXPECT_EQ(sk.leaves[1].vertices_m.size(), 3u);
  EXPECT_TRUE(near(sk.leaves[1].vertices_m[0], {0, 1, 0}));
  EXPECT_EQ(sk.leaves[0].joint, sk.leaves[1].joint);
}

TEST(TurtleLeaves, InABranchTheLeafHangsFromTheBranchPoint) {
  const Skeleton sk = skeleton_of("axiom: FF[+F{.f.+f.}]F\n");
  ASSERT_EQ(sk.leaves.size(), 1u);
  EXPECT_EQ(sk.leaves[0].joint, parent(1, 1));  // the lateral chain's tip
}

TEST(TurtleLeaves, GMovesWithoutDrawingAndWithoutEndingTheChain) {
  const Skeleton sk = skeleton_of("axiom: FG(2)F\n");
  ASSERT_EQ(sk.chains.size(), 1u);
  ASSERT_EQ(sk.chains[0].joint_count, 3u);
  EXPECT_TRUE(near(position_at(sk, 0, 2), {0, 4, 0}));
  EXPECT_EQ(sk.segment_count(), 2u);  // the G gap is no segment of its own: F's segment spans it
}

TEST(TurtleLeaves, PolygonsThatCannotBeLeavesAreErrorsNamingTheClosingModule) {
  struct Bad {
    const char* word;
    const char* says;
    const char* module;  // "module N (...)" of the interpreted word
  };
  const Bad bad[] = {
      {"F{.f.}", "at least 3 distinct vertices, this polygon has 2", "module 5 (})"},
      {"F{...}", "at least 3 distinct vertices, this polygon has 1", "module 5 (})"},
      {"{.f.f.}", "no area", "module 6 (})"},
      {"{.f.+f.+f&f.}", "not planar: vertex", "module 12 (})"},
      {"F}", "'}' without matching '{'", "module 1 (})"},
      {"F{.f.+f.", "'{' without matching '}'", "module 1 ({)"},
  };
  for (const Bad& b : bad) {
    const std::string message = grow_error(std::string("angle: 90\naxiom: ") + b.word + "\n");
    EXPECT_NE(message.find("test.lsys"), std::string::npos) << b.word << ": " << message;
    EXPECT_NE(message.find(b.says), std::string::npos) << b.word << ": " << message;
    EXPECT_NE(message.find(b.module), std::string::npos) << b.word << ": " << message;
  }
}

// ---- cpfg files (docs/cpfg.md): the symbols of the CPFG manual's chapter 6 -------------

std::string cpfg(std::string_view axiom) { return "Lsystem: 1\nAxiom: " + std::string(axiom) + "\nendlsystem\n"; }

TEST(TurtleCpfg, TheDefaultAngleIsTheViewFilesFortyFiveDegrees) {
  const Skeleton sk = skeleton_of(cpfg("+F"));
  ASSERT_EQ(sk.joints.size(), 2u);
  const double h = std::sqrt(0.5);
  EXPECT_TRUE(near(position(sk.joints[1]), {-h, h, 0}));  // + turns H toward L = -X
}

TEST(TurtleCpfg, GDrawsLikeFAndgMovesLikef) {
  // In sylva's format G moves without drawing; in cpfg it draws (manual 6.1).
  const Skeleton sk = skeleton_of(cpfg("FGgF"));
  ASSERT_EQ(sk.chains.size(), 2u);  // g ends the chain as f does
  EXPECT_EQ(sk.chains[0].joint_count, 3u);
  EXPECT_TRUE(near(position_at(sk, 0, 2), {0, 2, 0}));
  EXPECT_TRUE(near(position_at(sk, 1, 0), {0, 3, 0}));
  // Inside a polygon, G and g record no vertex; F and f do.
  const Skeleton leaf = skeleton_of("Lsystem: 1\nAxiom: {.f+(90)g+(90)f+(90)f}\nendlsystem\n");
  ASSERT_EQ(leaf.leaves.size(), 1u);
  // The start, after the first f, after the second; the third lands back on the start (dropped).
  EXPECT_EQ(leaf.leaves[0].vertices_m.size(), 3u);
}

// A % left in a cpfg word (cpfg cuts it a step later) is passed over, as cpfg's default
// `interpretation past %: on`; off, the turtle skips the rest of its branch.
TEST(TurtleCpfg, APercentLeftInTheWordIsPassedOverUnlessInterpretationPastCutIsOff) {
  auto unstepped = [](std::string_view axiom) {
    return "Lsystem: 1\nderivation length: 0\nAxiom: " + std::string(axiom) + "\nendlsystem\n";
  };
  const std::string text = unstepped("F[+F%F(2)[F]F]F(3)");
  const Skeleton past = skeleton_of(text), all = skeleton_of(unstepped("F[+FF(2)[F]F]F(3)"));
  EXPECT_TRUE(past.joints == all.joints && past.chains == all.chains);
  auto g = lsys::parse_grammar(text, "test.l", {});
  ASSERT_TRUE(g.ok()) << g.error().format();
  g->turtle.interpret_past_cut = false;
  auto off = grow(*g, {}, "test.l", {});
  ASSERT_TRUE(off.ok()) << off.error().format();
  const Skeleton cut = skeleton_of(unstepped("F[+F]F(3)"));  // the branch's F(2)[F]F after % are cut
  EXPECT_TRUE(off->skeleton.joints == cut.joints && off->skeleton.chains == cut.chains);
  EXPECT_LT(off->skeleton.joints.size(), past.joints.size());
}

// ?(label, s) draws the sub-L-system's modules s times larger, widths too, up to its $ (cpfg's
// interpret.c); the scale stacks with nested calls and an unmatched $ changes nothing.
TEST(TurtleCpfg, ASubLSystemCallScalesTheTurtleUpToItsEnd) {
  const Skeleton sk = skeleton_of(
      "Lsystem: 1\nderivation length: 0\nAxiom: #(2)F(1)?(2,0.5)F(1)?(2,0.5)F(1)$F(1)$F(1)$F(1)\nendlsystem\n"
      "Lsystem: 2\nAxiom: F\nendlsystem\n");
  ASSERT_EQ(sk.joints.size(), 7u);
  const double y[] = {0, 1, 1.5, 1.75, 2.25, 3.25, 4.25};
  for (size_t k = 0; k < 7; ++k) EXPECT_NEAR(sk.joints[k].position_m[1], y[k], 1e-12) << k;
  EXPECT_NEAR(sk.joints[2].radius_m, sk.joints[1].radius_m * 0.5, 1e-15);
  EXPECT_NEAR(sk.joints[3].radius_m, sk.joints[1].radius_m * 0.25, 1e-15);
  EXPECT_NEAR(sk.joints[6].radius_m, sk.joints[1].radius_m, 1e-15);
}

// L-system defined surfaces (CPFG manual 6.7.2, cpfg's patches.c): @PS(id, basis), a
// control point per @PC(id, r, c) where the turtle stands, @PD(id, s, t) drawing s x t cells
// as leaves. Control points on an even grid: Bézier spans the grid (P = (3v, 3u)); a
// B-spline spans its middle third (P = (1 + v, 1 + u)).
TEST(TurtleCpfg, AnLSystemDefinedSurfaceIsDrawnFromItsControlPoints) {
  auto patch = [](int basis, const std::string& draw) {
    std::string axiom = "@PS(1," + std::to_string(basis) + ")";
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c)
        axiom += "@M(" + std::to_string(c) + "," + std::to_string(r) + ",0)@PC(1," + std::to_string(r) + "," +
                 std::to_string(c) + ")";
    return "Lsystem: 1\nderivation length: 0\nAxiom: " + axiom + draw + "\nendlsystem\n";
  };
  const Skeleton bezier = skeleton_of(patch(1, "@PD(1,2,2)"));
  ASSERT_EQ(bezier.leaves.size(), 4u);
  const auto& v = bezier.leaves[0].vertices_m;
  ASSERT_EQ(v.size(), 4u);
  const double expected[4][2] = {{0, 0}, {0, 1.5}, {1.5, 1.5}, {1.5, 0}};
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(v[k][0], expected[k][0], 1e-12) << k;
    EXPECT_NEAR(v[k][1], expected[k][1], 1e-12) << k;
  }
  const Skeleton bspline = skeleton_of(patch(2, "@PD(1,1,1)"));
  ASSERT_EQ(bspline.leaves.size(), 1u);
  EXPECT_NEAR(bspline.leaves[0].vertices_m[0][0], 1, 1e-12);
  EXPECT_NEAR(bspline.leaves[0].vertices_m[2][1], 2, 1e-12);
  EXPECT_EQ(skeleton_of(patch(1, "")).leaves.size(), 0u) << "not drawn without @PD";
  EXPECT_EQ(skeleton_of(patch(1, "@PD(1)")).leaves.size(), 25u) << "5 x 5 cells by default";
  EXPECT_EQ(skeleton_of(cpfg("@PS(1)@PC(1,0,0)@PD(1,2,2)")).leaves.size(), 0u) << "points unset: nothing drawn";
  EXPECT_NE(grow_error(cpfg("@PS(1)@PC(1,4,0)")).find("row and column are 0 to 3"), std::string::npos);
}

// @bc(d): a circle's boundary in the H-L plane, a closed chain as wide as the line width;
// the turtle does not move. No line width: nothing drawn.
TEST(TurtleCpfg, ACircleBoundaryIsAClosedChainAroundTheTurtle) {
  const Skeleton sk = skeleton_of(cpfg("f(1)#(2)@bc(4)F(1)"));
  ASSERT_EQ(sk.chains.size(), 2u);
  ASSERT_EQ(sk.joints.size(), 25u + 2u);
  for (size_t k = 0; k < 25; ++k) {
    const Joint& j = sk.joints[k];
    EXPECT_NEAR(std::hypot(j.position_m[0], j.position_m[1] - 1, j.position_m[2]), 2, 1e-12) << k;
    EXPECT_NEAR(j.radius_m, 0.1, 1e-15);
  }
  EXPECT_EQ(sk.joints[0].position_m[1], sk.joints[24].position_m[1]);
  EXPECT_NEAR(sk.joints[26].position_m[1], 2, 1e-12) << "F goes on from where the turtle stood";
  EXPECT_EQ(skeleton_of(cpfg("#(0)@bc(4)")).chains.size(), 0u);
  // @; and @, (the back side's colour) draw nothing and change nothing drawn.
  EXPECT_TRUE(skeleton_of(cpfg("F@;F@,(3)F")).joints == skeleton_of(cpfg("FFF")).joints);
}

TEST(TurtleCpfg, SemicolonAndCommaStepTheColourIndexOrSetIt) {
  const Skeleton sk = skeleton_of(cpfg("F;F;;F,F;(7)F,(2)F"));
  ASSERT_EQ(sk.joints.size(), 7u);
  const uint32_t expected[] = {0, 0, 1, 3, 2, 7, 2};  // a joint has the material of the segment ending at it
  for (size_t k = 0; k < 7; ++k) EXPECT_EQ(sk.joints[k].material, expected[k]) << k;
  // As cpfg's interpret.c: a parameter is truncated toward zero, and an index stepped past
  // either end of the 256-entry colour map comes round once.
  const Skeleton wrap = skeleton_of(cpfg("F,F;(255)F;F;(256.9)F;(7.6)F,(-1.5)F"));
  ASSERT_EQ(wrap.joints.size(), 8u);
  const uint32_t wrapped[] = {0, 255, 255, 0, 0, 7, 255};
  for (size_t k = 0; k < 7; ++k) EXPECT_EQ(wrap.joints[k + 1].material, wrapped[k]) << k;
  EXPECT_NE(grow_error(cpfg(";(-300)F")).find("colour index"), std::string::npos);
}

TEST(TurtleCpfg, HashAndBangStepTheLineWidthOrSetItAndARadiusIsWidthTimesTheScale) {
  // The initial line width is 1: a radius of width_scale (0.05 m). !(4) sets the width to 4:
  // 0.2 m. Without a parameter they add and take the line width increment, 0 by default.
  const Skeleton sk = skeleton_of(cpfg("F!(4)F#F#(0.5)F!F"));
  ASSERT_EQ(sk.joints.size(), 6u);
  EXPECT_DOUBLE_EQ(sk.joints[0].radius_m, 0.05);
  EXPECT_DOUBLE_EQ(sk.joints[2].radius_m, 0.2);
  EXPECT_DOUBLE_EQ(sk.joints[3].radius_m, 0.2);
  EXPECT_DOUBLE_EQ(sk.joints[4].radius_m, 0.025);
  EXPECT_DOUBLE_EQ(sk.joints[5].radius_m, 0.025);
  EXPECT_NE(grow_error(cpfg("!(-1)F")).find("line width"), std::string::npos);
}

TEST(TurtleCpfg, AtMSetsThePositionAndAtVLevelsTheTurtle) {
  const Skeleton sk = skeleton_of(cpfg("F@M(3,0,0)F"));
  ASSERT_EQ(sk.chains.size(), 2u);
  EXPECT_TRUE(near(position_at(sk, 1, 0), {3, 0, 0}));
  EXPECT_TRUE(near(position_at(sk, 1, 1), {3, 1, 0}));
  // @v as $: after a roll and a pitch, L is horizontal again.
  const Skeleton level = skeleton_of(cpfg("&(30)/(40)@v+(90)F"));
  ASSERT_EQ(level.joints.size(), 2u);
  EXPECT_NEAR(level.joints[1].position_m[1], 0, kTolerance);  // + turned H within the horizontal
}

// @c(d) (CPFG manual 6.6): a disc of diameter d in the plane of H and L, a leaf hung from the
// joint the turtle stands on, in the current colour; @O(d): a sphere of diameter d around the
// turtle, a chain of its own of 16 frusta from pole to pole (tips at both), hung from that
// joint; without a parameter the diameter is the line width drawn. Neither moves the turtle.
TEST(TurtleCpfg, AtCDrawsADiscAndAtOASphereWhereTheTurtleStands) {
  const Skeleton sk = skeleton_of(cpfg("F(1)@O(1);(2)@c(0.5)F(1)+(90)@O"));
  ASSERT_EQ(sk.chains.size(), 3u);
  // The stem goes on through both: one chain of three joints.
  EXPECT_EQ(sk.chains[0].joint_count, 3u);
  EXPECT_TRUE(near(position_at(sk, 0, 2), {0, 2, 0}));
  // The first sphere: radius 0.5 around (0, 1, 0), along H = +y, hung from joint 1.
  const Chain& sphere = sk.chains[1];
  ASSERT_TRUE(sphere.parent);
  EXPECT_EQ(*sphere.parent, (ChainParent{0, 1}));
  ASSERT_EQ(sphere.joint_count, 17u);
  double widest = 0;
  for (uint32_t k = 0; k < sphere.joint_count; ++k) {
    const Joint& j = sk.joints[sphere.first_joint + k];
    const double from_centre = std::hypot(j.position_m[0], j.position_m[1] - 1, j.position_m[2]);
    // Every ring lies on the sphere: its distance along H and its radius make 0.5.
    EXPECT_NEAR(std::hypot(from_centre, j.radius_m), 0.5, 1e-12) << k;
    widest = std::max(widest, j.radius_m);
  }
  EXPECT_EQ(sk.joints[sphere.first_joint].radius_m, 0.0);
  EXPECT_EQ(sk.joints[sphere.first_joint + 16].radius_m, 0.0);
  EXPECT_NEAR(widest, 0.5, 1e-12);
  EXPECT_TRUE(near(position_at(sk, 1, 0), {0, 0.5, 0}));
  EXPECT_TRUE(near(position_at(sk, 1, 16), {0, 1.5, 0}));
  // The disc: 24 vertices at 0.25 from (0, 1, 0) in the xy plane (H = +y, L = −x), colour 2.
  ASSERT_EQ(sk.leaves.size(), 1u);
  const Leaf& disc = sk.leaves[0];
  EXPECT_EQ(disc.material, 2u);
  ASSERT_TRUE(disc.joint);
  EXPECT_EQ(*disc.joint, (ChainParent{0, 1}));
  ASSERT_EQ(disc.vertices_m.size(), 24u);
  for (const auto& v : disc.vertices_m) {
    EXPECT_NEAR(std::hypot(v[0], v[1] - 1), 0.25, 1e-12);
    EXPECT_NEAR(v[2], 0, 1e-12);
  }
  // Without a parameter: the line width's diameter (radius 0.05, a cpfg file's width 1),
  // along the turned heading, from the stem's tip.
  const Chain& small = sk.chains[2];
  EXPECT_EQ(*small.parent, (ChainParent{0, 2}));
  double widest_small = 0;
  for (uint32_t k = 0; k < small.joint_count; ++k) widest_small = std::max(widest_small, sk.joints[small.first_joint + k].radius_m);
  EXPECT_NEAR(widest_small, 0.05, 1e-12);
  EXPECT_TRUE(near(position_at(sk, 2, 0), {0.05, 2, 0}));  // + turned H from +y to −x; the pole behind is +x
  // A diameter of 0 or below draws nothing, as in cpfg (a rounding error's -1e-7 included);
  // one that is not finite is an error. @o (a disc facing the camera) is a sphere: it shows
  // as a disc of its diameter from every camera.
  EXPECT_EQ(skeleton_of(cpfg("F@O(-1e-7)F")).chains.size(), 1u);
  EXPECT_NE(grow_error(cpfg("F@O(1e300)")).find("diameter"), std::string::npos);
  const Skeleton screen = skeleton_of(cpfg("F(1)@o(1)"));
  const Skeleton ball = skeleton_of(cpfg("F(1)@O(1)"));
  EXPECT_EQ(screen.chains.size(), 2u);
  EXPECT_EQ(screen.joints, ball.joints);
}

// The turtle's scale (CPFG manual 6.3, as cpfg's interpret.c and blackbox.c apply it): @D(s)
// sets it, @Di(s) multiplies and @Dd(s) divides it by s (by the view file's scale multiplier
// without one); it multiplies every move's length and every width set or stepped, and @c /
// @O's diameters; brackets keep it.
TEST(TurtleCpfg, AtDScalesLengthsAndWidthsAndBracketsKeepTheScale) {
  const Skeleton sk = skeleton_of(cpfg("F(1)@D(2)F(1)[@Di(0.25)F(2)]F(1)@Dd(4)!(2)F(1)"));
  // Stem: 1, then 2 (scale 2), then 2 after the branch (its 0.5 stayed inside), then 0.5.
  ASSERT_EQ(sk.chains.size(), 2u);
  EXPECT_TRUE(near(position_at(sk, 0, 1), {0, 1, 0}));
  EXPECT_TRUE(near(position_at(sk, 0, 2), {0, 3, 0}));
  EXPECT_TRUE(near(position_at(sk, 0, 3), {0, 5, 0}));
  EXPECT_TRUE(near(position_at(sk, 0, 4), {0, 5.5, 0}));
  EXPECT_TRUE(near(position_at(sk, 1, 1), {0, 4, 0}));  // 2 × 0.5 from y = 3
  // !(2) at scale 0.5: a width of 1, radius 0.05.
  EXPECT_DOUBLE_EQ(sk.joints[sk.chains[0].first_joint + 4].radius_m, 2 * 0.05 * 0.5);
  const Skeleton ball = skeleton_of(cpfg("@D(3)@O(1)"));
  double widest = 0;
  for (const Joint& j : ball.joints) widest = std::max(widest, j.radius_m);
  EXPECT_NEAR(widest, 1.5, 1e-12);
  EXPECT_NE(grow_error(cpfg("F@DF")).find("@D needs the scale"), std::string::npos);
  EXPECT_NE(grow_error(cpfg("F@Di(0)F")).find("must not be 0"), std::string::npos);
}

// ---- predefined surfaces (CPFG manual 6.7.1, 8.1.5; docs/cpfg.md "Surfaces") -----------

// A vlab object in a fresh folder: `plant.l` with `axiom`, its view file `view`, and `files`
// (name, text) beside them.
sylva::Expected<GrowResult> grow_object(const std::string& axiom, const std::string& view,
                                        const std::vector<std::pair<std::string, std::string>>& files) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("sylva_object_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "specifications") << "generate:\n\tcpfg plant.l plant.v\n";
  std::ofstream(dir / "plant.l") << "Lsystem: 1\nAxiom: " << axiom << "\nendlsystem\n";
  std::ofstream(dir / "plant.v") << view;
  for (const auto& [name, text] : files) std::ofstream(dir / name) << text;
  auto g = lsys::load_grammar(dir.string());
  fs::remove_all(dir);
  if (!g.ok()) return g.error();
  return grow(*g, {}, "plant", {});
}

// ... with `leaf.s`, one flat Bézier patch over the unit square (control points at thirds),
// its contact point at the middle of its bottom edge, heading +y, up +z, SIZE 1.
sylva::Expected<GrowResult> grow_with_surface(const std::string& axiom, const std::string& view) {
  std::string s = "0 1 0 1 0 0\nCONTACT POINT  X: 0.5 Y: 0 Z: 0\nEND POINT  X: 0.5 Y: 1 Z: 0\n"
                  "HEADING  X: 0 Y: 1 Z: 0\nUP  X: 0 Y: 0 Z: 1\nSIZE: 1\nmiddle\n"
                  "TOP COLOR: 0 DIFFUSE: 0.5 BOTTOM COLOR: 0 DIFFUSE: 0.5\nAL: ~ A: ~ AR: ~\nL: ~ R: ~\nBL: ~ B: ~ BR: ~\n";
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) s += std::to_string(j / 3.0) + " " + std::to_string(i / 3.0) + " 0  ";
    s += "\n";
  }
  return grow_object(axiom, view, {{"leaf.s", s}});
}

double polygon_area(const Leaf& leaf) {
  glm::dvec3 sum(0);
  const auto& v = leaf.vertices_m;
  for (size_t k = 0; k < v.size(); ++k) {
    const auto& a = v[k];
    const auto& b = v[(k + 1) % v.size()];
    sum += glm::cross(glm::dvec3(a[0], a[1], a[2]), glm::dvec3(b[0], b[1], b[2]));
  }
  return 0.5 * glm::length(sum);
}

// `~l(s)` draws the view file's surface `l` where the turtle stands: the file's SIZE made the
// view file's size, times s; its x along cpfg's left (H × U: −x for the first turtle), y along
// H, z along U; one leaf per cell of the s × t grid a patch is cut into.
TEST(TurtleCpfg, TildeDrawsTheViewFilesSurfaceAsLeavesWhereTheTurtleStands) {
  auto grown = grow_with_surface("F(1);(3)~l(1.5)", "surface: l leaf.s 2 4 3\n");
  ASSERT_TRUE(grown.ok()) << grown.error().format();
  const Skeleton& sk = grown->skeleton;
  ASSERT_EQ(sk.leaves.size(), 12u);  // 4 × 3 cells, each flat: one quad
  double area = 0, lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
  for (const Leaf& leaf : sk.leaves) {
    EXPECT_EQ(leaf.material, 3u);
    ASSERT_TRUE(leaf.joint);
    EXPECT_EQ(*leaf.joint, (ChainParent{0, 1}));
    area += polygon_area(leaf);
    for (const auto& v : leaf.vertices_m)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
  }
  // The unit square, scaled by size 2 / SIZE 1 and by 1.5: 3 × 3, from the contact point at
  // the turtle (0, 1, 0) up along H, centred on it across.
  EXPECT_NEAR(area, 9, 1e-9);
  EXPECT_NEAR(lo[0], -1.5, 1e-9);
  EXPECT_NEAR(hi[0], 1.5, 1e-9);
  EXPECT_NEAR(lo[1], 1, 1e-9);
  EXPECT_NEAR(hi[1], 4, 1e-9);
  EXPECT_NEAR(lo[2], 0, 1e-9);
  EXPECT_NEAR(hi[2], 0, 1e-9);
  // Three parameters scale x, y and z apart; the file's cells are cpfg's 5 × 5 without counts;
  // a surface the view file does not name draws nothing, as in cpfg.
  auto stretched = grow_with_surface("~l(1,2,1)~q(1)", "surface: l leaf.s 1\n");
  ASSERT_TRUE(stretched.ok()) << stretched.error().format();
  ASSERT_EQ(stretched->skeleton.leaves.size(), 25u);
  double stretched_area = 0, top = 0;
  for (const Leaf& leaf : stretched->skeleton.leaves) {
    stretched_area += polygon_area(leaf);
    for (const auto& v : leaf.vertices_m) top = std::max(top, v[1]);
  }
  EXPECT_NEAR(stretched_area, 2, 1e-9);
  EXPECT_NEAR(top, 2, 1e-9);
  // A surface file that cannot be read is an error at the view file's line, the file's own
  // error in a note.
  auto missing = grow_with_surface("~l", "angle factor: 8\nsurface: l nothing.s 1\n");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().loc.line, 2u);
  EXPECT_NE(missing.error().message.find("surface file 'nothing.s'"), std::string::npos) << missing.error().format();
  EXPECT_FALSE(missing.error().notes.empty());
}

// A tsurface (CPFG manual 8.1.5 `tsurface: id file size`, 8.4; cpfg's tsurfaces.c): the file's
// triangles, their points times the size (no contact point), drawn by ~id as surfaces are
// (x along L, y along H, z along cpfg's up, sylva's −U), one leaf a triangle. The manual's
// two triangles make a unit diamond; a third stands in the plane of L and U.
TEST(TurtleCpfg, TildeDrawsATsurfacesTrianglesScaledByItsSize) {
  const std::string diamond =
      "name leaf grid 20 20 20\ntriangle\n-0.5 1 0 0 0 1\n 0.0 2 0 0 0 1\n 0.5 1 0 0 0 1\n"
      "triangle\n0.5,1,0, 0,0,1, 0.5,1.0\n0.0 0 0 0 0 1 0 0.5 7 8\n-0.5 1 0 0 0 1 0.5 0.0\n"
      "triangle 0 0 0\n1 0 0\n0 0 0.5\n";
  auto grown = grow_object("F(1);(3)~l(1.5)", "tsurface: l leaf.ray 2\n", {{"leaf.ray", diamond}});
  ASSERT_TRUE(grown.ok()) << grown.error().format();
  const Skeleton& sk = grown->skeleton;
  ASSERT_EQ(sk.leaves.size(), 3u);
  double area = 0, lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
  for (const Leaf& leaf : sk.leaves) {
    EXPECT_EQ(leaf.material, 3u);
    EXPECT_EQ(leaf.vertices_m.size(), 3u);
    area += polygon_area(leaf);
    for (const auto& v : leaf.vertices_m)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
  }
  // Scaled by 2 × 1.5: the diamond 9, the third triangle 3 × 1.5 / 2; from the turtle at (0, 1, 0).
  EXPECT_NEAR(area, 9 + 2.25, 1e-9);
  EXPECT_NEAR(lo[0], -3, 1e-9);  // the file's +x is cpfg's left: −x for the first turtle
  EXPECT_NEAR(hi[0], 1.5, 1e-9);
  EXPECT_NEAR(lo[1], 1, 1e-9);
  EXPECT_NEAR(hi[1], 7, 1e-9);
  EXPECT_NEAR(lo[2], -1.5, 1e-9);
  EXPECT_NEAR(hi[2], 0, 1e-9);
  // A word where a number belongs, an unfinished triangle, none at all: errors at their place
  // in the file, under the view file's line; an id a surface has already.
  auto bad = [&](const std::string& file, const std::string& view = "tsurface: l leaf.ray 1\n") {
    return grow_object("~l", view, {{"leaf.ray", file}});
  };
  auto word = bad("triangle\n1 2 3\n1 x 3\n");
  ASSERT_FALSE(word.ok());
  EXPECT_EQ(word.error().loc.line, 1u);
  ASSERT_FALSE(word.error().notes.empty());
  EXPECT_EQ(word.error().notes[0].loc.line, 3u);
  EXPECT_EQ(word.error().notes[0].loc.column, 3u);
  EXPECT_NE(word.error().notes[0].message.find("expected a number"), std::string::npos);
  auto short_one = bad("triangle\n1 2 3\n1 2 3\n");
  ASSERT_FALSE(short_one.ok());
  EXPECT_NE(short_one.error().notes[0].message.find("fewer than three vertices"), std::string::npos);
  auto none = bad("name leaf\n");
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().notes[0].message.find("at least one 'triangle'"), std::string::npos);
  auto twice = bad("triangle 0 0 0\n1 0 0\n0 1 0\n", "tsurface: l leaf.ray 1\ntsurface: l leaf.ray 2\n");
  ASSERT_FALSE(twice.ok());
  EXPECT_EQ(twice.error().loc.line, 2u);
  EXPECT_NE(twice.error().message.find("a second surface with the id 'l'"), std::string::npos);
}

// cpfg's double-sided surfaces (CPFG manual 6.3, 8.1.1; docs/cpfg.md "Two-sided surfaces"):
// with `initial color: front back` and a material file, each leaf keeps the turtle's colour
// as its (front) material and the back colour as its back material, its outline turned round
// (vertex 0 kept) so that its normal points to cpfg's front — the side cpfg's GL, which
// draws clockwise faces as front (glFrontFace(GL_CW)), shows the front colour on: for the
// first turtle's square in the plane of H and L, the side of cpfg's up (sylva's −U, −z). @;
// and @, step the back colour by the second colour increment, or set it.
TEST(TurtleCpfg, DoubleSidedSurfacesGiveEachLeafTheBackColourAsItsBackMaterial) {
  const std::string axiom = "{.f.+f.+f.}@;{.f.+f.+f.}@,(20)@,;(4){.f.+f.+f.}";
  const std::string view = "angle factor: 4\ninitial color: 3 7\ncolor increment: 1 2\n";
  const std::vector<std::pair<std::string, std::string>> material_file = {
      {"specifications", "generate:\n\tcpfg -M plant.mat plant.l plant.v\n"}, {"plant.mat", std::string(15, '\0')}};
  auto two = grow_object(axiom, view, material_file);
  ASSERT_TRUE(two.ok()) << two.error().format();
  auto plain = grow_object(axiom, view, {});  // no material file: one colour on both sides, as cpfg
  ASSERT_TRUE(plain.ok()) << plain.error().format();
  const auto& leaves = two->skeleton.leaves;
  ASSERT_EQ(leaves.size(), 3u);
  ASSERT_EQ(plain->skeleton.leaves.size(), 3u);
  const uint32_t front[3] = {3, 3, 4}, back[3] = {7, 9, 18};
  for (size_t l = 0; l < 3; ++l) {
    EXPECT_EQ(leaves[l].material, front[l]) << l;
    ASSERT_TRUE(leaves[l].back_material) << l;
    EXPECT_EQ(*leaves[l].back_material, back[l]) << l;
    const Leaf& one = plain->skeleton.leaves[l];
    EXPECT_EQ(one.material, front[l]);
    EXPECT_FALSE(one.back_material);
    // The same outline from the same vertex 0, the other way round.
    auto turned = one.vertices_m;
    std::reverse(turned.begin() + 1, turned.end());
    EXPECT_EQ(leaves[l].vertices_m, turned) << l;
    EXPECT_LT(polygon_newell_normal(leaves[l].vertices_m).z, 0) << "the normal toward cpfg's up";
    EXPECT_GT(polygon_newell_normal(one.vertices_m).z, 0);
  }
}

// A generalized cylinder with a contour (CPFG manual 6.7.3 @#(id), 8.1.5 `contour:`; cpfg's
// make_contour): the contour swept along the curve, x along cpfg's up (sylva's −U), times the
// radius, as polygon leaves between neighbouring rings instead of frusta. An open straight
// contour along x (control points at −3, −1, 1, 3: its B-spline runs from −1 to 1) makes a flat
// ribbon in the plane of H and U.
TEST(TurtleCpfg, AContourIsSweptAlongTheCylinderAsLeaves) {
  const std::string flat = "cver 1 3\nname: flat\npoints: 4 4\ntype: or\nsamples: 8\n"
                           "-3 0 0 1\n-1 0 0 1\n1 0 0 1\n3 0 0 1\n";
  auto grown = grow_object("@#(1) @Gs f(2) @Ge(4)", "initial line width: 1 shaded\ncontour: 1 flat.con\n",
                           {{"flat.con", flat}});
  ASSERT_TRUE(grown.ok()) << grown.error().format();
  const Skeleton& sk = grown->skeleton;
  EXPECT_TRUE(sk.chains.empty()) << "a contour's cylinder draws no frusta";
  ASSERT_EQ(sk.leaves.size(), 32u);  // 8 sides (cpfg's default) × 4 strips, each flat
  double area = 0, lo_z = 1e9, hi_z = -1e9;
  for (const Leaf& leaf : sk.leaves) {
    area += polygon_area(leaf);
    for (const auto& v : leaf.vertices_m) {
      EXPECT_NEAR(v[0], 0, 1e-9);
      lo_z = std::min(lo_z, v[2]), hi_z = std::max(hi_z, v[2]);
    }
  }
  // cpfg's partial lengths stop a tenth of a parameter unit before an open contour's end
  // (general.c: t < segments), so the ribbon runs from x = −1 to 0.8: 0.9 wide, x = −1 at +z.
  EXPECT_NEAR(area, 2 * 0.9, 1e-9);
  EXPECT_NEAR(lo_z, -0.4, 1e-9);
  EXPECT_NEAR(hi_z, 0.5, 1e-9);
  // `contour sides:` and @!(n) set the points around; @#(0) is the circle: frusta again.
  auto sides = grow_object("@!(4) @#(1) @Gs f(2) @Ge(4)", "initial line width: 1 shaded\ncontour: 1 flat.con\n",
                           {{"flat.con", flat}});
  ASSERT_TRUE(sides.ok());
  EXPECT_EQ(sides->skeleton.leaves.size(), 16u);
  auto round = grow_object("@#(1) @#(0) @Gs f(2) @Ge(4)", "contour: 1 flat.con\n", {{"flat.con", flat}});
  ASSERT_TRUE(round.ok());
  EXPECT_EQ(round->skeleton.chains.size(), 1u);
  EXPECT_TRUE(round->skeleton.leaves.empty());
  // A contour the view file does not name is an error at the module; a malformed file at its line.
  auto none = grow_object("@#(2) @Gs f(2) @Ge(4)", "contour: 1 flat.con\n", {{"flat.con", flat}});
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("names no contour"), std::string::npos) << none.error().format();
  auto bad = grow_object("F", "contour: 1 flat.con\n", {{"flat.con", "cver 1 3\nname: x\npoints: 4 4\ntype: or\n1 2\n"}});
  ASSERT_FALSE(bad.ok());
  ASSERT_EQ(bad.error().notes.size(), 1u);
  EXPECT_EQ(bad.error().notes[0].loc.line, 5u);
}

// A closed contour is sampled by arc length, its first point turned onto +x, its last the first.
TEST(TurtleCpfg, AClosedContourIsSampledEvenlyByArcLength) {
  lsys::CpfgContour square;
  square.closed = true;
  square.control = {{1, 1, 0}, {-1, 1, 0}, {-1, -1, 0}, {1, -1, 0}};  // a rounded square, symmetric
  const auto pts = square.sample(16);
  ASSERT_EQ(pts.size(), 17u);
  EXPECT_EQ(pts.front(), pts.back());
  EXPECT_NEAR(pts[0][1], 0, 1e-6);
  EXPECT_GT(pts[0][0], 0);
  std::vector<double> steps;
  for (size_t i = 0; i + 1 < pts.size(); ++i) steps.push_back(std::hypot(pts[i + 1][0] - pts[i][0], pts[i + 1][1] - pts[i][1]));
  const auto [lo, hi] = std::minmax_element(steps.begin(), steps.end());
  EXPECT_LT(*hi / *lo, 1.05) << "chords of equal arcs on a symmetric curve";
}

// @Gr (CPFG manual 6.7.3, cpfg's interpolate_connection): the radius and the curve's parameter
// along a piece follow a Hermite curve with the radius tangents (angle, length); without them
// the radius changes linearly. Tangents at 45° of length 1 and equal end radii r: the radius
// is r + t·s − 3t·s² + 2t·s³ with t = sin 45°, r + 0.0663 at a quarter of the piece.
TEST(TurtleCpfg, GrBendsTheRadiusAlongAPieceByItsTangents) {
  const Skeleton plain = skeleton_of(cpfg("!(2)@Gs f(2) @Ge(4)"));
  const Skeleton bent = skeleton_of(cpfg("!(2)@Gr(45,1)@Gs f(2) @Ge(4)"));
  ASSERT_EQ(plain.joints.size(), 5u);
  ASSERT_EQ(bent.joints.size(), 5u);
  const double r = 0.1, t = std::sqrt(0.5);
  for (const Joint& j : plain.joints) EXPECT_DOUBLE_EQ(j.radius_m, r);
  auto radius = [&](double s) { return r + t * s + (-3 * t) * s * s + (2 * t) * s * s * s; };
  auto parameter = [&](double s) { return t * s + (3 - 3 * t) * s * s + (-2 + 2 * t) * s * s * s; };
  // The straight Hermite piece from y = 0 to 2, tangents 2 × 1.2 along +y: y(u) = 0.8u³ − 1.2u² + 2.4u.
  auto along = [](double u) { return 0.8 * u * u * u - 1.2 * u * u + 2.4 * u; };
  for (int k = 0; k <= 4; ++k) {
    EXPECT_NEAR(bent.joints[static_cast<size_t>(k)].radius_m, radius(k / 4.0), 1e-12) << k;
    EXPECT_NEAR(bent.joints[static_cast<size_t>(k)].position_m[1], along(parameter(k / 4.0)), 1e-12) << k;
  }
  EXPECT_NEAR(bent.joints[1].radius_m, r + 0.0663, 1e-4);
}

// ---- generalized cylinders (CPFG manual 6.7.3, docs/cpfg.md) ---------------------------

glm::dvec3 at(const Skeleton& sk, size_t chain, size_t joint) {
  const Position q = position_at(sk, chain, joint);
  return {q[0], q[1], q[2]};
}

// The Hermite piece from a to b with tangents ta, tb, at u (the test's own formula).
glm::dvec3 hermite(glm::dvec3 a, glm::dvec3 ta, glm::dvec3 b, glm::dvec3 tb, double u) {
  const double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u;
  const double h01 = -2 * u * u * u + 3 * u * u, h11 = u * u * u - u * u;
  return h00 * a + h10 * ta + h01 * b + h11 * tb;
}

TEST(TurtleCpfg, AGeneralizedCylinderIsAHermiteCurveThroughItsControlPointsAlongTheHeadings) {
  // Figure 3 of the manual: @Gs -(45) f -(45) @Ge(n). The turtle starts at the origin heading
  // +y; - turns right (toward +x), so the curve leaves at 45° and arrives heading 90° right.
  const Skeleton sk = skeleton_of(cpfg("@Gs-(45)f(1)-(45)@Ge(8)"));
  ASSERT_EQ(sk.chains.size(), 1u);
  ASSERT_EQ(sk.chains[0].joint_count, 9u);
  EXPECT_FALSE(sk.chains[0].parent);
  const double h = std::sqrt(0.5);
  // @Gs's point is where the turtle stood (heading +y), @Ge's where f took it (heading (h, h)).
  const glm::dvec3 a(0, 0, 0), b(h, h, 0), ha(0, 1, 0), hb(1, 0, 0);
  const double len = 1, c = 1.2;  // the default tangent coefficients
  for (int k = 0; k <= 8; ++k)
    EXPECT_LT(glm::length(at(sk, 0, size_t(k)) - hermite(a, c * len * ha, b, c * len * hb, k / 8.0)), 1e-12) << k;
  // Tangent at both ends: the first piece leaves along +y, the last arrives along +x.
  const Skeleton fine = skeleton_of(cpfg("@Gs-(45)f(1)-(45)@Ge(200)"));
  const glm::dvec3 first = glm::normalize(at(fine, 0, 1) - at(fine, 0, 0));
  const glm::dvec3 last = glm::normalize(at(fine, 0, 200) - at(fine, 0, 199));
  EXPECT_GT(glm::dot(first, ha), std::cos(std::numbers::pi / 180));
  EXPECT_GT(glm::dot(last, hb), std::cos(std::numbers::pi / 180));
  for (const Joint& j : sk.joints) EXPECT_EQ(j.radius_m, sk.joints[0].radius_m);  // one width
}

TEST(TurtleCpfg, GtScalesTheTangentsAndWidthsChangeLinearlyBetweenControlPoints) {
  // The farthest point from the chord bulges more with longer tangents.
  auto bulge = [](const std::string& axiom) {  // the farthest joint from the chord
    const Skeleton sk = skeleton_of(cpfg(axiom));
    const glm::dvec3 a = at(sk, 0, 0), chord = glm::normalize(at(sk, 0, sk.joints.size() - 1) - a);
    double most = 0;
    for (size_t k = 0; k < sk.joints.size(); ++k) {
      const glm::dvec3 d = at(sk, 0, k) - a;
      most = std::max(most, glm::length(d - glm::dot(d, chord) * chord));
    }
    return most;
  };
  // The curve leaves 30° left of its chord and arrives 30° left of it: an S-free arc.
  const double plain = bulge("+(30)@Gs-(30)f(1)-(30)@Ge(32)");
  const double longer = bulge("+(30)@Gs-(30)f(1)-(30)@Gt(3,3)@Ge(32)");
  EXPECT_GT(plain, 0.01);
  EXPECT_GT(longer, 1.5 * plain);
  // #(w) between the control points: the radius goes linearly from one width to the next.
  const Skeleton sk = skeleton_of(cpfg("#(2)@Gs f(1) #(6) @Ge(4)"));
  ASSERT_EQ(sk.joints.size(), 5u);
  const double r0 = sk.joints[0].radius_m, r4 = sk.joints[4].radius_m;
  EXPECT_NEAR(r4, 3 * r0, 1e-12);
  for (int k = 0; k <= 4; ++k) EXPECT_NEAR(sk.joints[size_t(k)].radius_m, r0 + (r4 - r0) * k / 4.0, 1e-12) << k;
}

TEST(TurtleCpfg, ControlPointsComeFromGcDotAndFromEveryFAndfInsideABraceWithAType) {
  // @Gc(strips) and .(strips) each add a control point; the pieces have their strips.
  const Skeleton gc = skeleton_of(cpfg("@Gs f(1) @Gc(3) f(1) .(2) f(1) @Ge(5)"));
  ASSERT_EQ(gc.chains.size(), 1u);
  EXPECT_EQ(gc.chains[0].joint_count, 1u + 3 + 2 + 5);
  EXPECT_TRUE(near(position_at(gc, 0, 3), {0, 1, 0}));
  EXPECT_TRUE(near(position_at(gc, 0, 5), {0, 2, 0}));
  EXPECT_TRUE(near(position_at(gc, 0, 10), {0, 3, 0}));
  // {(1) ... }(1): f and F set the points (4 strips each, cpfg's default); F also draws its
  // own segment, as in cpfg, so there are two chains.
  const Skeleton brace = skeleton_of(cpfg("{(1)f(1)F(1)f(1)}(1)"));
  ASSERT_EQ(brace.chains.size(), 2u);
  EXPECT_EQ(brace.chains[0].joint_count, 2u);  // F's own segment
  EXPECT_EQ(brace.chains[1].joint_count, 1u + 4 + 4);
  EXPECT_TRUE(near(position_at(brace, 1, 0), {0, 1, 0}));
  EXPECT_TRUE(near(position_at(brace, 1, 8), {0, 3, 0}));
}

TEST(TurtleCpfg, BSplineCylindersFollowTheUniformCubicBasisAndClosedCurvesEndWhereTheyBegan) {
  // {(3): an open B-spline over the points f sets; it starts at (c0 + 4 c1 + c2) / 6.
  const Skeleton open = skeleton_of(cpfg("{(3,2)f(1)+(90)f(1)+(90)f(1)-(90)f(1)}(3)"));
  ASSERT_EQ(open.chains.size(), 1u);
  // c0 = (0,1), c1 = (-1,1), c2 = (-1,0), c3 = (-2,0) (+ turns toward -x): one piece.
  const glm::dvec3 c0(0, 1, 0), c1(-1, 1, 0), c2(-1, 0, 0), c3(-2, 0, 0);
  ASSERT_EQ(open.chains[0].joint_count, 3u);
  EXPECT_LT(glm::length(at(open, 0, 0) - (c0 + 4.0 * c1 + c2) / 6.0), 1e-12);
  EXPECT_LT(glm::length(at(open, 0, 2) - (c1 + 4.0 * c2 + c3) / 6.0), 1e-12);
  // {(2): a closed Hermite curve around a square comes back to its first point.
  const Skeleton loop = skeleton_of(cpfg("{(2)f(1)+(90)f(1)+(90)f(1)+(90)f(1)+(90)}(2)"));
  ASSERT_EQ(loop.chains.size(), 1u);
  EXPECT_LT(glm::length(at(loop, 0, loop.chains[0].joint_count - 1) - at(loop, 0, 0)), 1e-12);
  // {(4): the closed B-spline too.
  const Skeleton ring = skeleton_of(cpfg("{(4)f(1)+(90)f(1)+(90)f(1)+(90)f(1)+(90)}(4)"));
  ASSERT_EQ(ring.chains.size(), 1u);
  EXPECT_LT(glm::length(at(ring, 0, ring.chains[0].joint_count - 1) - at(ring, 0, 0)), 1e-12);
}

TEST(TurtleCpfg, ABranchDrawsOnACopyOfTheOpenCylinderFromItsLastPoint) {
  // [ gives the branch the cylinder as it stands (cpfg's spline stack): the branch's piece
  // leaves from the last control point as a lateral of the cylinder's chain.
  const Skeleton sk = skeleton_of(cpfg("@Gs f(1) @Gc(2) [+(45) f(1) @Ge(2)] -(45) f(1) @Ge(2)"));
  ASSERT_EQ(sk.chains.size(), 2u);
  EXPECT_EQ(sk.chains[0].joint_count, 1u + 2 + 2);
  ASSERT_TRUE(sk.chains[1].parent);
  EXPECT_EQ(*sk.chains[1].parent, (ChainParent{0, 2}));
  EXPECT_TRUE(near(position_at(sk, 1, 0), {0, 1, 0}));
  EXPECT_EQ(sk.chains[1].joint_count, 1u + 2);
  // @! sets cpfg's polygons around (frusta are round: nothing changes); @#(0) is the circle.
  const Skeleton plain = skeleton_of(cpfg("@Gs f(1) @Ge(4)"));
  const Skeleton sides = skeleton_of(cpfg("@!(12)@#(0)@Gs f(1) @Ge(4)"));
  EXPECT_EQ(plain.joints, sides.joints);
  EXPECT_NE(grow_error(cpfg("{(5)f}(5)")).find("type must be 1 to 4"), std::string::npos);
  EXPECT_NE(grow_error(cpfg("@Gs f @Ge(1e9)")).find("at most 10000"), std::string::npos);
  EXPECT_EQ(skeleton_of(cpfg("@Gs f(1) @Ge(-1e300)")).joints.size(), 2u) << "strips below 1 are 1";
  EXPECT_NE(grow_error(cpfg("f}(1)")).find("without an open generalized cylinder"), std::string::npos);
}

// The manual's generalized-cylinder object (vlab's GeneralizedCylinder/fractal.l, written
// again here): a Koch-like curve of control points drawn as one cylinder.
TEST(TurtleCpfg, TheManualsFractalCylinderGrowsAsOneChain) {
  const std::string text =
      "#define STEPS 2\n#define WID 0.8\n#define TANG 1.2\n#define NR 10\n#define SEC 50\n"
      "Lsystem: 1\nderivation length: STEPS\n"
      "Axiom: #(WID) @!(SEC) @Gt(TANG,1.5) @Gs X--f--X--f-- @Ge(NR)\n"
      "X --> X+f+X--f--X+f+X\nhomomorphism\nX --> @Gc(NR)\nendlsystem\n";
  const Skeleton sk = skeleton_of(text);
  ASSERT_EQ(sk.chains.size(), 1u);
  // 2 steps: X becomes 16 X's and 4 more f's... every X is a control point: 2 · 16 points,
  // plus @Gs's, NR strips between each.
  EXPECT_GT(sk.chains[0].joint_count, 100u);
  EXPECT_EQ((sk.chains[0].joint_count - 1) % 10, 0u);
}

}  // namespace
}  // namespace sylva
