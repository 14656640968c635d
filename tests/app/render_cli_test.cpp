// render_cli_test.cpp — `sylva render` as a user runs it (docs/spec/cli.md, docs/spec/scene.md).
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "tests/support/process.h"
#include "tests/support/requirements.h"

namespace {

const std::string kSaguaro = std::string(SYLVA_SOURCE_DIR) + "/presets/saguaro.lsys";

// The channel names of an image, sorted: OpenEXR stores channels in alphabetical order,
// so the names are the contract, not their order.
std::vector<std::string> channel_names(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return {"<cannot open " + path + ">"};
  std::vector<std::string> names = in->spec().channelnames;
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::string> sorted(std::vector<std::string> names) {
  std::sort(names.begin(), names.end());
  return names;
}

TEST(RenderCli, SaguaroRendersToPng) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("s.png"), "--width", "160", "--height", "120",
                               "--backend", "cpu"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  auto in = OIIO::ImageInput::open(dir.file("s.png"));
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 160);
  EXPECT_EQ(in->spec().height, 120);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::UINT8);
  // Only the picture: no temporary file and no AOV files left behind.
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"s.png"});
}

// Runs `sylva render` with EGL unable to find any vendor library (libglvnd reads this
// variable), so that no OpenGL context can be made whatever the machine has.
ProcessResult run_sylva_without_egl(const std::vector<std::string>& args) {
  setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/sylva-test-no-egl-vendor.json", 1);
  ProcessResult r = run_sylva(args);
  unsetenv("__EGL_VENDOR_LIBRARY_FILENAMES");
  return r;
}

// The default is 8 samples per pixel (kDefaultRenderSpp, chosen by `sylva bench spp`:
// docs/benchmarks.md): a render without --spp says so and is the --spp 8 picture byte for
// byte, and --spp 1 (the pixel centres) is a different picture of the thin pine.
TEST(RenderCli, TheDefaultIsEightSamplesPerPixel) {
  TempDir dir;
  const std::string pine = std::string(SYLVA_SOURCE_DIR) + "/presets/pine.lsys";
  auto render = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> argv = {"render", pine, "-o", dir.file(name), "--width", "96", "--height", "72",
                                     "--backend", "cpu", "--verbose"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return run_sylva(argv);
  };
  ProcessResult d = render("default.png", {});
  ASSERT_EQ(d.exit_code, 0) << describe(d);
  EXPECT_NE(d.err.find("96x72, 8 spp, "), std::string::npos) << d.err;
  ASSERT_EQ(render("eight.png", {"--spp", "8"}).exit_code, 0);
  ASSERT_EQ(render("one.png", {"--spp", "1"}).exit_code, 0);
  EXPECT_EQ(read_file(dir.file("default.png")), read_file(dir.file("eight.png")));
  EXPECT_NE(read_file(dir.file("default.png")), read_file(dir.file("one.png")));
}

// docs/spec/cli.md: auto uses OpenGL on a GPU; where the only GL is a software rasteriser
// (llvmpipe in CI) the CPU ray caster, several times faster there, and --verbose says why;
// where no context opens, the CPU, saying so on stderr.
TEST(RenderCli, AutoBackendUsesOpenGlOnAGpuAndTheCpuOverASoftwareRasteriser) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("s.png"), "--width", "32", "--height", "24",
                               "--verbose"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_TRUE(std::filesystem::exists(dir.file("s.png")));
  if (r.err.find("OpenGL unavailable (") != std::string::npos) {
    EXPECT_NE(r.err.find("using the CPU ray caster"), std::string::npos) << describe(r);
    return;
  }
  const size_t context = r.err.find("gl context");
  ASSERT_NE(context, std::string::npos) << describe(r);
  const std::string line = r.err.substr(context, r.err.find('\n', context) - context);
  if (line.find("(software rasteriser)") != std::string::npos) {
    EXPECT_NE(line.find(": not used"), std::string::npos) << line;
    EXPECT_NE(r.err.find(", CPU ray caster (--backend auto: "), std::string::npos) << describe(r);
    EXPECT_NE(r.err.find(" is a software rasteriser, slower than the CPU ray caster; --backend gl forces it)\n"),
              std::string::npos)
        << describe(r);
    EXPECT_EQ(r.err.find("frusta (GPU)"), std::string::npos) << describe(r);
    EXPECT_EQ(r.err.find("OpenGL unavailable"), std::string::npos) << describe(r);
  } else {
    EXPECT_NE(r.err.find("OpenGL ray caster ("), std::string::npos) << describe(r);
    EXPECT_NE(r.err.find("frusta (GPU)"), std::string::npos) << describe(r);
  }
}

