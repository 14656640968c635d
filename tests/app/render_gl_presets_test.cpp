// render_gl_presets_test.cpp — the GL backend (render_gl.h) renders every bundled
// preset and scene from the command line on a machine without X or GPU (llvmpipe through
// EGL), with no fallback to the CPU, and what it draws is a plant: the picture is not
// only sky and ground.
// Every render here passes --spp 1 (the pixel centres): these tests are about what is
// drawn, not how it is sampled, and the default of 8 samples would cost 8 times the time
// (RenderCli.TheDefaultIsEightSamplesPerPixel pins the default).
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/support/process.h"
#include "tests/support/requirements.h"

namespace {

namespace fs = std::filesystem;

// Every bundled grammar and scene but the fog scenes: their canopies (the pine stand's
// 390,711 frusta) cost llvmpipe tens of seconds a frame, which a smoke test per preset
// cannot pay under ASan. The GL fog pass on bundled and small scenes is tested by
// tests/app/render_fog_cli_test.cpp (the CLI, brute and medium on GL) and
// tests/gl/render_gl_fog_test.cpp (the elm grove, GL against the CPU).
std::vector<std::string> bundled_inputs() {
  std::vector<std::string> inputs;
  const fs::path presets = fs::path(SYLVA_SOURCE_DIR) / "presets";
  for (const auto& entry : fs::directory_iterator(presets))
    if (entry.path().extension() == ".lsys") inputs.push_back(entry.path().string());
  for (const auto& entry : fs::directory_iterator(presets / "scenes"))
    if (entry.path().string().ends_with(".scene.json") &&
        read_file(entry.path().string()).find("\"fog\"") == std::string::npos)
      inputs.push_back(entry.path().string());
  std::sort(inputs.begin(), inputs.end());
  return inputs;
}

class GlPreset : public ::testing::TestWithParam<std::string> {};

TEST_P(GlPreset, RendersWithOpenGlAndSeesThePlant) {
  TempDir dir;
  const std::string out = dir.file("p.exr");
  ProcessResult r = run_sylva({"render", "--spp", "1", GetParam(), "-o", out, "--width", "96", "--height", "72", "--backend", "gl",
                               "--aov", "id", "--verbose"});
  if (r.exit_code == 1 && r.err.find("no OpenGL 4.5 core context") != std::string::npos)
    SYLVA_SKIP_WITHOUT_GL("no OpenGL context on this machine: " << r.err);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("OpenGL ray caster ("), std::string::npos) << describe(r);
  EXPECT_EQ(r.err.find("CPU ray caster"), std::string::npos) << describe(r);
  // The default camera frames the plant: some pixels see it (id.plant >= 0).
  auto in = OIIO::ImageInput::open(out);
  ASSERT_TRUE(in) << out;
  const OIIO::ImageSpec spec = in->spec();
  const int plant_channel = spec.channelindex("id.plant");
  ASSERT_GE(plant_channel, 0) << "no id.plant channel";
  std::vector<float> ids(static_cast<size_t>(spec.width) * spec.height);
  ASSERT_TRUE(in->read_image(0, 0, plant_channel, plant_channel + 1, OIIO::TypeDesc::FLOAT, ids.data()));
  const auto seen = std::count_if(ids.begin(), ids.end(), [](float id) { return id >= 0; });
  EXPECT_GT(seen, static_cast<long>(ids.size() / 200)) << "the plant covers " << seen << " of " << ids.size()
                                                       << " pixels";
}

INSTANTIATE_TEST_SUITE_P(Bundled, GlPreset, ::testing::ValuesIn(bundled_inputs()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = fs::path(info.param).filename().string();
                           const bool scene = name.ends_with(".scene.json");
                           name = name.substr(0, name.find('.')) + (scene ? "_scene" : "");
                           std::replace_if(name.begin(), name.end(), [](char c) { return !std::isalnum(c); }, '_');
                           return name;
                         });

}  // namespace
