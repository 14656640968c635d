// growth_tween_test.cpp — a plant between two derivation steps (core/grow/growth_tween.h,
// issue 31 §3).
//
// The elm keeps every internode it made (its F modules have no production and their
// radii are set when they are made), so between steps n and n + 1 the wood that exists
// must stay where it is and only what is new may grow: the skeleton's total length is
// then exactly L(n) + alpha·(L(n+1) − L(n)) — a chain that was not matched to its old self
// would shrink and break that.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/geometry/skeleton.h"
#include "core/grow/grow.h"
#include "core/grow/growth_tween.h"

namespace sylva {
namespace {

Skeleton grown(const std::string& preset, int64_t steps) {
  const std::string path = std::string(SYLVA_SOURCE_DIR) + "/presets/" + preset;
  Expected<lsys::Grammar> g = lsys::load_grammar(path);
  if (!g) {
    ADD_FAILURE() << g.error().format();
    return {};
  }
  lsys::DeriveOptions o;
  o.steps = steps;
  Expected<GrowResult> r = grow(*g, o, path, {});
  if (!r) {
    ADD_FAILURE() << r.error().format();
    return {};
  }
  return std::move(r->skeleton);
}

double wood_length(const Skeleton& s) {
  double total = 0;
  for (const Chain& c : s.chains)
    for (uint32_t j = 1; j < c.joint_count; ++j) {
      const Joint& a = s.joints[c.first_joint + j - 1];
      const Joint& b = s.joints[c.first_joint + j];
      total += std::hypot(b.position_m[0] - a.position_m[0], b.position_m[1] - a.position_m[1],
                          b.position_m[2] - a.position_m[2]);
    }
  return total;
}

double leaf_area(const Skeleton& s) {
  double total = 0;
  for (const Leaf& leaf : s.leaves) {
    double n[3] = {0, 0, 0};
    for (size_t i = 0; i < leaf.vertices_m.size(); ++i) {
      const auto& p = leaf.vertices_m[i];
      const auto& q = leaf.vertices_m[(i + 1) % leaf.vertices_m.size()];
      n[0] += (p[1] - q[1]) * (p[2] + q[2]);
      n[1] += (p[2] - q[2]) * (p[0] + q[0]);
      n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    total += 0.5 * std::hypot(n[0], n[1], n[2]);
  }
  return total;
}

TEST(GrowthTween, WhatExistsStaysAndWhatIsNewGrowsOutInProportion) {
  for (int64_t n : {7, 11, 15}) {
    SCOPED_TRACE("elm, steps " + std::to_string(n) + " to " + std::to_string(n + 1));
    const Skeleton before = grown("elm.lsys", n), after = grown("elm.lsys", n + 1);
    ASSERT_GT(after.segment_count(), before.segment_count());
    const double lb = wood_length(before), la = wood_length(after);
    double last = lb;
    for (double alpha : {0.01, 0.25, 0.5, 0.75, 0.99}) {
      const Skeleton t = tween_growth(before, after, alpha);
      ASSERT_TRUE(validate_skeleton(t).ok()) << validate_skeleton(t).error().message;
      ASSERT_EQ(t.chains, after.chains);  // after's topology, in after's order
      ASSERT_EQ(t.joints.size(), after.joints.size());
      const double l = wood_length(t);
      EXPECT_NEAR(l, lb + alpha * (la - lb), 1e-9 * la) << alpha;
      EXPECT_GT(l, last);
      last = l;
    }
    EXPECT_EQ(tween_growth(before, after, 1.0), after);  // bit for bit
  }
}

TEST(GrowthTween, NewLeavesGrowAboutTheirJointAndTheOldOnesStay) {
  const Skeleton before = grown("elm_in_leaf.lsys", 14), after = grown("elm_in_leaf.lsys", 15);
  ASSERT_GT(after.leaves.size(), before.leaves.size());
  const double ab = leaf_area(before), aa = leaf_area(after);
  double last = 0;
  for (double alpha : {0.01, 0.3, 0.6, 0.9}) {
    const Skeleton t = tween_growth(before, after, alpha);
    ASSERT_TRUE(validate_skeleton(t).ok());
    const double a = leaf_area(t);
    // The old leaves keep their area, the new ones have alpha² of theirs.
    EXPECT_NEAR(a, ab + alpha * alpha * (aa - ab), 1e-9 * aa) << alpha;
    EXPECT_GT(a, last);
    last = a;
  }
}

TEST(GrowthTween, TheElmInLeafsTrunkThickensWhileTheCrownGrows) {
  // Secondary growth (presets/elm_in_leaf.lsys W(r, a)): the trunk's first internode is
  // NEW_WOOD = 0.45 of its full radius R_TRUNK·0.8 when it is made (step 1) and gains
  // 0.55/THICKEN of it every step until THICKEN = 20 steps old; a grammar that sets the
  // radius once (elm.lsys) keeps it from step 1 on.
  const double full = 0.42 * 0.8;
  double last = 0;
  for (int64_t n = 1; n <= 28; ++n) {
    const Skeleton s = grown("elm_in_leaf.lsys", n);
    ASSERT_FALSE(s.chains.empty()) << n;
    const double r = s.joints[s.chains[0].first_joint + 1].radius_m;
    const double age = double(n - 1);
    EXPECT_NEAR(r, full * (0.45 + 0.55 * std::min(1.0, age / 20)), 1e-12) << "step " << n;
    if (n <= 21) {
      EXPECT_GT(r, last) << "step " << n;
    }
    last = r;
  }
  // Between two steps the tween thickens the old wood linearly as well.
  const Skeleton before = grown("elm_in_leaf.lsys", 8), after = grown("elm_in_leaf.lsys", 9);
  const double rb = before.joints[1].radius_m, ra = after.joints[1].radius_m;
  ASSERT_GT(ra, rb);
  EXPECT_NEAR(tween_growth(before, after, 0.25).joints[1].radius_m, rb + 0.25 * (ra - rb), 1e-12);
  const Skeleton elm1 = grown("elm.lsys", 4), elm2 = grown("elm.lsys", 20);
  EXPECT_EQ(elm1.joints[1].radius_m, elm2.joints[1].radius_m);
}

TEST(GrowthTween, AChainThatIsNotTheOldOnesGrowsOutOfWhereItStarts) {
  // Before: one root chain of two segments. After: the same chain, one segment longer,
  // a lateral off its middle joint, and a second root chain elsewhere.
  Skeleton before, after;
  auto joint = [](double x, double y, double r) { return Joint{{x, y, 0}, r, 0}; };
  before.joints = {joint(0, 0, 0.2), joint(0, 1, 0.1), joint(0, 2, 0.05)};
  before.chains = {Chain{0, 3, std::nullopt}};
  after.joints = {joint(0, 0, 0.2), joint(0, 1, 0.1), joint(0, 2, 0.05), joint(0, 3, 0.02),
                  joint(0, 1, 0.05), joint(1, 1, 0.04),
                  joint(5, 0, 0.3), joint(5, 2, 0.1)};
  after.chains = {Chain{0, 4, std::nullopt}, Chain{4, 2, ChainParent{0, 1}}, Chain{6, 2, std::nullopt}};
  ASSERT_TRUE(validate_skeleton(after).ok());
  const Skeleton t = tween_growth(before, after, 0.5);
  EXPECT_EQ(t.joints[2].position_m[1], 2.0);   // old joints stay
  EXPECT_EQ(t.joints[3].position_m[1], 2.5);   // the tip grows out of the old end
  EXPECT_EQ(t.joints[3].radius_m, 0.01);
  EXPECT_EQ(t.joints[5].position_m[0], 0.5);   // the lateral, half out of its joint
  EXPECT_EQ(t.joints[5].position_m[1], 1.0);
  EXPECT_EQ(t.joints[6].position_m[0], 5.0);   // the new root, half up from its start
  EXPECT_EQ(t.joints[7].position_m[1], 1.0);
  EXPECT_EQ(t.joints[6].radius_m, 0.15);
}

}  // namespace
}  // namespace sylva
