// `sylva derive|grow GRAMMAR --scene FILE --verbose` with light queries (docs/spec/light.md):
// a grammar grows beside a scene's plants, their errors are placed at the scene's keys,
// --verbose reports what the light cost, and a grammar without ?E traces nothing.
#include <gtest/gtest.h>

#include <string>

#include "tests/support/process.h"

namespace {

// An apex that climbs while it is lit and stops in shade; a query at its tip.
constexpr const char* kApex =
    "module: A\n"
    "derivation length: 6\n"
    "axiom: A ?E(1)\n"
    "A > ?E(q) : q > 0.5 -> F(0.5) A\n";

TEST(LightCli, GrowBesideAScenesPlantsUnderTheirShade) {
  TempDir dir;
  const std::string apex = dir.write("apex.lsys", kApex);
  // A horizontal disc-shaped canopy 1.6 m up over the origin: four-sided leaf, 2 m wide.
  const std::string canopy = dir.write(
      "canopy.lsys",
      "axiom: f(1.6) &(90) f(1) { . +(90) f(1) . +(90) f(2) . +(90) f(2) . +(90) f(2) . +(90) f(1) . }\n");
  const std::string scene = dir.write(
      "shade.scene.json",
      "{\"format\": \"sylva-scene\", \"version\": 1, \"sun\": {\"direction\": [0, 1, 0], \"angular_radius_deg\": 0.27},\n"
      " \"environment\": {\"photons\": 200000, \"sensor_radius_m\": 0.05},\n"
      " \"plants\": [{\"grammar\": \"canopy.lsys\"}]}\n");
  auto alone = run_process({SYLVA_BINARY, "derive", apex, "--verbose"}, SYLVA_SOURCE_DIR, 120);
  ASSERT_EQ(alone.exit_code, 0) << describe(alone);
  EXPECT_NE(alone.out.find("F(0.5)F(0.5)F(0.5)F(0.5)F(0.5)F(0.5)A"), std::string::npos) << alone.out;
  EXPECT_NE(alone.err.find("light: 7 answers, 7 queries"), std::string::npos) << alone.err;
  // Under the canopy and a zenith sun the apex is in shade from the axiom on: it never grows.
  auto shaded = run_process({SYLVA_BINARY, "derive", apex, "--scene", scene}, SYLVA_SOURCE_DIR, 120);
  ASSERT_EQ(shaded.exit_code, 0) << describe(shaded);
  EXPECT_EQ(shaded.out, "A?E(0)\n") << shaded.out;
  const std::string skel = dir.file("apex.skel.json");
  auto grown = run_process({SYLVA_BINARY, "grow", apex, "--scene", scene, "-o", skel, "--verbose"}, SYLVA_SOURCE_DIR, 120);
  ASSERT_EQ(grown.exit_code, 0) << describe(grown);
  EXPECT_NE(grown.out.find("0 segments"), std::string::npos) << grown.out;
  EXPECT_NE(grown.err.find("light: "), std::string::npos) << grown.err;
}

TEST(LightCli, ANeighboursErrorIsPlacedAtTheScenesKey) {
  TempDir dir;
  const std::string apex = dir.write("apex.lsys", kApex);
  dir.write("broken.lsys", "axiom: A\nA -> B(1/0)\n");
  const std::string scene = dir.write(
      "bad.scene.json", "{\"format\": \"sylva-scene\", \"version\": 1,\n \"plants\": [{\"grammar\": \"broken.lsys\"}]}\n");
  auto r = run_process({SYLVA_BINARY, "derive", apex, "--scene", scene}, SYLVA_SOURCE_DIR, 120);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("broken.lsys:2:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bad.scene.json:2:"), std::string::npos) << r.err;  // the note at plants[0].grammar
}

TEST(LightCli, EnvironmentKeysOutOfRangeAreErrorsAtTheKey) {
  TempDir dir;
  const std::string apex = dir.write("apex.lsys", kApex);
  for (const char* env : {"\"photons\": 0", "\"sky\": \"cloudy\"", "\"sensor_radius_m\": -1", "\"every\": 0",
                          "\"sun_fraction\": 2", "\"bogus\": 1"}) {
    const std::string scene = dir.write("env.scene.json", std::string("{\"format\": \"sylva-scene\", \"version\": 1,\n") +
                                                              " \"environment\": {" + env + "},\n \"plants\": []}\n");
    auto r = run_process({SYLVA_BINARY, "derive", apex, "--scene", scene}, SYLVA_SOURCE_DIR, 60);
    EXPECT_EQ(r.exit_code, 1) << env << describe(r);
    EXPECT_NE(r.err.find("env.scene.json:2:"), std::string::npos) << env << ": " << r.err;
  }
}

}  // namespace