// Without --verbose, auto names OpenGL when it takes it, and says nothing when it takes
// the CPU over a software rasteriser (that is no failure); gl and cpu, chosen by the user,
// say nothing. --backend gl still draws with the software rasteriser.
TEST(RenderCli, AutoBackendNamesOpenGlWhenItTakesItAndIsQuietOtherwise) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("s.png"), "--width", "32", "--height", "24"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  ProcessResult verbose = run_sylva({"render", kSaguaro, "-o", dir.file("v.png"), "--width", "32", "--height", "24",
                                     "--verbose"});
  ASSERT_EQ(verbose.exit_code, 0) << describe(verbose);
  if (verbose.err.find("OpenGL ray caster (") != std::string::npos) {
    EXPECT_NE(r.err.find("sylva render: --backend auto: OpenGL ray caster ("), std::string::npos) << describe(r);
  } else if (verbose.err.find("is a software rasteriser") != std::string::npos) {
    EXPECT_EQ(r.err.find("backend"), std::string::npos) << describe(r);
    EXPECT_EQ(r.err.find("software"), std::string::npos) << describe(r);
    ProcessResult gl = run_sylva({"render", kSaguaro, "-o", dir.file("g.png"), "--width", "32", "--height", "24",
                                  "--backend", "gl", "--verbose"});
    ASSERT_EQ(gl.exit_code, 0) << describe(gl);
    EXPECT_NE(gl.err.find("OpenGL ray caster ("), std::string::npos) << describe(gl);
  }
  ProcessResult cpu = run_sylva({"render", kSaguaro, "-o", dir.file("c.png"), "--width", "32", "--height", "24",
                                 "--backend", "cpu"});
  ASSERT_EQ(cpu.exit_code, 0) << describe(cpu);
  EXPECT_EQ(cpu.err.find("--backend auto"), std::string::npos) << describe(cpu);
}

TEST(RenderCli, AutoBackendWithoutEglFallsBackToTheCpuSayingWhy) {
  TempDir dir;
  ProcessResult r = run_sylva_without_egl({"render", kSaguaro, "-o", dir.file("s.png"), "--width", "32", "--height", "24"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("OpenGL unavailable (no OpenGL 4.5 core context through EGL"), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("using the CPU ray caster"), std::string::npos) << describe(r);
  EXPECT_TRUE(std::filesystem::exists(dir.file("s.png")));
}

TEST(RenderCli, WhatTheGlBackendCannotDrawGoesToTheCpuUnderAutoAndFailsUnderGl) {
  // 17 plants, each with its own bark image: one more than the GL backend binds.
  TempDir dir;
  std::string plants;
  for (int i = 0; i < 17; ++i) {
    const std::string image = "bark" + std::to_string(i) + ".png";
    std::filesystem::copy_file(std::string(SYLVA_SOURCE_DIR) + "/presets/textures/bark.png", dir.file(image));
    plants += std::string(i ? ", " : "") + "{\"grammar\": \"" + kSaguaro + "\", \"position\": [" + std::to_string(3 * i) +
              ", 0, 0], \"bark\": {\"albedo\": \"" + image + "\"}}";
  }
  std::ofstream(dir.file("many.scene.json")) << "{\"format\": \"sylva-scene\", \"version\": 1, \"plants\": [" << plants
                                             << "]}";
  const std::string scene = dir.file("many.scene.json");
  ProcessResult r = run_sylva({"render", scene, "-o", dir.file("s.png"), "--width", "32", "--height", "24"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("the OpenGL backend cannot draw this ("), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("using the CPU ray caster"), std::string::npos) << describe(r);
  ProcessResult gl = run_sylva({"render", scene, "-o", dir.file("g.png"), "--backend", "gl"});
  EXPECT_EQ(gl.exit_code, 1) << describe(gl);
  EXPECT_NE(gl.err.find("--backend gl: the GL backend binds at most 16 distinct bark images"), std::string::npos)
      << describe(gl);
  EXPECT_FALSE(std::filesystem::exists(dir.file("g.png")));
}

// Issue 31 §6: a plant that grew nothing to draw renders (exit 0) but is named on stderr.
TEST(RenderCli, APlantThatGrewNothingIsAWarningNotASilentPicture) {
  TempDir dir;
  const std::string bare = dir.write("bare.lsys", "derivation length: 2\naxiom: A\nA -> +A\n");
  ProcessResult r = run_sylva({"render", bare, "-o", dir.file("b.png"), "--width", "32", "--height", "24",
                               "--backend", "cpu", "--spp", "1"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find(bare + ": warning: the plant has no segments and no leaves: nothing of it is drawn\n"),
            std::string::npos)
      << describe(r);
  EXPECT_TRUE(std::filesystem::exists(dir.file("b.png")));
  const std::string scene = dir.write("two.scene.json", R"({"plants": [{"grammar": ")" + kSaguaro +
                                                            R"("}, {"grammar": "bare.lsys"}]})");
  r = run_sylva({"render", scene, "-o", dir.file("s.png"), "--width", "32", "--height", "24", "--backend", "cpu",
                 "--spp", "1"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find(scene + ": warning: 1 of 2 plants has no segments and no leaves (the first: plants[1], "
                               "bare.lsys): nothing of it is drawn\n"),
            std::string::npos)
      << describe(r);
  ProcessResult plant = run_sylva({"render", kSaguaro, "-o", dir.file("p.png"), "--width", "32", "--height", "24",
                                   "--backend", "cpu", "--spp", "1"});
  EXPECT_EQ(plant.err.find("warning"), std::string::npos) << describe(plant);
}

