// Tests for core/geometry/skin.h: skinning skeleton chains into conical frusta (Bhagvat et al. 2009, sec. 2),
// the sharp-bend split, (u, v), normals, bounding pyramids and the GPU record.
#include "core/geometry/skin.h"
#include "core/util/math.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <numbers>
#include <random>
#include <vector>

namespace sylva {
namespace {

using glm::dvec3;

Joint joint(dvec3 p, double radius, uint32_t material = 0) {
  return Joint{{p.x, p.y, p.z}, radius, material};
}

// A skeleton of one root chain through `points` with `radii`.
Skeleton chain_skeleton(const std::vector<dvec3>& points, const std::vector<double>& radii) {
  Skeleton sk;
  for (size_t i = 0; i < points.size(); ++i) sk.joints.push_back(joint(points[i], radii[i]));
  sk.chains.push_back(Chain{0, uint32_t(points.size()), std::nullopt});
  return sk;
}

// Three joints: up the y axis to the origin, then on at `angle_deg` from straight on,
// bending toward +x. `offset` shifts everything.
Skeleton bent_chain(double angle_deg, double r_start, double r_joint, double r_end,
                    dvec3 offset = dvec3(0), double leg_m = 1.0) {
  double a = angle_deg * kPi / 180;
  return chain_skeleton({offset + dvec3(0, -leg_m, 0), offset,
                         offset + leg_m * dvec3(std::sin(a), std::cos(a), 0)},
                        {r_start, r_joint, r_end});
}

bool finite(const dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

bool all_finite(const Frustum& f) {
  const FrustumShape& s = f.shape;
  return finite(s.base) && finite(s.axis) && std::isfinite(s.length) && std::isfinite(s.radius0) &&
         std::isfinite(s.radius1) && finite(s.lower.normal) && std::isfinite(s.lower.offset) &&
         finite(s.upper.normal) && std::isfinite(s.upper.offset) && std::isfinite(f.u_offset) &&
         std::isfinite(f.v_lower_m) && std::isfinite(f.v_upper_m);
}

double turn_distance(double a, double b) {
  double d = std::abs(a - b);
  return std::min(d, 1 - d);
}

// (a): on every generator the lower cut lies strictly below the upper cut, and both cut
// points are on the r >= 0 nappe.
void expect_cuts_disjoint(const FrustumShape& s, const char* what) {
  AxisFrame f = axis_frame(s.axis);
  for (int i = 0; i < 360; ++i) {
    double a = 2 * kPi * i / 360;
    dvec3 radial = std::cos(a) * f.e0 + std::sin(a) * f.e1;
    double yl = generator_crossing_y(s, s.lower, radial);
    double yu = generator_crossing_y(s, s.upper, radial);
    ASSERT_LT(yl, yu) << what << " at u = " << i / 360.0;
    ASSERT_GE(s.radius_at(yl), -1e-12) << what;
    ASSERT_GE(s.radius_at(yu), -1e-12) << what;
  }
}

// ---- straight, bent, tapering, branching chains --------------------------------------

TEST(SkinStraightChain, ThreeCylindersHavePerpendicularCutsCapsAtBothEndsAndZeroUOffsets) {
  Skeleton sk = chain_skeleton({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}, {0, 3, 0}}, {0.2, 0.2, 0.2, 0.2});
  SkinnedSkeleton skin = skin_skeleton(sk);
  ASSERT_EQ(skin.frusta.size(), 3u);
  EXPECT_EQ(skin.split_joints, 0u);
  for (size_t i = 0; i < 3; ++i) {
    const Frustum& f = skin.frusta[i];
    EXPECT_EQ(f.segment, i);
    EXPECT_EQ(f.shape.radius0, 0.2);
    EXPECT_EQ(f.shape.radius1, 0.2);
    EXPECT_NEAR(glm::dot(f.shape.lower.normal, dvec3(0, 1, 0)), 1.0, 1e-15);
    EXPECT_NEAR(glm::dot(f.shape.upper.normal, dvec3(0, 1, 0)), 1.0, 1e-15);
    EXPECT_NEAR(f.shape.lower.offset, double(i), 1e-15);
    EXPECT_NEAR(f.shape.upper.offset, double(i + 1), 1e-15);
    EXPECT_EQ(f.u_offset, 0.0);
    EXPECT_EQ(f.v_lower_m, double(i));
    EXPECT_EQ(f.v_upper_m, double(i + 1));
    EXPECT_EQ(f.shape.cap_lower, i == 0);
    EXPECT_EQ(f.shape.cap_upper, i == 2);
    EXPECT_EQ(f.parent, int64_t(i) - 1);
  }
}

TEST(SkinMiter, NinetyDegreeBendWithEqualRadiiCutsAlongThe45DegreeMiterThroughTheJoint) {
  SkinnedSkeleton skin = skin_skeleton(bent_chain(90, 0.1, 0.1, 0.1), SkinOptions::paper());
  ASSERT_EQ(skin.frusta.size(), 2u);
  EXPECT_EQ(skin.split_joints, 0u);
  const Plane& a = skin.frusta[0].shape.upper;
  const Plane& b = skin.frusta[1].shape.lower;
  dvec3 miter = glm::normalize(dvec3(1, 1, 0));
  EXPECT_NEAR(glm::length(a.normal - miter), 0.0, 1e-14);
  EXPECT_EQ(a.normal, b.normal);
  EXPECT_EQ(a.offset, b.offset);
  EXPECT_NEAR(a.offset, 0.0, 1e-15);  // through the joint at the origin
  EXPECT_LT(seam_error(skin.frusta[0], skin.frusta[1]), 1e-12);
}

TEST(SkinTip, TaperingChainEndingInRadiusZeroHasNoCapAtTheTip) {
  Skeleton sk = chain_skeleton({{0, 0, 0}, {0, 1, 0}, {0.1, 2, 0}}, {0.3, 0.15, 0.0});
  SkinnedSkeleton skin = skin_skeleton(sk);
  ASSERT_EQ(skin.frusta.size(), 2u);
  EXPECT_TRUE(skin.frusta[0].shape.cap_lower);
  EXPECT_FALSE(skin.frusta[0].shape.cap_upper);
  EXPECT_FALSE(skin.frusta[1].shape.cap_lower);
  EXPECT_FALSE(skin.frusta[1].shape.cap_upper);
  EXPECT_EQ(skin.frusta[1].shape.radius1, 0.0);
  for (const Frustum& f : skin.frusta) {
    EXPECT_TRUE(cuts_are_proper(f.shape, 60));
    // The normal near the tip is finite (eq. 8 falls back to the cone normal there).
    dvec3 tip = f.shape.base + f.shape.length * f.shape.axis;
    dvec3 n = surface_normal(f, tip + 1e-15 * axis_frame(f.shape.axis).e0, NormalMode::interpolated);
    EXPECT_TRUE(finite(n));
  }
}

TEST(SkinBranch, BranchStartsWithPerpendicularCappedCutAndRecordsItsParent) {
  Skeleton sk;
  sk.joints = {joint({0, 0, 0}, 0.3), joint({0, 1, 0}, 0.28), joint({0, 2, 0}, 0.25),
               joint({0, 1, 0}, 0.1), joint({0.7, 1.7, 0}, 0.08)};
  sk.chains = {Chain{0, 3, std::nullopt}, Chain{3, 2, ChainParent{0, 1}}};
  SkinnedSkeleton skin = skin_skeleton(sk, SkinOptions::paper());  // no collar
  ASSERT_EQ(skin.frusta.size(), 3u);
  const Frustum& branch = skin.frusta[2];
  EXPECT_EQ(branch.chain, 1u);
  EXPECT_EQ(branch.segment, 0u);
  EXPECT_EQ(branch.parent, 0);  // the parent's segment ending at joint 1
  EXPECT_NEAR(glm::dot(branch.shape.lower.normal, branch.shape.axis), 1.0, 1e-15);
  EXPECT_TRUE(branch.shape.cap_lower);
  EXPECT_TRUE(branch.shape.cap_upper);
  EXPECT_EQ(branch.v_lower_m, 0.0);
  // Its base (the parent's joint) is inside the parent: buried.
  EXPECT_EQ(branch.shape.base, dvec3(0, 1, 0));
}

// ---- joints between chains and rounded bends (docs/joints.md) ------------------------

TEST(SkinJoints, ALateralStartsWithAFlaredCollarWhoseCapStaysInsideItsParent) {
  Skeleton sk;
  sk.joints = {joint({0, 0, 0}, 0.3), joint({0, 1, 0}, 0.28), joint({0, 2, 0}, 0.25),
               joint({0, 1, 0}, 0.15), joint({0.85, 1.85, 0}, 0.12)};
  sk.chains = {Chain{0, 3, std::nullopt}, Chain{3, 2, ChainParent{0, 1}}};
  SkinnedSkeleton skin = skin_skeleton(sk);
  ASSERT_EQ(skin.frusta.size(), 4u);  // the lateral's one segment is collar + rest
  const Frustum& collar = skin.frusta[2];
  const Frustum& rest = skin.frusta[3];
  EXPECT_EQ(collar.chain, 1u);
  EXPECT_EQ(collar.segment, 0u);
  EXPECT_EQ(rest.segment, 0u);
  EXPECT_GT(collar.shape.radius0, 0.15 * 1.3);   // flared
  EXPECT_LE(collar.shape.radius0, 0.9 * 0.28);   // its cap inside the parent
  EXPECT_EQ(collar.shape.radius1, rest.shape.radius0);  // no step at its end
  EXPECT_EQ(rest.shape.radius1, 0.12);
  EXPECT_NEAR(collar.v_upper_m + (rest.v_upper_m - rest.v_lower_m), glm::length(dvec3(0.85, 0.85, 0)), 1e-12);
  for (const Frustum& f : skin.frusta) EXPECT_TRUE(cuts_are_proper(f.shape, 60));
}

TEST(SkinJoints, AnEndIsMitredOntoItsContinuationWhichGoesOnAtItsRadiusWithItsUAndV) {
  // docs/joints.md "Continuations": the child in line shares one plane with the parent's
  // last frustum (no caps, no dome) and carries its u and v on.
  Skeleton sk;
  sk.joints = {joint({0, 0, 0}, 0.3), joint({0, 1.5, 0}, 0.3),        // ends at joint 1
               joint({0, 1.5, 0}, 0.2), joint({0.1, 3, 0}, 0.18),     // in line: goes on
               joint({0, 1.5, 0}, 0.15), joint({1.0, 2.1, 0}, 0.12)}; // a lateral
  sk.chains = {Chain{0, 2, std::nullopt}, Chain{2, 2, ChainParent{0, 1}}, Chain{4, 2, ChainParent{0, 1}}};
  EXPECT_EQ(continuation_children(sk), (std::vector<int64_t>{1, -1, -1}));
  SkinnedSkeleton skin = skin_skeleton(sk);
  ASSERT_EQ(skin.frusta.size(), 1 + 1 + 2u);  // no dome under the mitre
  const Frustum& end = skin.frusta[0];
  const Frustum& goes_on = skin.frusta[1];
  EXPECT_EQ(goes_on.chain, 1u);
  EXPECT_EQ(goes_on.parent, 0);
  // It starts at the end's radius, moved by sec. 2.2's fit only as far as the two cuts'
  // minor axes need (the end is a cylinder, the continuation tapers: unequal slopes).
  EXPECT_NEAR(goes_on.shape.radius0, 0.3, 0.01 * 0.3);
  EXPECT_NE(goes_on.shape.radius0, 0.3);
  EXPECT_EQ(goes_on.shape.radius1, 0.18);
  EXPECT_EQ(end.shape.upper.normal, goes_on.shape.lower.normal);  // one plane
  EXPECT_EQ(end.shape.upper.offset, goes_on.shape.lower.offset);
  EXPECT_LT(glm::dot(end.shape.upper.normal, end.shape.axis), 1.0);  // tilted: a mitre
  EXPECT_FALSE(end.shape.cap_upper);
  EXPECT_FALSE(goes_on.shape.cap_lower);
  EXPECT_LT(seam_error(end, goes_on), 1e-9);  // the cut curves coincide
  {  // without the fit: no radius step, and the cuts share only their major axis
    SkinOptions unfitted;
    unfitted.fit_minor_axis = false;
    const SkinnedSkeleton plain = skin_skeleton(sk, unfitted);
    EXPECT_EQ(plain.frusta[1].shape.radius0, 0.3);
    const double crack = seam_error(plain.frusta[0], plain.frusta[1]);
    EXPECT_GT(crack, 1e-4);
    EXPECT_LT(crack, 0.01 * 0.3);
  }
  EXPECT_DOUBLE_EQ(goes_on.v_lower_m, end.v_upper_m);  // v goes on
  for (int i = 0; i < 16; ++i) {  // u goes on: the same u on both sides of the cut
    const dvec3 p = cut_point(end.shape, end.shape.upper, i / 16.0);
    const double du = std::abs(surface_uv(end, p).u - surface_uv(goes_on, p).u);
    EXPECT_LT(std::min(du, 1 - du), 2e-3) << i;
    EXPECT_NEAR(surface_uv(end, p).v_m, surface_uv(goes_on, p).v_m, 1e-4) << i;  // within the seam error
  }
  for (const Frustum& f : skin.frusta) EXPECT_TRUE(cuts_are_proper(f.shape, 60));
  // The paper's skin keeps each chain to itself: flat caps, the child's v from 0.
  SkinnedSkeleton paper = skin_skeleton(sk, SkinOptions::paper());
  EXPECT_TRUE(paper.frusta[0].shape.cap_upper);
  EXPECT_EQ(paper.frusta[1].v_lower_m, 0.0);
}

TEST(SkinJoints, AContinuationWhoseCutsCannotBeFittedKeepsItsCapUnderTheDome) {
  // The elm's twig tips: a continuation goes on from its branch's end at the end's radius
  // and tapers to a third of it within 8 cm, 30.5° off the branch's axis. The interior
  // joint's plane is clamped to the tilt limit there, so no base radius makes the two cuts
  // coincide: a mitre would leave a crack of 5 cm. The smooth skin keeps both caps and
  // the dome instead (closed solids).
  Skeleton sk;
  const double a = 30.5 * kPi / 180;
  sk.joints = {joint({0, 0, 0}, 0.1038), joint({0, 0.795, 0}, 0.0913), joint({0, 0.795, 0}, 0.0913),
               joint({0.08 * std::sin(a), 0.795 + 0.08 * std::cos(a), 0}, 0.035)};
  sk.chains = {Chain{0, 2, std::nullopt}, Chain{2, 2, ChainParent{0, 1}}};
  ASSERT_EQ(continuation_children(sk), (std::vector<int64_t>{1, -1}));
  const SkinnedSkeleton skin = skin_skeleton(sk);
  EXPECT_TRUE(skin.frusta[0].shape.cap_upper);
  EXPECT_EQ(skin.frusta[1].kind, FrustumKind::knuckle);  // the dome's first frustum
  EXPECT_TRUE(skin.frusta.back().shape.cap_lower);
  EXPECT_EQ(skin.frusta.back().chain, 1u);
  SkinOptions unfitted;
  unfitted.fit_minor_axis = false;
  const SkinnedSkeleton mitred = skin_skeleton(sk, unfitted);
  ASSERT_EQ(mitred.frusta.size(), 2u);
  EXPECT_FALSE(mitred.frusta[0].shape.cap_upper);
  EXPECT_GT(seam_error(mitred.frusta[0], mitred.frusta[1]), 0.04);  // what the fit's check prevents
}

TEST(SkinJoints, AnEndWithChildrenAndNoContinuationIsADomeThatCarriesItsUAndV) {
  Skeleton sk;
  sk.joints = {joint({0, 0, 0}, 0.3), joint({0, 1.5, 0}, 0.3),          // ends at joint 1
               joint({0, 1.5, 0}, 0.15), joint({1.0, 2.1, 0}, 0.12),    // two laterals,
               joint({0, 1.5, 0}, 0.15), joint({-1.0, 2.1, 0}, 0.12)};  // none in line
  sk.chains = {Chain{0, 2, std::nullopt}, Chain{2, 2, ChainParent{0, 1}}, Chain{4, 2, ChainParent{0, 1}}};
  EXPECT_EQ(continuation_children(sk), (std::vector<int64_t>{-1, -1, -1}));
  SkinnedSkeleton skin = skin_skeleton(sk);
  const size_t dome = size_t(SkinOptions{}.knuckle_frusta / 2);
  ASSERT_EQ(skin.frusta.size(), 1 + dome + 2 + 2);
  EXPECT_EQ(skin.frusta[0].shape.radius1, 0.3);
  EXPECT_TRUE(skin.frusta[0].shape.cap_upper);
  const Frustum& dome_base = skin.frusta[1];
  EXPECT_EQ(dome_base.kind, FrustumKind::knuckle);
  EXPECT_NEAR(dome_base.shape.radius0, 0.3, 1e-15);  // no rim
  EXPECT_EQ(skin.frusta[dome].shape.radius1, 0.0);   // a tip
  EXPECT_EQ(dome_base.u_offset, skin.frusta[0].u_offset);  // the bark goes on over it
  EXPECT_EQ(dome_base.v_lower_m, skin.frusta[0].v_upper_m);
  for (const Frustum& f : skin.frusta) EXPECT_TRUE(cuts_are_proper(f.shape, 60));
}

TEST(SkinJoints, ABendSharperThan20DegreesIsAnArcOfPiecesTurningAtMost10Degrees) {
  for (double angle : {25.0, 60.0, 100.0}) {
    SkinnedSkeleton skin = skin_skeleton(bent_chain(angle, 0.2, 0.2, 0.2));
    SkinnedSkeleton plain = skin_skeleton(bent_chain(angle, 0.2, 0.2, 0.2), SkinOptions::paper());
    ASSERT_EQ(plain.frusta.size(), 2u);
    ASSERT_GT(skin.frusta.size(), 3u) << angle;
    EXPECT_EQ(skin.split_joints, 0u);
    double arc = 0;
    for (size_t i = 0; i < skin.frusta.size(); ++i) {
      const Frustum& f = skin.frusta[i];
      EXPECT_EQ(f.kind, FrustumKind::segment);
      EXPECT_TRUE(cuts_are_proper(f.shape, 60)) << angle;
      EXPECT_NEAR(f.v_lower_m, arc, 1e-12);
      arc = f.v_upper_m;
      if (i == 0) continue;
      const Frustum& below = skin.frusta[i - 1];
      double turn = std::acos(std::clamp(glm::dot(below.shape.axis, f.shape.axis), -1.0, 1.0)) * 180 / kPi;
      EXPECT_LE(turn, 10 + 1e-9) << angle;
      EXPECT_LE(below.segment, f.segment);  // pieces keep their segment, in order
      EXPECT_EQ(below.shape.upper.normal, f.shape.lower.normal);  // mitred, shared plane
    }
    EXPECT_EQ(skin.frusta.front().segment, 0u);
    EXPECT_EQ(skin.frusta.back().segment, 1u);
  }
}

TEST(SkinZeroLength, CoincidentJointsAreSkippedAndCountedWithoutNaN) {
  Skeleton sk = chain_skeleton({{0, 0, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}, {0, 2, 0}},
                               {0.1, 0.1, 0.1, 0.1, 0.1});
  SkinnedSkeleton skin = skin_skeleton(sk);
  EXPECT_EQ(skin.zero_length_skipped, 2u);
  ASSERT_EQ(skin.frusta.size(), 2u);
  EXPECT_EQ(skin.frusta[1].segment, 1u);  // joints 2, 3 coincide with 1: segment 1 -> 4
  for (const Frustum& f : skin.frusta) EXPECT_TRUE(all_finite(f));
  Skeleton single = chain_skeleton({{1, 1, 1}, {1, 1, 1}}, {0.1, 0.1});
  SkinnedSkeleton none = skin_skeleton(single);
  EXPECT_TRUE(none.frusta.empty());
  EXPECT_EQ(none.zero_length_skipped, 1u);
}

// ---- sharp bends ---------------------------------------------------------------------

class SkinSharpBend : public testing::TestWithParam<double> {};

// Checks (a), (b), (c) of the sharp-bend contract for one skinned bent chain.
void expect_watertight_bend(const SkinnedSkeleton& skin, double r_joint, const char* what) {
  for (const Frustum& f : skin.frusta) {
    ASSERT_TRUE(all_finite(f)) << what;
    EXPECT_TRUE(cuts_are_proper(f.shape, 60)) << what;
    expect_cuts_disjoint(f.shape, what);
  }
  const Frustum& leg1 = skin.frusta[0];
  const Frustum& leg2 = skin.frusta[1];
  if (skin.split_joints == 0) {
    // (b) one shared plane and one shared cut curve.
    EXPECT_EQ(leg1.shape.upper.normal, leg2.shape.lower.normal) << what;
    EXPECT_EQ(leg1.shape.upper.offset, leg2.shape.lower.offset) << what;
    EXPECT_LT(seam_error(leg1, leg2), 1e-9 * r_joint) << what;
    EXPECT_FALSE(leg1.shape.cap_upper);
    EXPECT_FALSE(leg2.shape.cap_lower);
  } else {
    // Split: both legs closed by caps, a knuckle ball whose slices share their circles
    // and which contains both cap rims.
    EXPECT_TRUE(leg1.shape.cap_upper) << what;
    EXPECT_TRUE(leg2.shape.cap_lower) << what;
    ASSERT_EQ(skin.frusta.size(), 2u + 8u) << what;
    for (size_t i = 3; i < skin.frusta.size(); ++i) {
      EXPECT_LT(seam_error(skin.frusta[i - 1], skin.frusta[i]), 1e-12) << what;
    }
    dvec3 center = leg1.shape.base + leg1.shape.length * leg1.shape.axis;
    for (const Frustum* leg : {&leg1, &leg2}) {
      const Plane& cap = leg == &leg1 ? leg->shape.upper : leg->shape.lower;
      for (int i = 0; i < 64; ++i) {
        dvec3 rim = cut_point(leg->shape, cap, i / 64.0);
        // Inside the knuckle: within some slice's radius at the rim's height.
        bool inside = false;
        for (size_t k = 2; k < skin.frusta.size(); ++k) {
          const FrustumShape& s = skin.frusta[k].shape;
          double y = glm::dot(rim - s.base, s.axis);
          if (y < -1e-12 || y > s.length + 1e-12) continue;
          double d = glm::length(rim - s.base - y * s.axis);
          if (d <= s.radius_at(y) + 1e-12) inside = true;
        }
        EXPECT_TRUE(inside) << what << " rim point " << i;
        EXPECT_LE(glm::length(rim - center), r_joint * (1 + 1e-12));
      }
    }
  }
}

TEST_P(SkinSharpBend, CylinderBendIsWatertightWithProperCutsAndNoNaN) {
  SkinnedSkeleton skin = skin_skeleton(bent_chain(GetParam(), 0.2, 0.2, 0.2));
  expect_watertight_bend(skin, 0.2, "cylinders");
  EXPECT_EQ(skin.split_joints, GetParam() > 120 ? 1u : 0u);
}

TEST_P(SkinSharpBend, TaperedBendWithMinorAxisFitIsWatertightWithProperCutsAndNoNaN) {
  SkinOptions fit;
  fit.fit_minor_axis = true;
  SkinnedSkeleton skin = skin_skeleton(bent_chain(GetParam(), 0.3, 0.2, 0.1), fit);
  expect_watertight_bend(skin, 0.2, "tapered, fitted");
}

TEST_P(SkinSharpBend, ShortFatSegmentsAreSplitRatherThanLetTheirCutsCross) {
  // Legs as long as the joint radius: a 90° miter would make the cuts meet inside.
  SkinnedSkeleton skin = skin_skeleton(bent_chain(GetParam(), 0.5, 0.5, 0.5, dvec3(0), 0.5));
  for (const Frustum& f : skin.frusta) {
    ASSERT_TRUE(all_finite(f));
    EXPECT_TRUE(cuts_are_proper(f.shape, 60));
    expect_cuts_disjoint(f.shape, "short fat");
  }
}

INSTANTIATE_TEST_SUITE_P(SkinJointAnglesDeg, SkinSharpBend,
                         testing::Values(0.0, 1e-6, 45.0, 90.0, 135.0, 179.0, 180.0));

TEST(SkinSharpBendLimits, PlaneTiltNeverExceedsTheLimitForAnyAngle) {
  for (double angle = 0; angle <= 180; angle += 0.5) {
    SkinnedSkeleton skin = skin_skeleton(bent_chain(angle, 0.3, 0.2, 0.05));
    for (const Frustum& f : skin.frusta) {
      ASSERT_TRUE(all_finite(f)) << angle;
      EXPECT_GE(glm::dot(f.shape.lower.normal, f.shape.axis), 0.5 - 1e-12) << angle;
      EXPECT_GE(glm::dot(f.shape.upper.normal, f.shape.axis), 0.5 - 1e-12) << angle;
      EXPECT_TRUE(cuts_are_proper(f.shape, 60)) << angle;
    }
  }
}

// ---- seam error and the minor-axis fit -----------------------------------------------

TEST(SkinSeam, MinorAxisFitMakesTheTwoEllipticalCutsCoincide) {
  // A cylinder into a strongly tapering cone, bent 45°: the medial construction alone
  // leaves the minor axes apart.
  for (double angle : {20.0, 45.0, 90.0}) {
    Skeleton sk = bent_chain(angle, 0.2, 0.2, 0.05);
    SkinnedSkeleton plain = skin_skeleton(sk, SkinOptions::paper());  // the mitre, unrounded
    SkinOptions fit_options = SkinOptions::paper();
    fit_options.fit_minor_axis = true;
    SkinnedSkeleton fit = skin_skeleton(sk, fit_options);
    ASSERT_EQ(plain.frusta.size(), 2u);
    ASSERT_EQ(fit.frusta.size(), 2u);
    double error_plain = seam_error(plain.frusta[0], plain.frusta[1]);
    double error_fit = seam_error(fit.frusta[0], fit.frusta[1]);
    std::printf("[ seam    ] bend %4.0f deg, r 0.2 -> 0.2 -> 0.05, legs 1 m: seam error "
                "%.3e m without fit, %.3e m with fit (new base radius %.6f m)\n",
                angle, error_plain, error_fit, fit.frusta[1].shape.radius0);
    RecordProperty("seam_error_without_fit_" + std::to_string(int(angle)), std::to_string(error_plain));
    RecordProperty("seam_error_with_fit_" + std::to_string(int(angle)), std::to_string(error_fit));
    EXPECT_GT(error_plain, 1e-4);
    EXPECT_LT(error_fit, 1e-9);
  }
}

TEST(SkinSeam, TheSmoothSkinFitsItsMitresAndThePapersDoesNot) {
  // The smooth skin's mitres coincide (skin.h fit_minor_axis, on); the paper's skin keeps
  // sec. 2's plain construction ("in practice ... unnecessary"), the seam G3 allows.
  const Skeleton sk = bent_chain(15, 0.2, 0.2, 0.05);  // under the smooth skin's 20° rounding
  const SkinnedSkeleton smooth = skin_skeleton(sk), paper = skin_skeleton(sk, SkinOptions::paper());
  ASSERT_EQ(smooth.frusta.size(), 2u);
  ASSERT_EQ(paper.frusta.size(), 2u);
  EXPECT_TRUE(SkinOptions{}.fit_minor_axis);
  EXPECT_FALSE(SkinOptions::paper().fit_minor_axis);
  EXPECT_LT(seam_error(smooth.frusta[0], smooth.frusta[1]), 1e-9);
  EXPECT_GT(seam_error(paper.frusta[0], paper.frusta[1]), 1e-4);
}

// ---- parametrization -----------------------------------------------------------------

TEST(SkinUV, UOnTheSharedCutAgreesFromBothFrustaAcrossBentJoints) {
  for (double angle : {1e-6, 30.0, 90.0, 120.0}) {
    for (dvec3 bend_axis : {dvec3(0, 0, 1), dvec3(1, 0, 0), glm::normalize(dvec3(1, 2, 3))}) {
      // A 3-segment chain in varying planes so the canonical frames disagree.
      double a = angle * kPi / 180;
      dvec3 p2 = dvec3(std::sin(a), std::cos(a), 0);
      dvec3 p3 = p2 + glm::normalize(glm::cross(bend_axis, p2) + p2);
      Skeleton sk = chain_skeleton({{0, -1, 0}, {0, 0, 0}, p2, p3}, {0.1, 0.1, 0.1, 0.1});
      SkinOptions opt;
      opt.twist_rad_per_m = 0.7;
      SkinnedSkeleton skin = skin_skeleton(sk, opt);
      ASSERT_EQ(skin.split_joints, 0u);
      for (size_t j = 1; j < skin.frusta.size(); ++j) {
        const Frustum& below = skin.frusta[j - 1];
        const Frustum& above = skin.frusta[j];
        for (int i = 0; i < 32; ++i) {
          dvec3 p = cut_point(below.shape, below.shape.upper, i / 32.0);
          SurfaceUV ub = surface_uv(below, p), ua = surface_uv(above, p);
          EXPECT_LT(turn_distance(ub.u, ua.u), 1e-9) << angle << " joint " << j;
          EXPECT_NEAR(ub.v, 1.0, 1e-9);
          EXPECT_NEAR(ua.v, 0.0, 1e-9);
          EXPECT_NEAR(ub.v_m, ua.v_m, 1e-9);
        }
      }
    }
  }
}

TEST(SkinUV, VRunsFromLowerToUpperCutScaledByArcLengthAndSafeForCylinders) {
  SkinnedSkeleton skin = skin_skeleton(bent_chain(40, 0.2, 0.2, 0.1, dvec3(0), 2.0), SkinOptions::paper());
  const Frustum& f = skin.frusta[1];  // tilted lower cut, perpendicular upper cut
  EXPECT_DOUBLE_EQ(f.v_lower_m, 2.0);
  EXPECT_DOUBLE_EQ(f.v_upper_m, 4.0);
  AxisFrame fr = axis_frame(f.shape.axis);
  for (int i = 0; i < 16; ++i) {
    double a = 2 * kPi * i / 16;
    dvec3 radial = std::cos(a) * fr.e0 + std::sin(a) * fr.e1;
    double yl = generator_crossing_y(f.shape, f.shape.lower, radial);
    double yu = generator_crossing_y(f.shape, f.shape.upper, radial);
    for (double t : {0.0, 0.25, 1.0}) {
      double y = yl + t * (yu - yl);
      dvec3 p = f.shape.base + y * f.shape.axis + f.shape.radius_at(y) * radial;
      SurfaceUV uv = surface_uv(f, p);
      EXPECT_NEAR(uv.v, t, 1e-12);
      EXPECT_NEAR(uv.v_m, 2.0 + 2.0 * t, 1e-12);
    }
  }
}

TEST(SkinUV, TwistTurnsUByRadiansPerMetreOfArcLength) {
  Skeleton sk = chain_skeleton({{0, 0, 0}, {0, 2, 0}}, {0.1, 0.1});
  SkinOptions opt;
  opt.twist_rad_per_m = kPi / 2;  // a quarter turn per metre
  SkinnedSkeleton skin = skin_skeleton(sk, opt);
  const Frustum& f = skin.frusta[0];
  dvec3 e0 = axis_frame(f.shape.axis).e0;
  EXPECT_NEAR(surface_uv(f, 0.1 * e0).u, 0.0, 1e-12);
  EXPECT_NEAR(surface_uv(f, dvec3(0, 1, 0) + 0.1 * e0).u, 0.25, 1e-12);
  EXPECT_NEAR(surface_uv(f, dvec3(0, 2, 0) + 0.1 * e0).u, 0.5, 1e-12);
}

// ---- normals -------------------------------------------------------------------------

TEST(SkinNormals, InterpolatedNormalIsC0AcrossAJointAndExactNormalIsPerpendicularToGenerators) {
  SkinOptions fit;
  fit.fit_minor_axis = true;
  for (double angle : {0.0, 30.0, 80.0}) {
    SkinnedSkeleton skin = skin_skeleton(bent_chain(angle, 0.3, 0.2, 0.15), fit);
    ASSERT_EQ(skin.split_joints, 0u);
    const Frustum& below = skin.frusta[0];
    const Frustum& above = skin.frusta[1];
    for (int i = 0; i < 64; ++i) {
      dvec3 p = cut_point(below.shape, below.shape.upper, i / 64.0);
      dvec3 nb = surface_normal(below, p, NormalMode::interpolated);
      dvec3 na = surface_normal(above, p, NormalMode::interpolated);
      EXPECT_LT(glm::length(nb - na), 1e-9) << angle << " sample " << i;
      EXPECT_NEAR(glm::length(nb), 1.0, 1e-12);
      // Exact normal: unit and ⊥ the generator direction axis + slope·ê.
      dvec3 ne = surface_normal(above, p, NormalMode::exact);
      dvec3 d = p - above.shape.base;
      dvec3 radial = glm::normalize(d - glm::dot(d, above.shape.axis) * above.shape.axis);
      EXPECT_NEAR(glm::dot(ne, above.shape.axis + above.shape.slope() * radial), 0.0, 1e-12);
      EXPECT_GT(glm::dot(ne, radial), 0.0);
    }
  }
}

// ---- bounding pyramid ----------------------------------------------------------------

// A random frustum with random cuts within the tilt limit, proper by construction or
// rejection.
FrustumShape random_frustum(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> uni(0, 1);
  for (;;) {
    FrustumShape s;
    s.base = dvec3(uni(rng), uni(rng), uni(rng)) * 10.0 - 5.0;
    s.axis = glm::normalize(dvec3(uni(rng), uni(rng), uni(rng)) - 0.5);
    s.length = 0.05 + 2 * uni(rng);
    int kind = int(uni(rng) * 4);
    double r = 0.01 + 0.5 * uni(rng);
    s.radius0 = r;
    s.radius1 = kind == 0 ? r : kind == 1 ? 0.0 : 0.01 + 0.5 * uni(rng);  // cylinder, tip
    AxisFrame f = axis_frame(s.axis);
    auto tilted = [&](double max_tilt) {
      double t = max_tilt * uni(rng), a = 2 * kPi * uni(rng);
      return glm::normalize(std::cos(t) * s.axis +
                            std::sin(t) * (std::cos(a) * f.e0 + std::sin(a) * f.e1));
    };
    double max_tilt = 60 * kPi / 180;
    dvec3 nl = tilted(max_tilt), nu = kind == 1 ? s.axis : tilted(max_tilt);
    s.lower = Plane{nl, glm::dot(nl, s.base)};
    dvec3 top = s.base + s.length * s.axis;
    s.upper = Plane{nu, glm::dot(nu, top)};
    if (cuts_are_proper(s, 60)) return s;
  }
}

TEST(SkinBounds, HundredThousandSurfacePointsPerRandomFrustumLieInsideItsBoundingPyramid) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> uni(0, 1);
  const int kFrusta = 24, kSamples = 100000;
  int outside = 0;
  double worst = -1;
  for (int n = 0; n < kFrusta; ++n) {
    FrustumShape s = random_frustum(rng);
    double shell = n % 2 ? 0.0 : 0.05 * uni(rng);
    FrustumShape outer = s;  // the relief shell's outer frustum
    outer.radius0 += shell;
    outer.radius1 += shell;
    BoundingPyramid pyr = bounding_pyramid(s, shell);
    ASSERT_TRUE(pyr.proper) << n;
    AxisFrame f = axis_frame(s.axis);
    double tol = 1e-12 * (1 + glm::length(s.base) + s.length);
    for (int i = 0; i < kSamples; ++i) {
      double a = 2 * kPi * uni(rng), t = uni(rng);
      dvec3 radial = std::cos(a) * f.e0 + std::sin(a) * f.e1;
      double yl = generator_crossing_y(outer, outer.lower, radial);
      double yu = generator_crossing_y(outer, outer.upper, radial);
      double y = yl + t * (yu - yl);
      dvec3 p = outer.base + y * outer.axis + outer.radius_at(y) * radial;
      double d = distance_outside(pyr, p);
      worst = std::max(worst, d);
      if (d > tol) ++outside;
    }
    // Triangles face outward: each triangle's normal points away from the centroid.
    dvec3 centroid(0);
    for (const dvec3& v : pyr.vertices) centroid += v / 8.0;
    for (int t = 0; t < 12; ++t) {
      dvec3 a = pyr.vertices[pyr.triangles[3 * t]], b = pyr.vertices[pyr.triangles[3 * t + 1]],
            c = pyr.vertices[pyr.triangles[3 * t + 2]];
      EXPECT_GE(glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0 - centroid), 0.0) << n;  // 0: a tip
    }
    // The vertices lie on their planes.
    for (int v = 0; v < 4; ++v) {
      EXPECT_NEAR(glm::dot(s.lower.normal, pyr.vertices[v]), s.lower.offset, 1e-12);
      EXPECT_NEAR(glm::dot(s.upper.normal, pyr.vertices[4 + v]), s.upper.offset, 1e-12);
    }
  }
  EXPECT_EQ(outside, 0) << "worst distance outside " << worst;
}

