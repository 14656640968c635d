// render_camera_cli_test.cpp — `sylva render --eye X,Y,Z --target X,Y,Z --fov DEG` (docs/spec/cli.md):
// the camera of a grammar, skeleton or scene set on the command line.
//
// The saguaro stands at the origin, its trunk a column about 0.3 m in radius up to 6.2 m
// (presets/saguaro.lsys), so the depth at the image's centre says where the camera is and
// what it looks at, and how much of the image the trunk fills says its field of view.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/support/process.h"

namespace {

const std::string kSaguaro = std::string(SYLVA_SOURCE_DIR) + "/presets/saguaro.lsys";
const std::string kSaguaroScene = std::string(SYLVA_SOURCE_DIR) + "/presets/scenes/saguaro.scene.json";

// The depth AOV (channel Z) of an EXR, row by row; empty if it cannot be read.
struct Depth {
  int width = 0, height = 0;
  std::vector<float> z;
  float at(int x, int y) const { return z[static_cast<size_t>(y) * width + x]; }
  float centre() const { return at(width / 2, height / 2); }
  double hit_fraction() const {
    size_t hits = 0;
    for (float v : z) hits += std::isfinite(v) ? 1 : 0;
    return static_cast<double>(hits) / static_cast<double>(z.size());
  }
};

Depth read_depth(const std::string& path) {
  Depth d;
  auto in = OIIO::ImageInput::open(path);
  if (!in) return d;
  const OIIO::ImageSpec& spec = in->spec();
  const int channel = spec.channelindex("Z");
  if (channel < 0) return d;
  d.width = spec.width;
  d.height = spec.height;
  d.z.resize(static_cast<size_t>(d.width) * d.height);
  if (!in->read_image(0, 0, channel, channel + 1, OIIO::TypeDesc::FLOAT, d.z.data())) d.z.clear();
  return d;
}

// Renders INPUT with the CPU ray caster at 64 x 48 with a depth AOV and the extra flags.
Depth render_depth(const TempDir& dir, const std::string& input, std::vector<std::string> flags) {
  std::vector<std::string> args = {"render", input, "-o", dir.file("d.exr"), "--width", "64", "--height", "48",
                                   "--aov", "depth", "--backend", "cpu"};
  args.insert(args.end(), flags.begin(), flags.end());
  ProcessResult r = run_sylva(args);
  EXPECT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 0) << describe(r);
  return read_depth(dir.file("d.exr"));
}

// The centre pixel sees the trunk's near side: `distance` from the eye to the trunk's
// axis, less one trunk radius (0.2 to 0.5 m, a scene's bark relief included).
void expect_centre_on_trunk(const Depth& d, double distance) {
  ASSERT_FALSE(d.z.empty()) << "no depth channel";
  EXPECT_GT(d.centre(), distance - 0.5);
  EXPECT_LT(d.centre(), distance - 0.2);
}

// Looking at the trunk's axis from 20 m (along -Z, where no arm stands in front of it at
// 3 m): the centre ray meets the trunk's near side, one trunk radius short of 20 m; from
// 10 m, one radius short of 10 m. Looking 5 m beside the trunk, the centre ray misses.
TEST(RenderCamera, EyeAndTargetPlaceTheCameraOfAGrammar) {
  TempDir dir;
  expect_centre_on_trunk(render_depth(dir, kSaguaro, {"--eye", "0,3,20", "--target", "0,3,0"}), 20);
  expect_centre_on_trunk(render_depth(dir, kSaguaro, {"--eye", "0,3,10", "--target", "0,3,0"}), 10);
  Depth beside = render_depth(dir, kSaguaro, {"--eye", "0,3,20", "--target", "5,3,0"});
  ASSERT_FALSE(beside.z.empty());
  EXPECT_TRUE(std::isinf(beside.centre())) << beside.centre();
}

