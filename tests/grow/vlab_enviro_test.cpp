// vlab's environmental programs built in (core/grow/vlab_enviro.h): chiba against closed
// forms and against testing every ball, its sky against chiba's sphere; honda81's rule.
#include "core/grow/vlab_enviro.h"

#include <cmath>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

namespace sylva {
namespace {

using Chiba = lsys::Grammar::Chiba;

Chiba one_source(double x, double y, double z) {
  Chiba c;
  c.sources.push_back({{x, y, z}, 1.0});
  return c;
}

// The lens two equal discs of radius r make d apart: 2 r² acos(d / 2r) − (d / 2) sqrt(4r² − d²).
double equal_lens(double r, double d) { return 2 * r * r * std::acos(d / (2 * r)) - d / 2 * std::sqrt(4 * r * r - d * d); }

// Three balls of radius 0.9 at y = 0, 1, 2, light from (1, 2, 0), with `estimate
// intersection area: on`: a ball above k apart covers the lens of the discs whose centres
// lie d = k sin θ apart across the ray, θ the light's angle from +y.
TEST(Chiba, EstimatedAreaDimsByTheCoveredShareOfTheDisc) {
  Chiba c = one_source(1, 2, 0);
  c.estimate_area = true;
  c.beam_radius = 1;
  c.transmittance = 0.5;
  const std::vector<ChibaBall> balls = {{{0, 0, 0}, 0.9}, {{0, 1, 0}, 0.9}, {{0, 2, 0}, 0.9}};
  const auto a = chiba_answers(c, balls);
  const double sin_t = 1 / std::sqrt(5.0), disc = std::numbers::pi * 0.81;
  const double one = 1 - 0.5 * equal_lens(0.9, sin_t) / disc, two = 1 - 0.5 * equal_lens(0.9, 2 * sin_t) / disc;
  EXPECT_NEAR(a[2].light, 1, 1e-15);
  EXPECT_NEAR(a[1].light, one, 1e-14);
  EXPECT_NEAR(a[0].light, one * two, 1e-14);
  EXPECT_NEAR(a[0].brightest.x, sin_t, 1e-14);
  EXPECT_NEAR(a[0].brightest.y, 2 * sin_t, 1e-14);
  // A ball whose disc holds the other's wholly (straight up, d = 0) covers all of it.
  Chiba up = c;
  up.sources[0] = {{0, 1, 0}, 1};
  up.transmittance = 0;
  EXPECT_EQ(chiba_answers(up, balls)[0].light, 0.0);
}

// Without the area estimate a ball dims by transmittance^(length inside / diameter widened by
// the beam): a ray from inside a ball counts only the part ahead of it.
TEST(Chiba, APathThroughABallDimsByItsLengthInside) {
  Chiba c = one_source(0, 1, 0);
  c.transmittance = 0.25;
  const ChibaBall other{{0, 0.5, 0}, 1};
  EXPECT_NEAR(chiba_dimming(c, {0, 0, 0}, 1, {0, 1, 0}, other), std::pow(0.25, 1.5 / 2), 1e-15);
  EXPECT_NEAR(chiba_dimming(c, {0, -3, 0}, 1, {0, 1, 0}, other), 0.25, 1e-15);
  EXPECT_EQ(chiba_dimming(c, {0, 3, 0}, 1, {0, 1, 0}, other), 1.0) << "behind";
  EXPECT_EQ(chiba_dimming(c, {2.5, -3, 0}, 1, {0, 1, 0}, other), 1.0) << "beside";
  c.beam_radius = 1;  // widened by the asking ball's radius: now it is met, over 2 * 2 * sin
  const double len = 2 * std::sqrt(4 - 2.5 * 2.5 + 4);
  EXPECT_NEAR(chiba_dimming(c, {1.5, -3, 0}, 1, {0, 1, 0}, other), std::pow(0.25, len / 4), 1e-15);
  // Far from the origin the distance across the ray keeps its digits.
  const glm::dvec3 far(1e8, 1e8, 1e8);
  EXPECT_NEAR(chiba_dimming(c, far, 1, {0, 1, 0}, {far + glm::dvec3(0, 5, 0), 1}), std::pow(0.25, 4.0 / 4), 1e-12);
}

// The sky: 8 * 4^k triangle centres of Leech's sphere (k from the samples asked for), unit,
// the upper hemisphere weighted 1 and the lower `lower to upper ratio`, summing to 1.
TEST(Chiba, TheSkyIsLeechsSphereWeightedByHemisphere) {
  Chiba c;
  c.samples = 128;
  c.lower_to_upper = 0.25;
  const auto s = chiba_samples(c);
  ASSERT_EQ(s.size(), 128u);
  double up = 0, down = 0;
  for (const ChibaSample& x : s) {
    EXPECT_NEAR(glm::length(x.direction), 1, 1e-15);
    (x.direction.y >= 0 ? up : down) += x.intensity;
  }
  EXPECT_NEAR(up + down, 1, 1e-14);
  EXPECT_NEAR(down / up, 0.25, 1e-14);
  c.samples = 20;  // 32 at the next level
  EXPECT_EQ(chiba_samples(c).size(), 32u);
  c.samples = 1;
  EXPECT_EQ(chiba_samples(c).size(), 8u);
  // Alone, a ball gets all the light; the brightest direction of a sky without its lower
  // half is straight up (the sphere is symmetric about y).
  c.samples = 128;
  c.lower_to_upper = 0;
  const auto a = chiba_answers(c, std::vector<ChibaBall>{{{0, 0, 0}, 1}});
  EXPECT_NEAR(a[0].light, 1, 1e-14);
  EXPECT_NEAR(a[0].brightest.y, 1, 1e-12);
  c.cie_sky = true;
  double cie = 0;
  for (const ChibaSample& x : chiba_samples(c)) {
    cie += x.intensity;
    EXPECT_TRUE(x.direction.y > 0 || x.intensity == 0);
  }
  EXPECT_NEAR(cie, 1, 1e-14);
}

// The grid finds every ball a ray meets: random clouds (radii spread tenfold, both modes,
// with a beam) answer as testing all balls in order does.
TEST(Chiba, TheGridWalkAnswersAsTestingEveryBall) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1), r(0.02, 0.2);
  for (int round = 0; round < 4; ++round) {
    Chiba c;
    c.samples = 32;
    c.lower_to_upper = 0.5;
    c.transmittance = 0.3;
    c.estimate_area = round % 2 == 1;
    c.beam_radius = round >= 2 ? 0.5 : (c.estimate_area ? 1 : 0);
    std::vector<ChibaBall> balls(400);
    for (ChibaBall& b : balls) b = {{u(rng) * 3, u(rng), u(rng) * 0.5}, r(rng)};
    const auto fast = chiba_answers(c, balls);
    const auto samples = chiba_samples(c);
    for (size_t i = 0; i < balls.size(); i += 7) {
      double sum = 0;
      for (const ChibaSample& s : samples) {
        double keep = 1;
        for (size_t j = 0; j < balls.size(); ++j)
          if (j != i) keep *= chiba_dimming(c, balls[i].centre, balls[i].radius, s.direction, balls[j]);
        sum += s.intensity * keep;
      }
      EXPECT_NEAR(fast[i].light, sum, 1e-12 * std::max(1.0, sum)) << "round " << round << " ball " << i;
    }
  }
}

// honda81: 0 where another query of the same index and at least the vigor lies within the radius.
TEST(Honda81, AQueryNearAsVigorousAOneOfItsIndexAnswersZero) {
  lsys::Grammar::Honda81 h;
  h.radius = 0.5;
  h.three_d = true;
  const std::vector<Honda81Query> q = {{{0, 0, 0}, 1, 0}, {{0, 0.3, 0}, 2, 0}, {{0, 0.3, 0.1}, 2, 1}};
  EXPECT_EQ(honda81_answers(h, q), (std::vector<double>{0, 1, 1}));
}

}  // namespace
}  // namespace sylva