TEST(RenderCli, GlBackendDrawsTheMeshBaseline) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("m.png"), "--width", "32", "--height", "24",
                               "--backend", "gl", "--geometry", "mesh", "--mesh-level", "1", "--verbose"});
  if (r.exit_code == 1 && r.err.find("no OpenGL 4.5 core context") != std::string::npos)
    SYLVA_SKIP_WITHOUT_GL("no OpenGL context on this machine: " << r.err);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("mesh (GPU)"), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("OpenGL rasteriser (meshes, "), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("triangles (GS 1)"), std::string::npos) << describe(r);
  EXPECT_TRUE(std::filesystem::exists(dir.file("m.png")));
}

TEST(RenderCli, GlBackendRendersWithOpenGl) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("s.png"), "--width", "64", "--height", "48",
                               "--backend", "gl", "--aov", "depth", "--verbose"});
  if (r.exit_code == 1 && r.err.find("no OpenGL 4.5 core context") != std::string::npos)
    SYLVA_SKIP_WITHOUT_GL("no OpenGL context on this machine: " << r.err);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("OpenGL ray caster ("), std::string::npos) << describe(r);
  EXPECT_EQ(r.err.find("CPU ray caster"), std::string::npos) << describe(r);
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"s.depth.exr", "s.png"}));
}

TEST(RenderCli, GlBackendWithoutEglExitsOneSayingWhyAndWritesNothing) {
  TempDir dir;
  ProcessResult r = run_sylva_without_egl({"render", kSaguaro, "-o", dir.file("s.png"), "--backend", "gl"});
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("--backend gl: no OpenGL 4.5 core context through EGL"), std::string::npos) << describe(r);
  EXPECT_FALSE(std::filesystem::exists(dir.file("s.png")));
}

TEST(RenderCli, ExrHoldsTheAovChannelsOfCliMd) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("s.exr"), "--width", "40", "--height", "30",
                               "--aov", "depth,normal,uv,id", "--backend", "cpu"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_EQ(channel_names(dir.file("s.exr")),
            sorted({"R", "G", "B", "A", "Z", "N.X", "N.Y", "N.Z", "U", "V", "id.plant", "id.chain",
                    "id.segment"}));
}

TEST(RenderCli, PngAovsGoToSideFilesWithCliMdChannels) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("s.png"), "--width", "40", "--height", "30",
                               "--aov", "depth,normal,uv,id", "--backend", "cpu"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_EQ(channel_names(dir.file("s.depth.exr")), std::vector<std::string>{"Z"});
  EXPECT_EQ(channel_names(dir.file("s.normal.exr")), sorted({"N.X", "N.Y", "N.Z"}));
  EXPECT_EQ(channel_names(dir.file("s.uv.exr")), sorted({"U", "V"}));
  EXPECT_EQ(channel_names(dir.file("s.id.exr")), sorted({"id.plant", "id.chain", "id.segment"}));
  // Depth is +inf where nothing is hit (the top-left corner is sky).
  auto in = OIIO::ImageInput::open(dir.file("s.depth.exr"));
  ASSERT_TRUE(in);
  std::vector<float> z(40 * 30);
  ASSERT_TRUE(in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, z.data()));
  EXPECT_TRUE(std::isinf(z[0]) && z[0] > 0);
}

