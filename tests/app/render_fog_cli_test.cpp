// render_fog_cli_test.cpp — `sylva render` on scenes with fog (docs/spec/cli.md's fog flags,
// docs/spec/fog.md's `fog` AOV), as a user runs it.
// Every render here passes --spp 1 (the pixel centres): these tests are about what is
// drawn, not how it is sampled, and the default of 8 samples would cost 8 times the time
// (RenderCli.TheDefaultIsEightSamplesPerPixel pins the default).
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/support/process.h"
#include "tests/support/requirements.h"

namespace {

const std::string kSaguaro = std::string(SYLVA_SOURCE_DIR) + "/presets/saguaro.lsys";

std::vector<std::string> channel_names(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return {"<cannot open " + path + ">"};
  std::vector<std::string> names = in->spec().channelnames;
  std::sort(names.begin(), names.end());
  return names;
}

// A small saguaro scene; `fog` is the scene's fog member (empty: none).
std::string write_scene(TempDir& dir, const std::string& fog) {
  std::filesystem::copy_file(kSaguaro, dir.file("cactus.lsys"), std::filesystem::copy_options::overwrite_existing);
  dir.write("f.scene.json", R"({"image": {"width": 32, "height": 24},
  "camera": {"eye": [8, 4, 8], "target": [0, 3, 0]},
  "sun": {"direction": [-0.5, 0.6, -0.4], "angular_radius_deg": 0.27},
  )" + (fog.empty() ? std::string() : "\"fog\": " + fog + ",") +
                                R"(
  "plants": [{"grammar": "cactus.lsys", "steps": 4}]})");
  return dir.file("f.scene.json");
}

const char* const kFog = R"({"sigma_s": 0.05, "sigma_a": 0.01, "g": 0.6, "top": 20, "mode": "brute", "steps": 4})";

// The fog AOV's channels, and fog.T in (0, 1] everywhere, from `backend`; false (the test
// skipped) where it is gl and no OpenGL context can be made.
bool expect_fog_render(const std::string& backend, const char* fog_pass) {
  TempDir dir;
  const std::string scene = write_scene(dir, kFog);
  ProcessResult r =
      run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.exr"), "--aov", "fog,depth", "--verbose", "--backend", backend});
  if (backend == "gl" && r.exit_code == 1 && r.err.find("no OpenGL 4.5 core context") != std::string::npos) return false;
  EXPECT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find(fog_pass), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("brute, 4 steps"), std::string::npos) << describe(r);
  std::vector<std::string> expected = {"R", "G", "B", "A", "Z", "fog.R", "fog.G", "fog.B", "fog.T"};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(channel_names(dir.file("f.exr")), expected);
  // fog.T is a transmittance: in (0, 1] everywhere; the sky pixels' is that of the fog up
  // to its top.
  auto in = OIIO::ImageInput::open(dir.file("f.exr"));
  EXPECT_TRUE(in);
  if (!in) return true;
  const OIIO::ImageSpec& spec = in->spec();
  const int t_channel = spec.channelindex("fog.T");
  EXPECT_GE(t_channel, 0);
  if (t_channel < 0) return true;
  std::vector<float> t(32 * 24);
  EXPECT_TRUE(in->read_image(0, 0, t_channel, t_channel + 1, OIIO::TypeDesc::FLOAT, t.data()));
  for (float v : t) {
    EXPECT_GT(v, 0.0f);
    EXPECT_LE(v, 1.0f);
  }
  return true;
}

TEST(RenderFogCli, AFoggySceneRendersOnTheCpuWithTheFogPassAndTheFogAov) {
  expect_fog_render("cpu", "fog (thread time)");
}

TEST(RenderFogCli, AFoggySceneInBruteRendersWithOpenGlWithTheFogPassAndTheFogAov) {
  if (!expect_fog_render("gl", "fog (GPU)")) SYLVA_SKIP_WITHOUT_GL("no OpenGL context on this machine");
}

// medium draws on the GL backend (its cones built as for fast, the map marched inside them).
TEST(RenderFogCli, MediumRendersWithOpenGlWithItsConesAndTheFogPass) {
  TempDir dir;
  const std::string scene = write_scene(dir, R"({"sigma_s": 0.05, "g": 0.6, "top": 20, "steps": 4, "photons": 20000})");
  ProcessResult r = run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "gl", "--fog-mode", "medium",
                               "--verbose"});
  if (r.exit_code == 1 && r.err.find("no OpenGL 4.5 core context") != std::string::npos)
    SYLVA_SKIP_WITHOUT_GL("no OpenGL context on this machine");
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("medium, 4 steps"), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("fog[FOG_MEDIUM SUN]"), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("cone upload"), std::string::npos) << describe(r);
  EXPECT_TRUE(std::filesystem::exists(dir.file("f.png")));
}

