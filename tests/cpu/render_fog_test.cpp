// render_fog_test.cpp — the CPU renderer through fog (docs/spec/fog.md, "What a pixel sees" and
// "Outputs"): beauty = fog.T·L_end + fog.RGB with L_end computed here independently, the
// sunlight on surfaces attenuated by T_sun, what a ray that leaves the fog sees, and that a
// scene without fog runs none of it.
#include "core/cpu/render_cpu.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/cpu/sun_maps.h"
#include "core/light/fog.h"
#include "core/scene/fog_integrator.h"
#include "core/util/math.h"
#include "tests/support/test_scenes.h"

namespace sylva {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// test_scenes.h's foggy cylinder, 48 × 36, 8 steps.
Scene foggy_cylinder(FogMode mode = FogMode::brute) { return test::foggy_cylinder(mode, 8); }

bool has_pass(const RenderResult& r, const std::string& prefix) {
  return std::any_of(r.passes.begin(), r.passes.end(),
                     [&](const RenderPass& p) { return p.name.rfind(prefix, 0) == 0; });
}

TEST(RenderFog, ASceneWithoutFogRunsNoneOfIt) {
  Scene s = foggy_cylinder();
  s.fog.reset();
  RenderOptions o;
  o.aovs = kAovFog;
  const RenderResult r = render_cpu(s, o);
  EXPECT_FALSE(has_pass(r, "fog"));
  EXPECT_FALSE(has_pass(r, "photons"));
  EXPECT_FALSE(has_pass(r, "cones"));
  EXPECT_FALSE(has_pass(r, "sun maps"));
  EXPECT_TRUE(r.image.fog.empty());  // no fog, no fog AOV
  // Nor does mode map build its maps without fog.
  o.fog.mode = FogMode::map;
  EXPECT_FALSE(has_pass(render_cpu(s, o), "sun maps"));
}

TEST(RenderFog, AFoggySceneListsTheFogPassAndBruteAndReferenceTraceNoPhotons) {
  for (FogMode mode : {FogMode::brute, FogMode::reference}) {
    Scene s = foggy_cylinder(mode);
    s.fog->steps = 2;
    const RenderResult r = render_cpu(s, {});
    ASSERT_TRUE(has_pass(r, "fog")) << fog_mode_name(mode);
    const auto fog = std::find_if(r.passes.begin(), r.passes.end(),
                                  [](const RenderPass& p) { return p.name.rfind("fog", 0) == 0; });
    EXPECT_NE(fog->detail.find(fog_mode_name(mode)), std::string::npos) << fog->detail;
    EXPECT_NE(fog->detail.find(std::to_string(48 * 36) + " rays"), std::string::npos) << fog->detail;
    EXPECT_GT(fog->seconds, 0);
    EXPECT_FALSE(has_pass(r, "photons")) << fog_mode_name(mode);
    EXPECT_FALSE(has_pass(r, "cones")) << fog_mode_name(mode);
  }
}

TEST(RenderFog, BeautyIsFogTransmittanceTimesWhatIsSeenPlusTheFogsLight) {
  const Scene s = foggy_cylinder();
  RenderOptions o;
  o.aovs = kAovFog | kAovDepth;
  const RenderResult r = render_cpu(s, o);
  ASSERT_EQ(r.image.fog.size(), size_t(48 * 36 * 4));
  const FogMedium m = fog_medium_of(s);
  const glm::dvec3 sun = s.sun.direction;
  const SceneGeometry geometry = build_scene_geometry(s, {});
  int ground = 0, sky = 0, plant = 0;
  for (uint32_t j = 0; j < s.height; ++j)
    for (uint32_t i = 0; i < s.width; ++i) {
      const size_t p = static_cast<size_t>(j) * s.width + i;
      const float* fog = &r.image.fog[p * 4];
      const float* beauty = &r.image.beauty[p * 4];
      const Ray ray = camera_ray(s, i + 0.5, j + 0.5);
      const double length = glm::length(ray.direction);
      const glm::dvec3 d = ray.direction / length;
      glm::dvec3 end;
      double t_end;
      if (std::isfinite(r.image.depth[p])) {  // the plant: L_end is its shading; check T only
        ++plant;
        t_end = r.image.depth[p];
        EXPECT_NEAR(fog[3], fog_transmittance(m, ray.origin, d, 0, t_end), 2e-6) << i << "," << j;
        for (int c = 0; c < 3; ++c) EXPECT_GE(beauty[c], fog[c] * (1 - 1e-6f)) << i << "," << j;
        continue;
      }
      if (d.y < 0) {  // the ground: ρ_g·L_sky + ρ_g/π·E_sun·(n·s)·V·T_sun
        ++ground;
        t_end = -ray.origin.y / d.y;
        const glm::dvec3 x = ray.origin + t_end * d;
        const bool shadowed = geometry.tracer->any(Ray{x + glm::dvec3(0, 1e-7 * 6, 0), sun}, 0, kInf);
        const double t_sun = fog_sun_transmittance(m, x, sun);
        EXPECT_LT(t_sun, 0.25);  // 30 m of fog toward the sun: sunlight visibly dimmed
        end = s.ground.albedo * s.sky + (shadowed ? 0.0 : sun.y * t_sun / kPi) * s.ground.albedo * s.sun.radiance;
      } else {  // the sky, through the fog up to its top
        ++sky;
        t_end = kInf;
        end = s.sky;
      }
      EXPECT_NEAR(fog[3], fog_transmittance(m, ray.origin, d, 0, t_end), 2e-7) << i << "," << j;
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(beauty[c], fog[3] * end[c] + fog[c], 2e-6 * (1 + beauty[c])) << i << "," << j << " channel " << c;
    }
  EXPECT_GT(ground, 100);
  EXPECT_GT(sky, 100);
  EXPECT_GT(plant, 50);
}

TEST(RenderFog, ARayLeavingHeightFogWithoutATopSeesTheAttenuatedSky) {
  Scene s = foggy_cylinder();
  s.fog->top = kInf;
  s.fog->height_falloff = 0.2;
  RenderOptions o;
  o.aovs = kAovFog;
  const RenderResult r = render_cpu(s, o);
  const FogMedium m = fog_medium_of(s);
  const uint32_t i = 2, j = 1;  // top-left: sky
  const Ray ray = camera_ray(s, i + 0.5, j + 0.5);
  const glm::dvec3 d = glm::normalize(ray.direction);
  ASSERT_GT(d.y, 0);
  // τ(0, ∞) = σ_t·e^{−h·y0}/(h·d_y), finite: the sky shows through.
  const double tau = 0.06 * std::exp(-0.2 * 1.5) / (0.2 * d.y);
  const size_t p = static_cast<size_t>(j) * s.width + i;
  EXPECT_NEAR(r.image.fog[p * 4 + 3], std::exp(-tau), 1e-6);
  EXPECT_GT(r.image.fog[p * 4 + 3], 0.1f);
  EXPECT_NEAR(r.image.beauty[p * 4 + 2], r.image.fog[p * 4 + 3] * s.sky.z + r.image.fog[p * 4 + 2], 1e-6);
  EXPECT_NEAR(fog_transmittance(m, ray.origin, d, 0, kInf), std::exp(-tau), 1e-12);
}

TEST(RenderFog, HeightFogWithoutATopRendersInEveryModeAndAgreesWithTheReference) {
  // A climbing ray in height fog without a top integrates to kFogFar; its shadow rays start
  // only near the plant (docs/fog.md "Where shadow rays start"), never far out, where
  // Embree cannot trace. Every mode renders, and matches the reference; the reference
  // matches a top so high (150 m: ρ = e^{−30}) that nothing above it counts.
  Scene s = foggy_cylinder(FogMode::reference);
  s.fog->top = kInf;
  s.fog->height_falloff = 0.2;
  s.fog->steps = 16;
  s.fog->photons = 50000;
  RenderOptions o;
  o.aovs = kAovFog;
  const RenderResult ref = render_cpu(s, o);
  Scene capped = s;
  capped.fog->top = 150;
  const RenderResult high = render_cpu(capped, o);
  // RMSE of the fog's RGB against the reference, relative to the reference's mean.
  auto relative_rmse = [&](const RenderResult& r) {
    double err = 0, mean = 0;
    for (size_t p = 0; p < ref.image.fog.size(); p += 4)
      for (int c = 0; c < 3; ++c) {
        const double d = r.image.fog[p + c] - ref.image.fog[p + c];
        err += d * d, mean += ref.image.fog[p + c];
      }
    const double n = 3.0 * ref.image.fog.size() / 4;
    return std::sqrt(err / n) / (mean / n);
  };
  EXPECT_LT(relative_rmse(high), 1e-5);
  for (FogMode mode :
       {FogMode::brute, FogMode::medium, FogMode::fast, FogMode::refined, FogMode::automatic, FogMode::map}) {
    RenderOptions m = o;
    m.fog.mode = mode;
    const RenderResult r = render_cpu(s, m);
    ASSERT_EQ(r.image.fog.size(), ref.image.fog.size()) << fog_mode_name(mode);
    // Brute and medium sample 16 points a ray, fast darkens every cone whole: looser.
    const double tolerance =
        mode == FogMode::refined || mode == FogMode::automatic || mode == FogMode::map ? 0.01 : 0.05;
    EXPECT_LT(relative_rmse(r), tolerance) << fog_mode_name(mode);
  }
}

TEST(RenderFog, IdenticalForEveryThreadCount) {
  const Scene s = foggy_cylinder(FogMode::automatic);
  RenderOptions one, two;
  one.threads = 1, two.threads = 2;
  one.aovs = two.aovs = kAovFog;
  one.spp = two.spp = 2;
  const RenderResult a = render_cpu(s, one), b = render_cpu(s, two);
  EXPECT_EQ(a.image.beauty, b.image.beauty);
  EXPECT_EQ(a.image.fog, b.image.fog);
}

TEST(RenderFog, OptionsOverrideTheScenesModeAndSteps) {
  const Scene s = foggy_cylinder(FogMode::reference);
  RenderOptions o;
  o.fog.mode = FogMode::brute;
  o.fog.steps = 3;
  const RenderResult r = render_cpu(s, o);
  const auto fog = std::find_if(r.passes.begin(), r.passes.end(),
                                [](const RenderPass& p) { return p.name.rfind("fog", 0) == 0; });
  ASSERT_NE(fog, r.passes.end());
  EXPECT_EQ(fog->detail.rfind("brute, 3 steps", 0), 0u) << fog->detail;
  // A cone mode traces sun photons into shadow cones first (and brute above traced none).
  EXPECT_EQ(std::find_if(r.passes.begin(), r.passes.end(), [](const RenderPass& p) { return p.name == "photons"; }),
            r.passes.end());
  o.fog.mode = FogMode::fast;
  o.fog.photons = 20000;
  const RenderResult f = render_cpu(s, o);
  EXPECT_NE(std::find_if(f.passes.begin(), f.passes.end(), [](const RenderPass& p) { return p.name == "photons"; }),
            f.passes.end());
  const auto fast = std::find_if(f.passes.begin(), f.passes.end(),
                                 [](const RenderPass& p) { return p.name.rfind("fog", 0) == 0; });
  ASSERT_NE(fast, f.passes.end());
  EXPECT_EQ(fast->detail.rfind("fast, 3 steps", 0), 0u) << fast->detail;
  EXPECT_NE(fast->detail.find("shadow cones"), std::string::npos) << fast->detail;
}

TEST(RenderFog, SurfacesReceiveSunlightAttenuatedByTheFog) {
  // The same scene with a fog that only absorbs (σ_s = 0: it scatters nothing toward the
  // eye): a ground pixel's sunlit part shrinks by T_sun, its sky ambient part does not, and
  // both by T along the camera ray.
  Scene clear = foggy_cylinder(), foggy = foggy_cylinder();
  clear.fog.reset();
  foggy.fog->sigma_s = 0;
  foggy.fog->sigma_a = 0.02;
  const RenderResult a = render_cpu(clear, {}), b = render_cpu(foggy, {});
  const FogMedium m = fog_medium_of(foggy);
  const uint32_t i = 24, j = 34;  // bottom middle: the ground, in the sun
  const Ray ray = camera_ray(clear, i + 0.5, j + 0.5);
  const glm::dvec3 d = glm::normalize(ray.direction);
  const double t = -ray.origin.y / d.y;
  const glm::dvec3 x = ray.origin + t * d;
  const double T = fog_transmittance(m, ray.origin, d, 0, t), t_sun = fog_sun_transmittance(m, x, clear.sun.direction);
  const size_t p = static_cast<size_t>(j) * clear.width + i;
  const double ambient = clear.ground.albedo.x * clear.sky.x;
  const double sunlit_clear = a.image.beauty[p * 4] - ambient;
  EXPECT_GT(sunlit_clear, 0.1);
  EXPECT_NEAR(b.image.beauty[p * 4], T * (ambient + t_sun * sunlit_clear), 1e-6);
}

TEST(RenderFog, MapModeBuildsItsMapsFromPhotonsAndCastsNoShadowRays) {
  Scene s = foggy_cylinder(FogMode::map);
  s.sun.angular_radius_deg = 0.27;  // a disc: one map per direction (a point sun has one)
  RenderOptions o;
  o.fog.map_resolution = 512;
  o.fog.map_directions = 3;
  const RenderResult r = render_cpu(s, o);
  EXPECT_TRUE(has_pass(r, "photons"));
  EXPECT_FALSE(has_pass(r, "cones"));  // the maps' tiles are the index (docs/fog-map.md)
  const auto maps = std::find_if(r.passes.begin(), r.passes.end(), [](const RenderPass& p) { return p.name == "sun maps"; });
  ASSERT_NE(maps, r.passes.end());
  EXPECT_EQ(maps->detail.rfind("3 maps of 512²", 0), 0u) << maps->detail;
  const auto fog = std::find_if(r.passes.begin(), r.passes.end(),
                                [](const RenderPass& p) { return p.name.rfind("fog", 0) == 0; });
  ASSERT_NE(fog, r.passes.end());
  EXPECT_EQ(fog->detail.rfind("map, ", 0), 0u) << fog->detail;
  EXPECT_NE(fog->detail.find(" 0 shadow rays"), std::string::npos) << fog->detail;
  EXPECT_EQ(fog->detail.find(" 0 map texels"), std::string::npos) << fog->detail;
  // Maps over the memory bound are refused with what they would need.
  o.fog.map_resolution = 65536;
  o.fog.map_directions = 64;
  try {
    (void)render_cpu(s, o);
    ADD_FAILURE() << "no error";
  } catch (const SunMapsRefused& e) {  // bad input (the CLI's exit 1), not a fault
    EXPECT_NE(std::string(e.what()).find("more than the limit of 64.0 MiB"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sylva
