// render_cli_test.cpp — `sylva render` as a user runs it (cli.md, scene.md).
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "tests/app/process.h"

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

TEST(RenderCli, AutoBackendFallsBackToTheCpuSayingSo) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("s.png"), "--width", "32", "--height", "24"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("OpenGL backend not available yet; using the CPU ray caster"), std::string::npos)
      << describe(r);
}

TEST(RenderCli, GlBackendIsAUsageErrorForNow) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("s.png"), "--backend", "gl"});
  EXPECT_EQ(r.exit_code, 2) << describe(r);
  EXPECT_NE(r.err.find("OpenGL"), std::string::npos) << describe(r);
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
             {"grammar": "cactus.lsys", "seed": 5, "position": [-2, 0, -1], "scale": 0.7}]})");
  ProcessResult r = run_sylva({"render", dir.file("a.scene.json"), "-o", dir.file("a.png"), "--backend", "cpu",
                               "--verbose"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  auto in = OIIO::ImageInput::open(dir.file("a.png"));
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 48);
  // --verbose lists the passes.
  for (const char* pass : {"skin", "accel build", "trace", "shade", "write"})
    EXPECT_NE(r.err.find(pass), std::string::npos) << pass << "\n" << describe(r);
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

TEST(RenderCli, SkeletonInputRenders) {
  TempDir dir;
  ProcessResult g = run_sylva({"grow", kSaguaro, "-o", dir.file("s.skel.json")});
  ASSERT_EQ(g.exit_code, 0) << describe(g);
  ProcessResult r = run_sylva({"render", dir.file("s.skel.json"), "-o", dir.file("s.png"), "--width", "32",
                               "--height", "24", "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 0) << describe(r);
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