TEST(RenderCli, UnknownAovIsAUsageError) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("s.png"), "--aov", "depth,albedo"});
  EXPECT_EQ(r.exit_code, 2) << describe(r);
  EXPECT_NE(r.err.find("albedo"), std::string::npos);
}

TEST(RenderCli, SceneFileRendersItsPlantsRelativeToTheScene) {
  TempDir dir;
  std::filesystem::copy_file(kSaguaro, dir.file("cactus.lsys"));
  dir.write("a.scene.json", R"({"image": {"width": 48, "height": 36},
  "camera": {"eye": [8, 4, 8], "target": [0, 3, 0]},
  "plants": [{"grammar": "cactus.lsys", "position": [1, 0, 0], "rotate_y_deg": 30},
             {"grammar": "cactus.lsys", "seed": 5, "position": [-2, 0, -1], "scale": 0.7},
             {"grammar": "cactus.lsys", "position": [20, 0, 20]}]})");
  ProcessResult r = run_sylva({"render", dir.file("a.scene.json"), "-o", dir.file("a.png"), "--backend", "cpu",
                               "--verbose"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  auto in = OIIO::ImageInput::open(dir.file("a.png"));
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 48);
  // --verbose lists the passes; the third cactus stands behind the camera.
  for (const char* pass : {"culling", "1 of 3 plants culled", "skin", "accel build", "analytic frusta", "trace",
                           "shade", "write"})
    EXPECT_NE(r.err.find(pass), std::string::npos) << pass << "\n" << describe(r);
}

TEST(RenderCli, MeshGeometryListsItsTessellationAndTriangleStructure) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("s.png"), "--width", "48", "--height", "36",
                               "--backend", "cpu", "--geometry", "mesh", "--mesh-level", "1", "--verbose"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  for (const char* pass : {"culling", "skin", "tessellate", "triangles, GS 1", "accel build",
                           "Embree triangles", "(GS 1)", "trace", "shade", "write"})
    EXPECT_NE(r.err.find(pass), std::string::npos) << pass << "\n" << describe(r);
  EXPECT_EQ(run_sylva({"render", kSaguaro, "-o", dir.file("a.png"), "--geometry", "cones"}).exit_code, 2);
  EXPECT_EQ(run_sylva({"render", kSaguaro, "-o", dir.file("a.png"), "--mesh-level", "7"}).exit_code, 2);
}