TEST(RenderFogCli, PngPutsTheFogAovInASideFile) {
  TempDir dir;
  const std::string scene = write_scene(dir, kFog);
  ProcessResult r = run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--aov", "fog", "--backend", "cpu",
                               "--fog-mode", "reference", "--fog-steps", "2"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  std::vector<std::string> expected = {"fog.R", "fog.G", "fog.B", "fog.T"};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(channel_names(dir.file("f.fog.exr")), expected);
}

TEST(RenderFogCli, TheGlBackendRefusesTheFogModesItLacksWithStatusOneAndAutoFallsBackToTheCpu) {
  TempDir dir;
  const std::string scene = write_scene(dir, kFog);
  ProcessResult r = run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "gl", "--fog-mode", "refined"});
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("fog pass runs brute, medium, fast and map (auto) only (the fog asks for refined"), std::string::npos)
      << describe(r);
  EXPECT_FALSE(std::filesystem::exists(dir.file("f.png")));
  r = run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--fog-mode", "reference", "--fog-steps", "2", "--verbose"});
  EXPECT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("the OpenGL backend cannot draw this (the GL backend's fog pass runs brute, medium, fast and map (auto) only"),
            std::string::npos)
      << describe(r);
  EXPECT_NE(r.err.find("fog (thread time)"), std::string::npos) << describe(r);
}

TEST(RenderFogCli, BadFogFlagsAreUsageErrors) {
  TempDir dir;
  const std::string scene = write_scene(dir, kFog);
  struct Bad {
    std::vector<std::string> flags;
    const char* says;
  };
  const Bad bad[] = {
      {{"--photons", "0"}, "--photons 0: expected an integer from 1 to 1000000000"},
      {{"--photons", "-5"}, "--photons -5"},
      {{"--photons", "2000000000"}, "--photons 2000000000"},
      {{"--photons", "many"}, "--photons many"},
      {{"--fog-steps", "0"}, "--fog-steps 0: expected an integer from 1 to 65536"},
      {{"--fog-steps", "1000000"}, "--fog-steps 1000000"},
      {{"--fog-steps", "1.5"}, "--fog-steps 1.5"},
      {{"--fog-mode", "warp"}, "--fog-mode warp: expected auto, brute, medium, fast, refined, reference or map"},
      {{"--fog-map-resolution", "1000"}, "--fog-map-resolution 1000: expected a multiple of 32 from 32 to 65536"},
      {{"--fog-map-resolution", "0"}, "--fog-map-resolution 0: expected a multiple of 32"},
      {{"--fog-map-directions", "65"}, "--fog-map-directions"},
      {{"--cone-params", "96,8,24"}, "--cone-params 96,8,24: expected auto or p1,p2,p3,p4"},
      {{"--cone-params", "96,8,24,16,2"}, "expected auto or p1,p2,p3,p4"},
      {{"--cone-params", "0,0,0,0"}, "expected auto or p1,p2,p3,p4"},
      {{"--cone-params", "24,8,24,16"}, "p1 >= p3 + 1"},  // p1 must exceed p3
      {{"--cone-params", "96,1,24,16"}, "p2 >= 2"},
      {{"--cone-params", "96,8,24,0"}, "p4 >= 1"},
      {{"--cone-params", "96,8,24,1000000"}, "each at most 100000"},
      {{"--cone-params", "a,b,c,d"}, "expected auto or p1,p2,p3,p4"},
      {{"--cone-params", "96,,24,16"}, "expected auto or p1,p2,p3,p4"},
      {{"--cone-params", "automatic"}, "expected auto or p1,p2,p3,p4"},
      {{"--aov", "fogg"}, "unknown AOV 'fogg'"},
  };
  for (const Bad& b : bad) {
    std::vector<std::string> args = {"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "cpu"};
    args.insert(args.end(), b.flags.begin(), b.flags.end());
    ProcessResult r = run_sylva(args);
    EXPECT_EQ(r.exit_code, 2) << b.flags[0] << " " << b.flags[1] << ": " << describe(r);
    EXPECT_NE(r.err.find(b.says), std::string::npos) << describe(r);
    EXPECT_FALSE(std::filesystem::exists(dir.file("f.png")));
  }
}

TEST(RenderFogCli, GoodConeParamsAndPhotonsAreAccepted) {
  TempDir dir;
  const std::string scene = write_scene(dir, kFog);
  for (const char* params : {"auto", "96,8,24,16", "25,2,24,1"}) {
    ProcessResult r = run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "cpu", "--photons", "1000",
                                 "--cone-params", params, "--fog-steps", "2"});
    EXPECT_EQ(r.exit_code, 0) << params << ": " << describe(r);
  }
}

