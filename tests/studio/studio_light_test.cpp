// studio_light_test.cpp — the studio's Light (?E) panel driven headless (an ImGui context
// with simulated input, the real grow worker, a fake viewport): a grammar with light
// queries grows in the scene's light, the panel's controls change the scene's environment
// and regrow the plant, the cost is shown, and the environment is saved with the scene.
#include <gtest/gtest.h>

#include <string>

#include "core/scene/scene.h"
#include "core/scene/scene_json.h"
#include "core/util/file_io.h"
#include "tests/studio/headless_ui.h"

namespace sylva::studio::test {
namespace {

const char* const kApex =
    "module: A\n"
    "derivation length: 4\n"
    "axiom: A ?E(1)\n"
    "A > ?E(q) : q > 0.5 -> F(0.5) [+(30) A ?E(1)] A\n";

const char* const kScene = R"({"format": "sylva-scene", "version": 1,
  "camera": {"eye": [4, 2, 4], "target": [0, 1, 0]},
  "environment": {"photons": 20000},
  "plants": [{"grammar": "apex.lsys"}]})";

TEST(StudioLight, ThePanelChangesTheEnvironmentRegrowsThePlantAndSavesIt) {
  TempDir dir("StudioLight");
  ASSERT_TRUE(write_file_atomically(dir.file("apex.lsys"), kApex).ok());
  const std::string scene_path = dir.file("light.scene.json");
  ASSERT_TRUE(write_file_atomically(scene_path, kScene).ok());
  HeadlessUi ui;
  FakeViewport viewport;
  StudioOptions o;
  o.presets_dir = std::string(SYLVA_SOURCE_DIR) + "/presets";
  auto app = std::make_unique<StudioApp>(o, &viewport);
  ASSERT_FALSE(app->open(scene_path));
  ASSERT_TRUE(ui.until(*app, [&] { return app->plant_drawn(); }));
  ASSERT_TRUE(app->plant());
  EXPECT_EQ(app->plant()->light.answers, 5u) << "the axiom and four steps answered";
  EXPECT_EQ(app->plant()->light.photons, 5u * 20000u) << "the scene's photons";

  // Open the panel and drag its photons slider: the environment changes and the plant regrows.
  ImGuiIO& io = ImGui::GetIO();
  for (int i = 0; i < 60 && !app->rect("light:photons"); ++i) {
    auto panels = app->rect("panels");
    auto header = app->rect("header:light");
    ASSERT_TRUE(panels);
    if (header && header->min.y >= panels->min.y && header->max.y <= panels->max.y) {
      io.MousePos = header->centre();
      io.MouseDown[0] = true;
      ui.frame(*app);
      io.MouseDown[0] = false;
      ui.frames(*app, 2);
      continue;
    }
    io.MousePos = panels->centre();
    io.MouseWheel = -1.0f;
    ui.frame(*app);
  }
  ASSERT_TRUE(app->rect("light:photons")) << "the panel opens";
  for (int i = 0; i < 60; ++i) {  // scroll until the slider is wholly in view
    auto panels = app->rect("panels");
    auto widget = app->rect("light:photons");
    ASSERT_TRUE(panels && widget);
    if (widget->min.y >= panels->min.y && widget->max.y <= panels->max.y) break;
    io.MousePos = panels->centre();
    io.MouseWheel = widget->max.y > panels->max.y ? -1.0f : 1.0f;
    ui.frame(*app);
  }
  const auto r = *app->rect("light:photons");
  io.MousePos = ImVec2(r.min.x + 5, r.centre().y);
  ui.frame(*app);
  io.MouseDown[0] = true;
  for (int i = 0; i < 8; ++i) {
    io.MousePos.x += (r.max.x - r.min.x) * 0.05f;
    ui.frame(*app);
  }
  io.MouseDown[0] = false;
  ui.frames(*app, 2);
  ASSERT_TRUE(app->scene().environment);
  const uint64_t photons = app->scene().environment->photons;
  EXPECT_NE(photons, 20000u);
  ASSERT_TRUE(ui.until(*app, [&] { return app->plant() && app->plant()->light.photons == 5 * photons; }))
      << "the plant regrows in the new light";

  const std::string saved = dir.file("saved.scene.json");
  ASSERT_FALSE(app->save_scene(saved));
  Expected<Scene> read = read_scene_file(saved);
  ASSERT_TRUE(read) << read.error().format();
  ASSERT_TRUE(read->environment);
  EXPECT_EQ(read->environment->photons, photons);
}

}  // namespace
}  // namespace sylva::studio::test