TEST(RenderCli, BadSceneIsExitOneWithPlaceAndTheOldImageSurvives) {
  TempDir dir;
  dir.write("old.png", "the previous picture");
  dir.write("bad.scene.json", "{\"plants\": [],\n  \"sun\": {\"radiance\": [1, 1, 1], \"colour\": 2}}");
  ProcessResult r = run_sylva({"render", dir.file("bad.scene.json"), "-o", dir.file("old.png"), "--backend", "cpu"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("bad.scene.json:2:34: error: unknown key \"colour\""), std::string::npos) << describe(r);
  EXPECT_EQ(read_file(dir.path() / "old.png"), "the previous picture");
  EXPECT_EQ(list_dir(dir.path()).size(), 2u);  // no temporary file left
}

TEST(RenderCli, BadGrammarInSceneIsExitOneWithThePlace) {
  TempDir dir;
  dir.write("g.lsys", "axiom: F\np1: F -> F[\n");
  dir.write("s.scene.json", R"({"plants": [{"grammar": "g.lsys"}]})");
  ProcessResult r = run_sylva({"render", dir.file("s.scene.json"), "-o", dir.file("s.png"), "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("g.lsys:"), std::string::npos) << describe(r);
  EXPECT_FALSE(std::filesystem::exists(dir.file("s.png")));
}

TEST(RenderCli, AGrammarErrorInASceneShowsTheGrammarsPlaceThenTheSceneKeyThatNamedIt) {
  // docs/spec/cli.md: the grammar's own file:line:column, source line and caret, then a note at
  // the scene's "grammar" value, so an editor can underline both; nothing is written.
  TempDir dir;
  dir.write("bad.lsys", "axiom: A\nA -> F(foo(2))\n");
  dir.write("forest.scene.json", "{\"plants\": [\n  {\"seed\": 2, \"grammar\": \"bad.lsys\"}\n]}");
  const std::string expected = dir.file("bad.lsys") +
                               ":2:8: error: unknown function 'foo'\n"
                               "A -> F(foo(2))\n"
                               "       ^\n" +
                               dir.file("forest.scene.json") + ":2:26: note: plants[0].grammar names this grammar\n";
  ProcessResult r = run_sylva({"render", dir.file("forest.scene.json"), "-o", dir.file("f.png"), "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_EQ(r.err, expected) << describe(r);
  EXPECT_EQ(r.out, "");
  EXPECT_FALSE(std::filesystem::exists(dir.file("f.png")));
  // `sylva export` reports it the same way.
  ProcessResult e = run_sylva({"export", dir.file("forest.scene.json"), "-o", dir.file("f.glb")});
  EXPECT_EQ(e.exit_code, 1) << describe(e);
  EXPECT_EQ(e.err, expected) << describe(e);
}

TEST(RenderCli, SkeletonInputRenders) {
  TempDir dir;
  ProcessResult g = run_sylva({"grow", kSaguaro, "-o", dir.file("s.skel.json")});
  ASSERT_EQ(g.exit_code, 0) << describe(g);
  ProcessResult r = run_sylva({"render", dir.file("s.skel.json"), "-o", dir.file("s.png"), "--width", "32",
                               "--height", "24", "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 0) << describe(r);
}

TEST(RenderCli, SceneWithAMissingBarkTextureFailsAtItsKeyWithStatus1) {
  TempDir dir;
  dir.write("s.scene.json", "{\"plants\": [{\"grammar\": \"" + kSaguaro +
                                "\",\n  \"bark\": {\"height\": \"missing.png\"}}]}");
  ProcessResult r = run_sylva({"render", dir.file("s.scene.json"), "-o", dir.file("a.png"), "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("s.scene.json:2:12: error: plants[0].bark.height: no such image file"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(dir.file("missing.png")), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.png")));
}

TEST(RenderCli, ReliefScenePresetsRenderAndSayWhatRan) {
  // The bundled relief scenes, small: the verbose passes name the relief (and a scene
  // without a height map says "relief: none").
  TempDir dir;
  const std::string scenes = std::string(SYLVA_SOURCE_DIR) + "/presets/scenes/";
  for (const char* name : {"saguaro", "pine"}) {
    ProcessResult r = run_sylva({"render", scenes + name + ".scene.json", "-o", dir.file(std::string(name) + ".png"),
                                 "--width", "64", "--height", "48", "--backend", "cpu", "--verbose"});
    EXPECT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_NE(r.err.find("1 plant, 32 linear + 8 bisection steps"), std::string::npos) << name << ": " << r.err;
  }
  ProcessResult plain = run_sylva({"render", kSaguaro, "-o", dir.file("p.png"), "--width", "32", "--height", "24",
                                   "--backend", "cpu", "--verbose"});
  EXPECT_EQ(plain.exit_code, 0) << describe(plain);
  EXPECT_NE(plain.err.find("relief"), std::string::npos) << plain.err;
  EXPECT_NE(plain.err.find("none"), std::string::npos) << plain.err;
}

// Issue 31 §6: `render plant.glb` draws the bark and materials the file carries — the
// picture of the exported scene itself, not the bare default look — and leaves no file
// of the images it wrote out behind; a height map no longer where the export found it is
// a warning, and the bark is drawn flat.
std::vector<float> rgb_pixels(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return {};
  std::vector<float> v(static_cast<size_t>(in->spec().width) * in->spec().height * 3);
  if (!in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, v.data())) return {};
  return v;
}
double mean_abs_difference(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size() || a.empty()) return 1e9;
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += std::abs(a[i] - b[i]);
  return sum / static_cast<double>(a.size());
}

TEST(RenderCli, AGltfFileRendersWithTheBarkAndMaterialsItCarries) {
  TempDir dir;
  const std::string textures = std::string(SYLVA_SOURCE_DIR) + "/presets/textures/";
  std::filesystem::copy_file(textures + "bark_height.png", dir.file("height.png"));
  const std::string elm = std::string(SYLVA_SOURCE_DIR) + "/presets/elm.lsys";
  dir.write("elm.scene.json", R"({"plants": [{"grammar": ")" + elm + R"(", "bark": {"albedo": ")" + textures +
                                  R"(bark.png", "height": "height.png", "u_repeat": 2, "relief_depth": 0.03}}],
                                  "materials": [{"index": 1, "albedo": [0.7, 0.1, 0.05], "specular": 0.2}]})");
  dir.write("bare.scene.json", R"({"plants": [{"grammar": ")" + elm + R"("}]})");
  for (const char* name : {"elm", "bare"}) {
    ProcessResult e = run_sylva({"export", dir.file(std::string(name) + ".scene.json"), "-o",
                                 dir.file(std::string(name) + ".glb"), "--mesh"});
    ASSERT_EQ(e.exit_code, 0) << describe(e);
  }
  const std::filesystem::path scratch = dir.file("tmp");
  std::filesystem::create_directory(scratch);
  setenv("TMPDIR", scratch.c_str(), 1);
  auto render = [&](const std::string& input, const std::string& out) {
    ProcessResult r = run_sylva({"render", input, "-o", dir.file(out), "--eye", "1.5,3,4", "--target", "0,2.5,0", "--sun", "0.5,1,0.3", "--fov", "35",
                                 "--width", "96", "--height", "72", "--backend", "cpu"});
    EXPECT_EQ(r.exit_code, 0) << describe(r);
    return r;
  };
  render(dir.file("elm.glb"), "glb.png");
  render(dir.file("elm.scene.json"), "scene.png");
  render(dir.file("bare.glb"), "bare.png");
  EXPECT_TRUE(std::filesystem::is_empty(scratch));  // the images written out are gone
  const std::vector<float> glb = rgb_pixels(dir.file("glb.png")), scene = rgb_pixels(dir.file("scene.png")),
                           bare = rgb_pixels(dir.file("bare.png"));
  const double same = mean_abs_difference(glb, scene), apart = mean_abs_difference(bare, scene);
  EXPECT_LT(same, 0.002) << "the glTF drew another look than the scene it was exported from";
  EXPECT_GT(apart, 10 * same + 0.002) << "the bare elm should look different";
  // The height map moved away: a warning naming it, exit 0, the bark flat.
  std::filesystem::remove(dir.file("height.png"));
  ProcessResult moved = render(dir.file("elm.glb"), "flat.png");
  EXPECT_NE(moved.err.find("warning: the bark's height map"), std::string::npos) << describe(moved);
  EXPECT_NE(moved.err.find("height.png"), std::string::npos) << describe(moved);
  EXPECT_GT(mean_abs_difference(rgb_pixels(dir.file("flat.png")), glb), 0);
  // $TMPDIR naming a file, not a folder: the images go under /tmp, the render still runs.
  setenv("TMPDIR", dir.file("elm.scene.json").c_str(), 1);
  render(dir.file("elm.glb"), "other_tmp.png");
  EXPECT_TRUE(std::filesystem::exists(dir.file("other_tmp.png")));
  unsetenv("TMPDIR");
}

TEST(RenderCli, UsageErrors) {
  TempDir dir;
  EXPECT_EQ(run_sylva({"render", kSaguaro}).exit_code, 2);                                  // no -o
  EXPECT_EQ(run_sylva({"render", "-o", dir.file("a.png")}).exit_code, 2);                  // no INPUT
  EXPECT_EQ(run_sylva({"render", dir.file("x.txt"), "-o", dir.file("a.png")}).exit_code, 2);  // kind
  EXPECT_EQ(run_sylva({"render", kSaguaro, "-o", dir.file("a.png"), "--spp", "0"}).exit_code, 2);
  EXPECT_EQ(run_sylva({"render", kSaguaro, "-o", dir.file("a.unknownformat")}).exit_code, 2);
  dir.write("s.scene.json", R"({"plants": []})");
  EXPECT_EQ(run_sylva({"render", dir.file("s.scene.json"), "-o", dir.file("a.png"), "-n", "3"}).exit_code, 2);
  ProcessResult help = run_sylva({"render", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--aov"), std::string::npos);
}

}  // namespace