// ---- GPU record and large offsets ----------------------------------------------------

TEST(SkinGpu, UnpackingTheRecordReproducesTheShapeWithinFloatPrecision) {
  for (dvec3 offset : {dvec3(0), dvec3(1e6, 2e3, -1e6)}) {
    Skeleton sk = bent_chain(50, 0.3, 0.2, 0.1, offset);
    SkinnedSkeleton skin = skin_skeleton(sk);
    for (const Frustum& f : skin.frusta) {
      UnpackedGpuSegment u = unpack_gpu_segment(pack_gpu_segment(f));
      const FrustumShape& a = f.shape;
      const FrustumShape& b = u.shape;
      double scale = a.length + a.radius0;  // float precision relative to the segment
      EXPECT_LT(glm::length(a.base - b.base), 1e-11 * glm::length(a.base) + 1e-9);
      EXPECT_LT(glm::length(a.axis - b.axis), 1e-6);
      EXPECT_NEAR(a.length, b.length, 1e-6 * scale);
      EXPECT_NEAR(a.radius0, b.radius0, 1e-7 * scale);
      EXPECT_NEAR(a.radius1, b.radius1, 1e-7 * scale);
      EXPECT_LT(glm::length(a.lower.normal - b.lower.normal), 1e-5);
      EXPECT_LT(glm::length(a.upper.normal - b.upper.normal), 1e-5);
      // Planes compared where it matters: the cut points of both agree near the surface.
      for (int i = 0; i < 8; ++i) {
        EXPECT_LT(glm::length(cut_point(a, a.lower, i / 8.0) - cut_point(b, b.lower, i / 8.0)),
                  1e-5 * scale);
        EXPECT_LT(glm::length(cut_point(a, a.upper, i / 8.0) - cut_point(b, b.upper, i / 8.0)),
                  1e-5 * scale);
      }
      EXPECT_EQ(a.cap_lower, b.cap_lower);
      EXPECT_EQ(a.cap_upper, b.cap_upper);
      EXPECT_LT(turn_distance(u.u_offset, f.u_offset), 1.0 / 65536);
      EXPECT_NEAR(u.v_lower_m, f.v_lower_m, 1e-6 * (1 + f.v_lower_m));
    }
  }
}