// A 1 degree field of view from 20 m sees 0.35 m of the trunk's 0.6 m width: every pixel
// hits it. At 60 degrees the trunk is a thin column and most pixels miss the plant (the
// depth AOV is +inf where no plant is hit, on sky and ground alike).
TEST(RenderCamera, FovSetsTheFieldOfView) {
  TempDir dir;
  Depth narrow = render_depth(dir, kSaguaro, {"--eye", "0,3,20", "--target", "0,3,0", "--fov", "1"});
  ASSERT_FALSE(narrow.z.empty());
  EXPECT_EQ(narrow.hit_fraction(), 1.0);
  Depth wide = render_depth(dir, kSaguaro, {"--eye", "0,3,20", "--target", "0,3,0", "--fov", "60"});
  ASSERT_FALSE(wide.z.empty());
  EXPECT_LT(wide.hit_fraction(), 0.5);
}

// --eye alone moves the eye and keeps the default camera's target on the framed plant,
// so the centre still sees the saguaro.
TEST(RenderCamera, EyeAloneKeepsTheFramedTarget) {
  TempDir dir;
  Depth d = render_depth(dir, kSaguaro, {"--eye", "0,3.2,25"});
  ASSERT_FALSE(d.z.empty());
  EXPECT_TRUE(std::isfinite(d.centre()));
  EXPECT_GT(d.centre(), 24);
  EXPECT_LT(d.centre(), 25);
}

// A skeleton's default scene takes the flags as a grammar's does.
TEST(RenderCamera, FlagsPlaceTheCameraOfASkeleton) {
  TempDir dir;
  ProcessResult grown = run_sylva({"grow", kSaguaro, "-o", dir.file("s.skel.json")});
  ASSERT_EQ(grown.exit_code, 0) << describe(grown);
  Depth d = render_depth(dir, dir.file("s.skel.json"), {"--eye", "0,3,20", "--target", "0,3,0", "--fov", "1"});
  expect_centre_on_trunk(d, 20);
  EXPECT_EQ(d.hit_fraction(), 1.0);
}

// On a scene the flags override its camera key (saguaro.scene.json looks from 6.5, 3.6, 9).
TEST(RenderCamera, FlagsOverrideASceneCamera) {
  TempDir dir;
  Depth d = render_depth(dir, kSaguaroScene, {"--eye", "0,3,15", "--target", "0,3,0", "--fov", "1"});
  expect_centre_on_trunk(d, 15);
  EXPECT_EQ(d.hit_fraction(), 1.0);
}

// --sun (issue 31 §6): the direction toward the sun over the scene's; the default scene's
// own direction gives the same image, a low sun another; zero or malformed: exit 2.
TEST(RenderCamera, SunSetsTheDirectionTowardTheSun) {
  TempDir dir;
  auto render = [&](const std::string& name, std::vector<std::string> flags) {
    std::vector<std::string> args = {"render", kSaguaro, "-o", dir.file(name), "--width", "48", "--height", "36",
                                     "--backend", "cpu", "--spp", "1"};
    args.insert(args.end(), flags.begin(), flags.end());
    ProcessResult r = run_sylva(args);
    EXPECT_EQ(r.exit_code, 0) << describe(r);
    return read_file(dir.file(name));
  };
  const std::string plain = render("plain.png", {});
  EXPECT_FALSE(plain.empty());
  EXPECT_EQ(render("same.png", {"--sun", "0.5,1,0.3"}), plain);
  EXPECT_NE(render("low.png", {"--sun", "1,0.2,0"}), plain);
  for (const char* bad : {"0,0,0", "1,2", "nan,1,0"}) {
    ProcessResult r = run_sylva({"render", kSaguaro, "-o", dir.file("bad.png"), "--sun", bad});
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << describe(r);
    EXPECT_NE(r.err.find("--sun"), std::string::npos) << describe(r);
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("bad.png")));
}