TEST(RenderFogCli, FogFlagsOnASceneWithoutFogAreUsageErrors) {
  TempDir dir;
  const std::string scene = write_scene(dir, "");
  for (const std::vector<std::string>& flags : std::vector<std::vector<std::string>>{
           {"--fog-mode", "brute"}, {"--fog-steps", "8"}, {"--photons", "10"}, {"--cone-params", "auto"},
           {"--aov", "fog"}}) {
    std::vector<std::string> args = {"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "cpu"};
    args.insert(args.end(), flags.begin(), flags.end());
    ProcessResult r = run_sylva(args);
    EXPECT_EQ(r.exit_code, 2) << flags[0] << ": " << describe(r);
    EXPECT_NE(r.err.find("apply to a scene with fog only"), std::string::npos) << describe(r);
  }
  // Without fog and without the flags: no fog pass at all.
  ProcessResult r = run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "cpu", "--verbose"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_EQ(r.err.find("fog"), std::string::npos) << describe(r);
}

TEST(RenderFogCli, OnlyTheConeAndMapModesTraceSunPhotons) {
  TempDir dir;
  const std::string scene = write_scene(dir, R"({"mode": "fast", "top": 20, "steps": 2, "photons": 20000})");
  // The scene's own mode, then each mode from the flag: the cone modes list the photon and
  // cone passes, map (and auto, which is map on the CPU) the photons and its sun maps;
  // brute and reference trace no photons.
  struct Case {
    std::vector<std::string> flags;
    bool photons, cones;
    const char* mode;
  };
  const Case cases[] = {{{}, true, true, "fast"},
                        {{"--fog-mode", "medium"}, true, true, "medium"},
                        {{"--fog-mode", "refined"}, true, true, "refined"},
                        {{"--fog-mode", "map"}, true, false, "map"},
                        {{"--fog-mode", "auto"}, true, false, "map (auto)"},
                        {{"--fog-mode", "brute"}, false, false, "brute"},
                        {{"--fog-mode", "reference"}, false, false, "reference"}};
  for (const Case& c : cases) {
    std::vector<std::string> args = {"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "cpu", "--verbose"};
    args.insert(args.end(), c.flags.begin(), c.flags.end());
    ProcessResult r = run_sylva(args);
    ASSERT_EQ(r.exit_code, 0) << c.mode << ": " << describe(r);
    EXPECT_EQ(r.err.find("  photons ") != std::string::npos, c.photons) << c.mode << ": " << describe(r);
    EXPECT_EQ(r.err.find("shadow cones") != std::string::npos, c.cones) << c.mode << ": " << describe(r);
    EXPECT_EQ(r.err.find("  sun maps ") != std::string::npos, c.photons && !c.cones) << c.mode << ": " << describe(r);
    EXPECT_NE(r.err.find(std::string("fog (thread time)")), std::string::npos) << describe(r);
    EXPECT_NE(r.err.find(std::string(c.mode) + ", 2 steps"), std::string::npos) << c.mode << ": " << describe(r);
  }
}

TEST(RenderFogCli, SunMapsOverTheMemoryBoundAreBadInputAndNothingIsWritten) {
  TempDir dir;
  const std::string scene = write_scene(dir, R"({"mode": "map", "top": 20, "photons": 20000})");
  for (const char* backend : {"cpu", "gl"}) {
    ProcessResult r = run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", backend,
                                 "--fog-map-resolution", "65536", "--fog-map-directions", "64"});
    if (r.exit_code == 1 && r.err.find("no OpenGL 4.5 core context") != std::string::npos) continue;
    EXPECT_EQ(r.exit_code, 1) << backend << ": " << describe(r);
    EXPECT_NE(r.err.find("sylva render: error: the sun maps would need"), std::string::npos) << describe(r);
    EXPECT_NE(r.err.find("more than the limit of 64.0 MiB: lower the resolution or the disc directions"),
              std::string::npos)
        << describe(r);
    EXPECT_FALSE(std::filesystem::exists(dir.file("f.png")));
  }
}

