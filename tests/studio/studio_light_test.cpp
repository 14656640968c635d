// studio_light_test.cpp — the studio's Light (?E) panel driven headless (an ImGui context
// with simulated input, the real grow worker, a fake viewport): a grammar with light
// queries grows in the scene's light, the panel's controls change the scene's environment
// and regrow the plant, the cost is shown, and the environment is saved with the scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
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

// The studio on a scene whose plant asks for light (kScene, kApex), grown and drawn.
struct LightStudio {
  explicit LightStudio(const char* name) : dir(name) {}
  void open() {
    ASSERT_TRUE(write_file_atomically(dir.file("apex.lsys"), kApex).ok());
    ASSERT_TRUE(write_file_atomically(dir.file("light.scene.json"), kScene).ok());
    StudioOptions o;
    o.presets_dir = std::string(SYLVA_SOURCE_DIR) + "/presets";
    app = std::make_unique<StudioApp>(o, &viewport);
    ASSERT_FALSE(app->open(dir.file("light.scene.json")));
    ASSERT_TRUE(ui.until(*app, [&] { return app->plant_drawn(); }));
    ASSERT_TRUE(app->plant());
  }
  TempDir dir;
  HeadlessUi ui;
  FakeViewport viewport;
  std::unique_ptr<StudioApp> app;
};

// Opens the Light panel (scrolling the panels to its header and clicking it) and scrolls
// until `widget` is wholly in view.
void show_light_widget(HeadlessUi& ui, StudioApp& app, const std::string& widget_name) {
  ImGuiIO& io = ImGui::GetIO();
  for (int i = 0; i < 60 && !app.rect(widget_name); ++i) {
    auto panels = app.rect("panels");
    auto header = app.rect("header:light");
    ASSERT_TRUE(panels);
    if (header && header->min.y >= panels->min.y && header->max.y <= panels->max.y) {
      io.MousePos = header->centre();
      io.MouseDown[0] = true;
      ui.frame(app);
      io.MouseDown[0] = false;
      ui.frames(app, 2);
      continue;
    }
    io.MousePos = panels->centre();
    io.MouseWheel = -1.0f;
    ui.frame(app);
  }
  ASSERT_TRUE(app.rect(widget_name)) << "the panel opens";
  for (int i = 0; i < 60; ++i) {  // scroll until the widget is wholly in view
    auto panels = app.rect("panels");
    auto widget = app.rect(widget_name);
    ASSERT_TRUE(panels && widget);
    if (widget->min.y >= panels->min.y && widget->max.y <= panels->max.y) break;
    io.MousePos = panels->centre();
    io.MouseWheel = widget->max.y > panels->max.y ? -1.0f : 1.0f;
    ui.frame(app);
  }
}

