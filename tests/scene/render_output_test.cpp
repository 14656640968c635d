// render_output_test.cpp — a render's files (core/scene/render_output.h): the paths it writes,
// and all of them or none (docs/limits.md "Outputs"): when the last file cannot be written
// the AOV files already complete in their temporaries replace nothing.
#include "core/scene/render_output.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace sylva {
namespace {

namespace fs = std::filesystem;

std::string contents(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

class RenderOutputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = ::testing::TempDir() + "sylva-render-output-XXXXXX";
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }
  static RenderImage image() {
    RenderImage i;
    i.width = 4;
    i.height = 2;
    i.beauty.assign(4 * 2 * 4, 0.5f);
    i.depth.assign(4 * 2, 1.0f);
    i.normal.assign(4 * 2 * 3, 0.0f);
    return i;
  }
  fs::path dir_;
};

TEST_F(RenderOutputTest, ThePathsAreTheSideFilesThenTheImage) {
  EXPECT_EQ(render_output_paths("a/out.png", kAovDepth | kAovId),
            (std::vector<std::string>{"a/out.depth.exr", "a/out.id.exr", "a/out.png"}));
  EXPECT_EQ(render_output_paths("out.exr", kAovDepth | kAovId), std::vector<std::string>{"out.exr"});
}

TEST_F(RenderOutputTest, AFailingImageLeavesEveryAovFileAsItWas) {
  const fs::path png = dir_ / "out.png";
  { std::ofstream(dir_ / "out.depth.exr") << "old depth"; }
  { std::ofstream(png) << "old png"; }
  ASSERT_EQ(::chmod(png.c_str(), 0444), 0);
  Expected<std::vector<std::string>> written = write_render(png.string(), image());
  ASSERT_FALSE(written.ok());
  EXPECT_EQ(written.error().file, png.string());
  EXPECT_EQ(contents(dir_ / "out.depth.exr"), "old depth");
  EXPECT_EQ(contents(png), "old png");
  EXPECT_EQ(entries(dir_), (std::vector<std::string>{"out.depth.exr", "out.png"}));  // no temporary left

  ASSERT_EQ(::chmod(png.c_str(), 0644), 0);
  written = write_render(png.string(), image());
  ASSERT_TRUE(written.ok()) << written.error().format();
  EXPECT_EQ(*written, render_output_paths(png.string(), kAovDepth | kAovNormal));
  EXPECT_EQ(entries(dir_), (std::vector<std::string>{"out.depth.exr", "out.normal.exr", "out.png"}));
  EXPECT_NE(contents(dir_ / "out.depth.exr"), "old depth");
}

}  // namespace
}  // namespace sylva