TEST(SkinPrecision, ChainAtAMillionMetresMatchesTheChainAtTheOriginTo1e9Relative) {
  SkinOptions fit = SkinOptions::paper();
  fit.fit_minor_axis = true;
  dvec3 offset(1e6, -1e6, 1e6);
  SkinnedSkeleton near = skin_skeleton(bent_chain(70, 0.3, 0.2, 0.1), fit);
  SkinnedSkeleton far = skin_skeleton(bent_chain(70, 0.3, 0.2, 0.1, offset), fit);
  ASSERT_EQ(near.frusta.size(), far.frusta.size());
  for (size_t i = 0; i < near.frusta.size(); ++i) {
    const FrustumShape& a = near.frusta[i].shape;
    const FrustumShape& b = far.frusta[i].shape;
    double scale = a.length + a.radius0;
    EXPECT_LT(glm::length(a.axis - b.axis), 1e-9);
    EXPECT_NEAR(a.length, b.length, 1e-9 * scale);
    EXPECT_NEAR(a.radius0, b.radius0, 1e-9 * scale);
    EXPECT_LT(glm::length(a.lower.normal - b.lower.normal), 1e-9);
    EXPECT_LT(glm::length(a.upper.normal - b.upper.normal), 1e-9);
    EXPECT_NEAR(a.lower.offset, b.lower.offset - glm::dot(b.lower.normal, offset), 1e-9 * scale);
    EXPECT_NEAR(a.upper.offset, b.upper.offset - glm::dot(b.upper.normal, offset), 1e-9 * scale);
    EXPECT_LT(turn_distance(near.frusta[i].u_offset, far.frusta[i].u_offset), 1e-9);
    dvec3 p = cut_point(a, a.upper, 0.3);
    SurfaceUV ua = surface_uv(near.frusta[i], p), ub = surface_uv(far.frusta[i], p + offset);
    EXPECT_LT(turn_distance(ua.u, ub.u), 1e-9);
    EXPECT_NEAR(ua.v, ub.v, 1e-9);
  }
  if (far.frusta.size() >= 2) {
    EXPECT_LT(seam_error(far.frusta[0], far.frusta[1]), 1e-9);
  }
}

TEST(SkinProgress, ReportsTheChainsSkinnedAndStopsWhenCancelled) {
  // 3000 two-joint chains: checked every 1024 chains.
  Skeleton sk;
  for (uint32_t c = 0; c < 3000; ++c) {
    sk.joints.push_back({{double(c), 0, 0}, 0.1, 0});
    sk.joints.push_back({{double(c), 1, 0}, 0.1, 0});
    sk.chains.push_back({2 * c, 2, std::nullopt});
  }
  std::vector<double> fractions;
  Expected<SkinnedSkeleton> all =
      skin_skeleton(sk, {}, Progress([&](double f, std::string_view) { fractions.push_back(f); }));
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(all->frusta.size(), 3000u);
  EXPECT_EQ(all->frusta.size(), skin_skeleton(sk).frusta.size());
  ASSERT_EQ(fractions.size(), 3u);  // after 1024 and 2048 chains, then 1
  EXPECT_DOUBLE_EQ(fractions[0], 1024.0 / 3000);
  EXPECT_EQ(fractions.back(), 1.0);
  std::atomic<bool> cancel{true};
  EXPECT_TRUE(skin_skeleton(sk, {}, Progress(&cancel)).cancelled());
}

}  // namespace
}  // namespace sylva