TEST(StudioLight, ThePanelChangesTheEnvironmentRegrowsThePlantAndSavesIt) {
  LightStudio studio("StudioLight");
  ASSERT_NO_FATAL_FAILURE(studio.open());
  TempDir& dir = studio.dir;
  HeadlessUi& ui = studio.ui;
  auto& app = studio.app;
  EXPECT_EQ(app->plant()->light.answers, 5u) << "the axiom and four steps answered";
  EXPECT_EQ(app->plant()->light.photons, 5u * 20000u) << "the scene's photons";

  // Open the panel and drag its photons slider: the environment changes and the plant regrows.
  ImGuiIO& io = ImGui::GetIO();
  show_light_widget(ui, *app, "light:photons");
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

TEST(StudioLight, AToggleColoursEveryQueryByItsAnswerOverThePicture) {
  LightStudio studio("StudioLightDots");
  ASSERT_NO_FATAL_FAILURE(studio.open());
  HeadlessUi& ui = studio.ui;
  auto& app = studio.app;
  ASSERT_EQ(app->plant()->queries.size(), 1u) << "one edited plant";
  const std::vector<GrowQuery>& queries = app->plant()->queries[0];
  ASSERT_GT(queries.size(), 2u);
  EXPECT_TRUE(app->query_dots().empty()) << "off until toggled";

  show_light_widget(ui, *app, "light:show_queries");
  const auto box = *app->rect("light:show_queries");
  ImGuiIO& io = ImGui::GetIO();
  io.MousePos = ImVec2(box.min.x + 6, box.centre().y);
  ui.frame(*app);
  io.MouseDown[0] = true;
  ui.frame(*app);
  io.MouseDown[0] = false;
  ui.frames(*app, 2);
  // Every query is drawn (the camera sees the whole plant), inside the viewport, coloured
  // by its own answer, far to near.
  const std::vector<QueryDot>& dots = app->query_dots();
  ASSERT_EQ(dots.size(), queries.size());
  const auto view = *app->rect("viewport");
  std::multiset<double> drawn, answered;
  for (const GrowQuery& q : queries) answered.insert(q.q);
  for (size_t i = 0; i < dots.size(); ++i) {
    const QueryDot& d = dots[i];
    drawn.insert(d.q);
    EXPECT_GE(d.centre.x, view.min.x);
    EXPECT_LE(d.centre.x, view.max.x);
    EXPECT_GE(d.centre.y, view.min.y);
    EXPECT_LE(d.centre.y, view.max.y);
    EXPECT_EQ(d.colour, light_colour(d.q));
    EXPECT_GE(d.radius, 2.0f);
    EXPECT_LE(d.radius, 9.0f);
    if (i > 0) {
      EXPECT_LE(d.depth, dots[i - 1].depth);
    }
  }
  EXPECT_EQ(drawn, answered);
  // The branches shade each other: the answers, and so the colours, differ.
  std::set<ImU32> colours;
  for (const QueryDot& d : dots) colours.insert(d.colour);
  EXPECT_GE(colours.size(), 3u);
  // The dots follow the camera: orbiting the view moves them (they are projected again).
  const std::vector<QueryDot> before = dots;
  const auto v = *app->rect("viewport");
  io.MousePos = v.centre();
  ui.frame(*app);
  io.MouseDown[0] = true;
  for (int i = 0; i < 4; ++i) {
    io.MousePos.x += 15;
    ui.frame(*app);
  }
  io.MouseDown[0] = false;
  ui.frames(*app, 2);
  ASSERT_EQ(app->query_dots().size(), before.size());
  double moved = 0;
  for (size_t i = 0; i < before.size(); ++i)
    moved = std::max<double>(moved, std::abs(app->query_dots()[i].centre.x - before[i].centre.x));
  EXPECT_GT(moved, 2.0) << "the view turned; the dots stayed";
  // Toggled off again: nothing is drawn.
  io.MousePos = ImVec2(app->rect("light:show_queries")->min.x + 6, app->rect("light:show_queries")->centre().y);
  io.MouseDown[0] = true;
  ui.frame(*app);
  io.MouseDown[0] = false;
  ui.frames(*app, 2);
  EXPECT_TRUE(app->query_dots().empty());
}

TEST(StudioLight, TheRampRunsFromDarkVioletToYellowGrowingBrighter) {
  auto rgb = [](ImU32 c) {
    const ImVec4 v = ImGui::ColorConvertU32ToFloat4(c);
    return std::array<float, 3>{v.x, v.y, v.z};
  };
  const auto lo = rgb(light_colour(0)), hi = rgb(light_colour(1));
  EXPECT_NEAR(lo[0], 0.267f, 0.01f);
  EXPECT_NEAR(lo[2], 0.329f, 0.01f);
  EXPECT_NEAR(hi[0], 0.993f, 0.01f);
  EXPECT_NEAR(hi[1], 0.906f, 0.01f);
  EXPECT_EQ(light_colour(-3), light_colour(0));
  EXPECT_EQ(light_colour(7), light_colour(1));
  EXPECT_EQ(light_colour(std::nan("")), light_colour(0));
  float previous = -1;
  for (int i = 0; i <= 20; ++i) {
    const auto c = rgb(light_colour(i / 20.0));
    const float luma = 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
    EXPECT_GT(luma, previous) << "q " << i / 20.0;
    previous = luma;
  }
}

}  // namespace
}  // namespace sylva::studio::test
