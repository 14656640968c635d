// outputs_cli_test.cpp — where `sylva` may write (docs/spec/cli.md, docs/limits.md "Outputs"): never
// onto one of its inputs under any name, never onto a FIFO, a device or a read-only file
// (refused with exit 1, the file as it was), all of a render's files or none, and a
// "{seed}" in the folder part of an output pattern creates each seed's folder.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tests/support/process.h"

namespace {

namespace fs = std::filesystem;

constexpr const char* kGrammar = "axiom: F\nF -> F[+F]F\n";

class OutputsCliTest : public ::testing::Test {
 protected:
  // Expects exit 1 with `phrase` in the message and `path` holding `contents` still.
  void expect_refused(const ProcessResult& r, const std::string& phrase) {
    ASSERT_FALSE(crashed(r)) << describe(r);
    EXPECT_EQ(r.exit_code, 1) << describe(r);
    EXPECT_NE(r.err.find(phrase), std::string::npos) << describe(r);
  }
  TempDir dir_;
};

TEST_F(OutputsCliTest, GrowOntoItsOwnGrammarIsRefusedUnderAnyName) {
  const std::string g = dir_.write("a.lsys", kGrammar);
  ASSERT_EQ(::link(g.c_str(), dir_.file("hard.lsys").c_str()), 0);
  for (const std::string& target : {g, dir_.path().string() + "/./a.lsys", dir_.file("hard.lsys")}) {
    SCOPED_TRACE(target);
    expect_refused(run_sylva({"grow", g, "-o", target}), "it is an input of this command");
    EXPECT_EQ(read_file(g), kGrammar);
  }
  // From inside the folder, by a relative name.
  expect_refused(run_sylva({"grow", "a.lsys", "-o", "a.lsys"}, dir_.path().string()), "it is an input");
  EXPECT_EQ(read_file(g), kGrammar);
  EXPECT_EQ(list_dir(dir_.path()), (std::vector<std::string>{"a.lsys", "hard.lsys"}));
}

TEST_F(OutputsCliTest, AFifoOrADeviceIsNeverReplacedByAFile) {
  const std::string g = dir_.write("a.lsys", kGrammar);
  const std::string fifo = dir_.file("out.skel.json");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  expect_refused(run_sylva({"grow", g, "-o", fifo}), "it is a FIFO");
  EXPECT_TRUE(fs::is_fifo(fifo));
  expect_refused(run_sylva({"grow", g, "-o", "/dev/null"}), "it is a character device");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  EXPECT_EQ(list_dir(dir_.path()), (std::vector<std::string>{"a.lsys", "out.skel.json"}));
}

TEST_F(OutputsCliTest, AReadOnlyTargetIsNotSilentlyReplaced) {
  const std::string g = dir_.write("a.lsys", kGrammar);
  const std::string target = dir_.write("kept.skel.json", "old");
  ASSERT_EQ(::chmod(target.c_str(), 0444), 0);
  expect_refused(run_sylva({"grow", g, "-o", target}), "the file is read-only");
  EXPECT_EQ(read_file(target), "old");
  EXPECT_EQ(list_dir(dir_.path()), (std::vector<std::string>{"a.lsys", "kept.skel.json"}));
}

// The render's files are all checked before the render: one read-only AOV file stops
// the run with every file as it was and no temporary left.
TEST_F(OutputsCliTest, ARenderWritesAllItsFilesOrNone) {
  const std::string g = dir_.write("a.lsys", kGrammar);
  dir_.write("out.depth.exr", "old depth");
  const std::string normal = dir_.write("out.normal.exr", "old normal");
  ASSERT_EQ(::chmod(normal.c_str(), 0444), 0);
  ProcessResult r = run_sylva({"render", g, "-o", dir_.file("out.png"), "--backend", "cpu", "--width", "32",
                               "--height", "24", "--aov", "depth,normal"});
  expect_refused(r, "out.normal.exr: error: cannot write: the file is read-only");
  EXPECT_EQ(read_file(dir_.file("out.depth.exr")), "old depth");
  EXPECT_EQ(read_file(normal), "old normal");
  EXPECT_EQ(list_dir(dir_.path()), (std::vector<std::string>{"a.lsys", "out.depth.exr", "out.normal.exr"}));
}

TEST_F(OutputsCliTest, ASeedInTheFolderPartCreatesEachSeedsFolder) {
  const std::string g = dir_.write("a.lsys", kGrammar);
  ProcessResult r = run_sylva({"grow", g, "-o", dir_.file("out/{seed}/plant.skel.json"), "--seed", "3..4"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_TRUE(fs::is_regular_file(dir_.file("out/3/plant.skel.json"))) << describe(r);
  EXPECT_TRUE(fs::is_regular_file(dir_.file("out/4/plant.skel.json"))) << describe(r);

  r = run_sylva({"export", g, "-o", dir_.file("one/{seed}/plant.glb"), "--seed", "7"});
  EXPECT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_TRUE(fs::is_regular_file(dir_.file("one/7/plant.glb"))) << describe(r);
}

TEST_F(OutputsCliTest, AMissingFolderWithoutASeedIsAnErrorNamingIt) {
  const std::string g = dir_.write("a.lsys", kGrammar);
  ProcessResult r = run_sylva({"export", g, "-o", dir_.file("missing/plant.glb")});
  expect_refused(r, "cannot create a temporary file in directory '" + dir_.file("missing") +
                        "': No such file or directory");
  EXPECT_EQ(list_dir(dir_.path()), std::vector<std::string>{"a.lsys"});
}

}  // namespace
