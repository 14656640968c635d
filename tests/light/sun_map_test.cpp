// Tests for core/light/sun_map.h: the map's frame, and the walk against the slow exact
// reference — the map's own point test (lit()) at many points along random rays over random
// maps, tiles left out, gaps and all.
#include "core/light/sun_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <random>
#include <stdexcept>
#include <vector>

#include "core/geometry/skin.h"

namespace sylva {
namespace {

SunMapFrame frame_toward(const glm::dvec3& to_sun, double half, uint32_t size) {
  SunMapFrame f;
  f.centre = {1.5, 4, -2};
  f.to_sun = glm::normalize(to_sun);
  const AxisFrame a = axis_frame(f.to_sun);
  f.e0 = a.e0, f.e1 = a.e1;
  f.half_extent_m = half;
  f.size = size;
  return f;
}

// A map whose tiles are allocated with probability `fill` and whose texels hold heights in
// [−3, 3] or, with probability `gaps`, no plant.
SunDepthMap random_map(const SunMapFrame& f, double fill, double gaps, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  const uint32_t tiles = f.size / SunDepthMap::kTile;
  std::vector<uint8_t> allocated(size_t(tiles) * tiles);
  for (uint8_t& a : allocated) a = u(rng) < fill;
  SunDepthMap map(f, allocated);
  for (size_t k = 0; k < map.allocated_tiles(); ++k) {
    float* h = map.slot_texels(k);
    for (uint32_t i = 0; i < SunDepthMap::kTile * SunDepthMap::kTile; ++i)
      h[i] = u(rng) < gaps ? SunDepthMap::kNoPlant : static_cast<float>(-3 + 6 * u(rng));
    map.finish_tile(k);
  }
  return map;
}

// Whether t lies in one of the sorted, disjoint intervals.
bool inside(const std::vector<FogInterval>& lit, double t) {
  const auto it = std::upper_bound(lit.begin(), lit.end(), t, [](double x, const FogInterval& i) { return x < i.t0; });
  return it != lit.begin() && t <= std::prev(it)->t1;
}

TEST(SunMap, TexelCentresAndHeightsUseTheFrame) {
  const SunMapFrame f = frame_toward({0.2, 1, 0.1}, 8, 64);
  std::vector<uint8_t> allocated(4, 0);
  allocated[3] = 1;  // the tile of texels 32..63 in both directions
  SunDepthMap map(f, allocated);
  ASSERT_EQ(map.allocated_tiles(), 1u);
  EXPECT_EQ(map.tile_of_slot(0), 3u);
  map.slot_texels(0)[5 * 32 + 7] = 1.25f;  // texel (39, 37)
  map.finish_tile(0);
  const glm::dvec3 c = map.texel_centre(39, 37);
  EXPECT_NEAR(glm::dot(c - f.centre, f.to_sun), 0, 1e-12);
  EXPECT_NEAR(glm::dot(c - f.centre, f.e0), -8 + 39.5 * 0.25, 1e-12);
  EXPECT_EQ(map.height_at(c), 1.25f);
  EXPECT_EQ(map.height_at(c + 5.0 * f.to_sun), 1.25f);  // the same texel all along the sun
  EXPECT_FALSE(map.lit(c + 1.2 * f.to_sun));
  EXPECT_TRUE(map.lit(c + 1.3 * f.to_sun));
  EXPECT_EQ(map.height_at(map.texel_centre(38, 37)), SunDepthMap::kNoPlant);  // the tile's other texels
  EXPECT_EQ(map.height_at(map.texel_centre(3, 3)), SunDepthMap::kNoPlant);    // a tile left out
  EXPECT_EQ(map.height_at(f.centre + 9.0 * f.e0), SunDepthMap::kNoPlant);     // outside the grid
  EXPECT_TRUE(map.lit(f.centre + 9.0 * f.e0 - 100.0 * f.to_sun));
  EXPECT_THROW(SunDepthMap(frame_toward({0, 1, 0}, 8, 48), std::vector<uint8_t>(4)), std::invalid_argument);
  EXPECT_THROW(SunDepthMap(f, std::vector<uint8_t>(3)), std::invalid_argument);
}

TEST(SunMap, WalkAgreesWithThePointTestOnRandomRays) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int rays = 0, checked = 0, lit_points = 0, dark_points = 0;
  for (int m = 0; m < 6; ++m) {
    const SunMapFrame f = frame_toward({0.3 * u(rng), 1, 0.3 * u(rng)}, 5, 128);
    const SunDepthMap map = random_map(f, 0.7, 0.3, rng);
    for (int r = 0; r < 300; ++r, ++rays) {
      glm::dvec3 d = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
      if (r % 10 == 0) d = glm::normalize(f.to_sun + 0.01 * glm::dvec3(u(rng), u(rng), u(rng)));  // near the sun
      if (r % 10 == 1) d = glm::normalize(glm::cross(f.to_sun, f.e0) + 0.3 * f.e1);  // level in height
      if (r % 10 == 2) d = f.e0;  // along the grid's rows
      const glm::dvec3 o = f.centre + glm::dvec3(6 * u(rng), 6 * u(rng), 6 * u(rng));
      const double t0 = 2 * u(rng), t1 = t0 + 12;
      std::vector<FogInterval> lit;
      SunMapWalkStats stats;
      map.lit_parts(o, d, t0, t1, &lit, &stats);
      // Sorted, disjoint, separated, inside [t0, t1].
      for (size_t i = 0; i < lit.size(); ++i) {
        ASSERT_LT(lit[i].t0, lit[i].t1);
        ASSERT_GE(lit[i].t0, t0);
        ASSERT_LE(lit[i].t1, t1);
        if (i) {
          ASSERT_LT(lit[i - 1].t1, lit[i].t0);
        }
      }
      // Each sample point agrees with the point test, away from texel edges and crossings.
      for (int k = 0; k < 400; ++k) {
        const double t = t0 + (k + 0.5) / 400 * (t1 - t0);
        const glm::dvec3 p = o + t * d;
        const glm::dvec3 q = p - f.centre;
        const double x = (glm::dot(q, f.e0) + f.half_extent_m) / f.texel_m();
        const double y = (glm::dot(q, f.e1) + f.half_extent_m) / f.texel_m();
        const double edge = std::min(std::abs(x - std::round(x)), std::abs(y - std::round(y)));
        const double h = glm::dot(q, f.to_sun);
        if (edge < 1e-6 || std::abs(h - map.height_at(p)) < 1e-6) continue;
        ++checked;
        const bool truth = map.lit(p);
        (truth ? lit_points : dark_points) += 1;
        ASSERT_EQ(inside(lit, t), truth) << "map " << m << " ray " << r << " t " << t;
      }
    }
  }
  EXPECT_EQ(rays, 1800);
  EXPECT_GT(checked, 600000);
  EXPECT_GT(lit_points, 100000);  // both answers were tested often
  EXPECT_GT(dark_points, 30000);
}

TEST(SunMap, WalkSkipsTilesAboveThePlantsAndEmptyTiles) {
  std::mt19937_64 rng(3);
  const SunMapFrame f = frame_toward({0, 1, 0}, 5, 128);
  const SunDepthMap map = random_map(f, 0.5, 0.0, rng);
  // A ray far above every height (heights are at most 3): one lit piece, no texel tested.
  std::vector<FogInterval> lit;
  SunMapWalkStats stats;
  map.lit_parts(f.centre + glm::dvec3(-6, 10, 0.3), glm::dvec3(1, 0, 0), 0, 12, &lit, &stats);
  ASSERT_EQ(lit.size(), 1u);
  EXPECT_EQ(lit[0].t0, 0);
  EXPECT_EQ(lit[0].t1, 12);
  EXPECT_GT(stats.tiles, 2u);
  EXPECT_EQ(stats.texels, 0u);
  // Far below, with no gaps: dark wherever a tile is, texels still untested.
  lit.clear();
  stats = {};
  map.lit_parts(f.centre + glm::dvec3(-6, -10, 0.3), glm::dvec3(1, 0, 0), 0, 12, &lit, &stats);
  EXPECT_EQ(stats.texels, 0u);
  double lit_length = 0;
  for (const FogInterval& i : lit) lit_length += i.t1 - i.t0;
  EXPECT_GT(lit_length, 2);   // outside the grid, and the tiles left out
  EXPECT_LT(lit_length, 10);  // but not the allocated tiles
  // Appending merges with a touching piece the caller put there.
  lit = {{-1, 0}};
  map.lit_parts(f.centre + glm::dvec3(-6, 10, 0.3), glm::dvec3(1, 0, 0), 0, 12, &lit);
  ASSERT_EQ(lit.size(), 1u);
  EXPECT_EQ(lit[0].t0, -1);
  EXPECT_EQ(lit[0].t1, 12);
}

TEST(SunMap, AppendLitMergesTouchingPieces) {
  std::vector<FogInterval> lit;
  append_lit(&lit, 0, 1);
  append_lit(&lit, 1, 2);
  append_lit(&lit, 3, 3);  // empty: dropped
  append_lit(&lit, 4, 5);
  ASSERT_EQ(lit.size(), 2u);
  EXPECT_EQ(lit[0].t1, 2);
  EXPECT_EQ(lit[1].t0, 4);
}

}  // namespace
}  // namespace sylva