// Mode map (and auto) on the GL backend: the CPU builds the sun maps (their passes listed),
// the GL fog pass walks them (render_gl_fog_test.cpp compares the images); no cones, no cone pass.
TEST(RenderFogCli, MapDrawsOnTheGlBackendWithTheCpusSunMaps) {
  TempDir dir;
  const std::string scene = write_scene(dir, R"({"mode": "map", "top": 20, "photons": 20000})");
  ProcessResult r =
      run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "gl", "--verbose"});
  if (r.exit_code == 1 && r.err.find("no OpenGL 4.5 core context") != std::string::npos)
    SYLVA_SKIP_WITHOUT_GL("no OpenGL context on this machine");
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("  sun maps "), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("  map upload "), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("fog[FOG_MAP SUN]"), std::string::npos) << describe(r);
  EXPECT_EQ(r.err.find("shadow cones"), std::string::npos) << describe(r);
  EXPECT_TRUE(std::filesystem::exists(dir.file("f.png")));
  // auto is map on the GL backend (docs/gl-fog.md sec. 2b): the same maps and pass.
  r = run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "gl", "--fog-mode", "auto",
                 "--verbose"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("  sun maps "), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("fog[FOG_MAP SUN]"), std::string::npos) << describe(r);
}

TEST(RenderFogCli, TheConeParametersAreTheFlagsOrTheAutomaticChoiceWithItsReport) {
  // --verbose prints the automatic choice's report (what it measured on random points,
  // core/cpu/photons.h AutoConeReport) or the parameters --cone-params gave.
  TempDir dir;
  const std::string scene = write_scene(dir, R"({"mode": "fast", "top": 20, "steps": 2, "photons": 20000})");
  ProcessResult r = run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "cpu", "--verbose"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("20000 photons"), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("cone parameters (automatic)"), std::string::npos) << describe(r);
  for (const char* mode : {"medium", "refined", "fast"}) {
    r = run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "cpu", "--verbose", "--fog-mode", mode,
                   "--cone-params", "41,8,8,8"});
    ASSERT_EQ(r.exit_code, 0) << mode << ": " << describe(r);
    EXPECT_NE(r.err.find("p1 41, p2 8, p3 8, p4 8"), std::string::npos) << mode << ": " << describe(r);
    EXPECT_EQ(r.err.find("cone parameters (automatic)"), std::string::npos) << mode << ": " << describe(r);
  }
}

TEST(RenderFogCli, EveryBundledFogSceneRendersOnTheCpuWithItsSunMaps) {
  // presets/scenes/'s fog scenes (crepuscular rays, height fog), small and quick: the
  // default mode (auto: map, sun maps built from sun photons) and the fog AOV.
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(SYLVA_SOURCE_DIR) + "/presets/scenes")) {
    const std::string path = entry.path().string();
    if (!path.ends_with(".scene.json") || read_file(path).find("\"fog\"") == std::string::npos) continue;
    ++scenes;
    TempDir dir;
    ProcessResult r = run_sylva({"render", "--spp", "1", path, "-o", dir.file("f.exr"), "--backend", "cpu", "--width", "48",
                                 "--height", "36", "--photons", "20000", "--fog-steps", "4", "--aov", "fog",
                                 "--verbose"});
    ASSERT_EQ(r.exit_code, 0) << path << ": " << describe(r);
    EXPECT_NE(r.err.find("  sun maps "), std::string::npos) << path << ": " << describe(r);
    EXPECT_NE(r.err.find("map (auto)"), std::string::npos) << path << ": " << describe(r);
    const std::vector<std::string> channels = channel_names(dir.file("f.exr"));
    EXPECT_NE(std::find(channels.begin(), channels.end(), "fog.T"), channels.end()) << path;
  }
  EXPECT_GE(scenes, 2);
}

TEST(RenderFogCli, BadFogKeyInASceneIsExitOneAtTheKey) {
  TempDir dir;
  const std::string scene = write_scene(dir, R"({"g": 0.99})");
  ProcessResult r = run_sylva({"render", "--spp", "1", scene, "-o", dir.file("f.png"), "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("f.scene.json:4:11: error: fog.g must be in (-0.938117, 0.938117)"), std::string::npos)
      << describe(r);
}

TEST(RenderFogCli, HelpDescribesTheFogFlags) {
  ProcessResult help = run_sylva({"render", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  for (const char* flag : {"--fog-mode", "--fog-steps", "--photons", "--cone-params", "fog.T", ".fog.exr"})
    EXPECT_NE(help.out.find(flag), std::string::npos) << flag;
}

}  // namespace