// Bad values are usage errors (exit 2) that name the flag, and nothing is written.
TEST(RenderCamera, BadValuesAreUsageErrorsNamingTheFlag) {
  TempDir dir;
  const std::vector<std::vector<std::string>> bad = {
      {"--eye", "1,2"},          {"--eye", "1,2,3,4"},     {"--eye", "1,,3"},       {"--eye", "1,2,x"},
      {"--eye", "nan,0,0"},      {"--target", "inf,0,0"},  {"--target", "1 2 3"},   {"--target", ""},
      {"--fov", "0"},            {"--fov", "180"},         {"--fov", "-10"},        {"--fov", "wide"},
      {"--fov", "nan"},          {"--eye"},
  };
  for (const std::vector<std::string>& flags : bad) {
    std::vector<std::string> args = {"render", kSaguaro, "-o", dir.file("a.png")};
    args.insert(args.end(), flags.begin(), flags.end());
    ProcessResult r = run_sylva(args);
    EXPECT_EQ(r.exit_code, 2) << flags.front() << " " << (flags.size() > 1 ? flags[1] : "") << ": " << describe(r);
    EXPECT_NE(r.err.find(flags.front()), std::string::npos) << describe(r);
  }
  EXPECT_TRUE(list_dir(dir.path()).empty());
}

// A camera the flags make degenerate: eye on the target, or looking straight down +Y.
TEST(RenderCamera, ADegenerateCameraIsAUsageError) {
  TempDir dir;
  ProcessResult same = run_sylva({"render", kSaguaro, "-o", dir.file("a.png"), "--eye", "1,2,3", "--target", "1,2,3"});
  EXPECT_EQ(same.exit_code, 2) << describe(same);
  EXPECT_NE(same.err.find("must differ"), std::string::npos) << describe(same);
  ProcessResult down = run_sylva({"render", kSaguaro, "-o", dir.file("a.png"), "--eye", "0,20,0", "--target", "0,0,0"});
  EXPECT_EQ(down.exit_code, 2) << describe(down);
  EXPECT_NE(down.err.find("up"), std::string::npos) << describe(down);
  EXPECT_TRUE(list_dir(dir.path()).empty());
}

// A camera beyond the world's ±1e12 m (docs/limits.md), as a scene's camera may not be:
// a usage error naming the flag, on every backend. (Before: --backend cpu aborted in
// Embree's BVH assertion.)
TEST(RenderCamera, ACameraBeyondTheWorldIsAUsageErrorNamingTheFlag) {
  TempDir dir;
  const std::vector<std::vector<std::string>> far = {
      {"--eye", "1e20,1,1"}, {"--target", "1e300,0,0"}, {"--eye", "0,0,-2e12"}, {"--eye", "1.5e308,0,0"}};
  for (const std::vector<std::string>& flags : far)
    for (const char* backend : {"cpu", "auto"}) {
      std::vector<std::string> args = {"render", kSaguaro, "-o", dir.file("a.png"), "--backend", backend,
                                       "--width", "16", "--height", "12"};
      args.insert(args.end(), flags.begin(), flags.end());
      ProcessResult r = run_sylva(args);
      ASSERT_FALSE(crashed(r)) << flags[0] << " " << flags[1] << ": " << describe(r);
      EXPECT_EQ(r.exit_code, 2) << flags[0] << " " << flags[1] << ": " << describe(r);
      EXPECT_NE(r.err.find(flags[0] + ": the "), std::string::npos) << describe(r);
      EXPECT_NE(r.err.find("1e12 m"), std::string::npos) << describe(r);
    }
  EXPECT_TRUE(list_dir(dir.path()).empty());
}

// render --help lists the three flags.
TEST(RenderCamera, HelpDescribesTheFlags) {
  ProcessResult help = run_sylva({"render", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  for (const char* flag : {"--eye X,Y,Z", "--target X,Y,Z", "--fov DEG"})
    EXPECT_NE(help.out.find(flag), std::string::npos) << flag << " not in:\n" << help.out;
}

}  // namespace
