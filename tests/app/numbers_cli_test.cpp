// numbers_cli_test.cpp — extreme numbers at the command line (docs/limits.md "Numbers"):
// a grammar length like 1e300, a sun direction like 1e200 or an image too large to
// allocate end with exit 1 and a message, or render correctly, on every backend alike —
// never an abort (Embree asserts on rays it cannot represent).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/support/process.h"

namespace {

class NumbersCliTest : public ::testing::Test {
 protected:
  TempDir dir_;
};

std::vector<std::string> render_args(const std::string& input, const std::string& output, const char* backend) {
  return {"render", input, "-o", output, "--backend", backend, "--width", "32", "--height", "24"};
}

TEST_F(NumbersCliTest, AHugeLengthIsAnInputErrorOnEveryBackend) {
  const std::string g = dir_.write("big.lsys", "axiom: F(1e300)\n");
  for (const char* backend : {"cpu", "auto"}) {
    SCOPED_TRACE(backend);
    ProcessResult r = run_sylva(render_args(g, dir_.file("big.png"), backend));
    ASSERT_FALSE(crashed(r)) << describe(r);
    EXPECT_EQ(r.exit_code, 1) << describe(r);
    EXPECT_NE(r.err.find("exceeds the limit of 1e12 m"), std::string::npos) << describe(r);
  }
  ProcessResult r = run_sylva({"export", g, "-o", dir_.file("big.glb")});
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_EQ(list_dir(dir_.path()), std::vector<std::string>{"big.lsys"});
}

TEST_F(NumbersCliTest, AHugeSunDirectionRendersLikeItsUnitDirection) {
  dir_.write("ok.lsys", "axiom: F(1)\n");
  const std::string huge = dir_.write(
      "huge.scene.json", R"({"sun": {"direction": [1e200, 2e200, 0]}, "plants": [{"grammar": "ok.lsys"}]})");
  const std::string unit = dir_.write(
      "unit.scene.json", R"({"sun": {"direction": [0.5, 1, 0]}, "plants": [{"grammar": "ok.lsys"}]})");
  for (const char* backend : {"cpu", "auto"}) {
    SCOPED_TRACE(backend);
    ProcessResult a = run_sylva(render_args(huge, dir_.file("huge.png"), backend));
    ASSERT_FALSE(crashed(a)) << describe(a);
    ASSERT_EQ(a.exit_code, 0) << describe(a);
    ProcessResult b = run_sylva(render_args(unit, dir_.file("unit.png"), backend));
    ASSERT_EQ(b.exit_code, 0) << describe(b);
    EXPECT_EQ(read_file(dir_.file("huge.png")), read_file(dir_.file("unit.png")));
  }
}

TEST_F(NumbersCliTest, AnImageTooLargeToAllocateIsRefusedAtOnce) {
  const std::string g = dir_.write("ok.lsys", "axiom: F(1)\n");
  ProcessResult r = run_sylva({"render", g, "-o", dir_.file("big.png"), "--backend", "cpu", "--width", "65536",
                               "--height", "65536"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("more than the limit of 67108864"), std::string::npos) << describe(r);
  EXPECT_LT(r.max_rss_kb, 1 << 20) << "nothing the size of the image was allocated";
  EXPECT_EQ(list_dir(dir_.path()), std::vector<std::string>{"ok.lsys"});
}

// A skeleton file may hold any double; a glTF accessor holds float32. Exporting a joint at
// 1e300 is refused rather than written as null into an invalid file.
TEST_F(NumbersCliTest, ExportingBeyondFloat32IsAnErrorNotAnInvalidFile) {
  const std::string sk = dir_.write(
      "far.skel.json",
      R"({"format": "sylva-skeleton", "version": 1, "chains": [{"parent": null, "joints": [[0,0,0,0.1,0],[1e300,0,0,0.1,0]]}]})");
  ProcessResult r = run_sylva({"export", sk, "-o", dir_.file("far.glb")});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("beyond the limit of 1e12 m"), std::string::npos) << describe(r);
  EXPECT_EQ(list_dir(dir_.path()), std::vector<std::string>{"far.skel.json"});
}

}  // namespace
