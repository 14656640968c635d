// studio_fog_test.cpp — the studio's Fog panel driven headless (an ImGui context with
// simulated input, the real grow and cone workers, a fake viewport): the controls change
// the scene's fog live, the shadow cones are rebuilt on the cone worker for a new sun and
// never for a camera move, and the fog is saved with the scene.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>

#include <string>

#include "core/scene/scene.h"
#include "core/scene/scene_json.h"
#include "core/util/file_io.h"
#include "tests/studio/headless_ui.h"

namespace sylva::studio::test {
namespace {

const char* const kTree =
    "angle: 30\n"
    "derivation length: 4\n"
    "axiom: A\n"
    "productions:\n"
    "A -> F(1)[+A][-A]\n";

// The tree under fog in a cone mode (fast), few photons: the cones take milliseconds.
const char* const kFoggyScene = R"({"format": "sylva-scene", "version": 1,
  "camera": {"eye": [6, 2, 6], "target": [0, 2, 0]},
  "sun": {"direction": [0.4, 1, -0.3], "angular_radius_deg": 0},
  "fog": {"sigma_s": 0.05, "sigma_a": 0.01, "g": 0.6, "top": 30, "mode": "fast", "steps": 16, "photons": 4000},
  "plants": [{"grammar": "tree.lsys"}]})";

struct FogFixture : ::testing::Test {
  FogFixture() : dir(::testing::UnitTest::GetInstance()->current_test_info()->name()) {
    EXPECT_TRUE(write_file_atomically(dir.file("tree.lsys"), kTree).ok());
    scene_path = dir.file("foggy.scene.json");
    EXPECT_TRUE(write_file_atomically(scene_path, kFoggyScene).ok());
  }
  // Opens the foggy scene and waits for its plant and its first cones.
  std::unique_ptr<StudioApp> opened() {
    StudioOptions o;
    o.presets_dir = std::string(SYLVA_SOURCE_DIR) + "/presets";
    auto app = std::make_unique<StudioApp>(o, &viewport);
    EXPECT_FALSE(app->open(scene_path));
    EXPECT_TRUE(ui.until(*app, [&] { return app->plant_drawn() && viewport.fog_cones_calls > 0; }));
    return app;
  }
  // Scrolls the panels until the widget `name` is wholly inside them.
  bool show(StudioApp& app, const std::string& name) {
    ImGuiIO& io = ImGui::GetIO();
    for (int i = 0; i < 60; ++i) {
      auto panels = app.rect("panels");
      auto widget = app.rect(name);
      if (!panels) return false;
      if (widget && widget->min.y >= panels->min.y && widget->max.y <= panels->max.y) return true;
      io.MousePos = panels->centre();
      io.MouseWheel = !widget || widget->max.y > panels->max.y ? -1.0f : 1.0f;
      ui.frame(app);
    }
    return false;
  }
  // Presses on the slider `name` near its left end and drags it right over `frames` frames.
  bool drag_slider(StudioApp& app, const std::string& name, int frames = 10) {
    if (!show(app, name)) return false;
    const WidgetRect r = *app.rect(name);
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = ImVec2(r.min.x + 5, r.centre().y);
    ui.frame(app);
    io.MouseDown[0] = true;
    for (int i = 0; i < frames; ++i) {
      io.MousePos.x += (r.max.x - r.min.x) * 0.04f;
      ui.frame(app);
    }
    io.MouseDown[0] = false;
    ui.frames(app, 2);
    return true;
  }
  TempDir dir;
  std::string scene_path;
  HeadlessUi ui;
  FakeViewport viewport;
};

TEST_F(FogFixture, CameraMovesAndTheMediumNeverRebuildTheConesTheSunDoesOnTheWorker) {
  auto app = opened();
  ASSERT_TRUE(app->scene().fog);
  EXPECT_EQ(app->cone_requests(), 1u) << "one build for the opened plants and sun";
  ASSERT_TRUE(viewport.last_cones);
  const uint64_t started = app->cone_worker().builds_started();
  const int renders = viewport.renders, plants = viewport.set_plants_calls;

  ASSERT_TRUE(ui.orbit(*app));
  ui.frames(*app, 5);
  EXPECT_GT(viewport.renders, renders) << "the new camera is drawn";
  EXPECT_EQ(app->cone_requests(), 1u) << "a camera move never rebuilds the cones";
  EXPECT_EQ(app->cone_worker().builds_started(), started);
  EXPECT_EQ(viewport.set_plants_calls, plants);

  // The medium's controls act on the scene's fog at once, without new cones or plants.
  const double sigma_s = app->scene().fog->sigma_s, g = app->scene().fog->g;
  ASSERT_TRUE(drag_slider(*app, "fog:sigma_s"));
  ASSERT_TRUE(drag_slider(*app, "fog:g"));
  EXPECT_NE(app->scene().fog->sigma_s, sigma_s);
  EXPECT_NE(app->scene().fog->g, g);
  EXPECT_EQ(app->cone_requests(), 1u) << "the medium needs no new cones";
  EXPECT_EQ(viewport.set_plants_calls, plants);

  // Dragging the sun asks the cone worker for new cones; the last ones stay on screen
  // until they come.
  const int given = viewport.fog_cones_calls;
  const std::shared_ptr<const ConeSet> before = viewport.last_cones;
  ASSERT_TRUE(drag_slider(*app, "sun azimuth"));
  EXPECT_GT(app->cone_requests(), 1u);
  EXPECT_TRUE(viewport.last_cones) << "the last cones keep drawing while the new are built";
  EXPECT_EQ(viewport.set_plants_calls, plants) << "a new sun is not new plants";
  ASSERT_TRUE(ui.until(*app, [&] { return !app->cone_worker().busy() && viewport.fog_cones_calls > given; }));
  ui.frames(*app, 3);
  EXPECT_NE(viewport.last_cones, before);
  const uint64_t asked = app->cone_requests();
  ui.frames(*app, 10);
  EXPECT_EQ(app->cone_requests(), asked) << "a sun at rest asks nothing more";
}

// Mode map from the panel's list (auto, brute, medium, fast, map): the cone worker builds the
// plants' sun maps and the viewport gets them; a camera move never rebuilds them, a new sun does.
TEST_F(FogFixture, MapFromTheModeListBuildsSunMapsOnTheWorkerOncePerSun) {
  auto app = opened();
  ASSERT_TRUE(show(*app, "fog:mode"));
  const WidgetRect combo = *app->rect("fog:mode");
  const ImGuiStyle& style = ImGui::GetStyle();
  const float row = ImGui::GetFontSize() + style.ItemSpacing.y;
  // The list opens below the control, or above it where the window has no room below.
  for (float y : {combo.max.y + style.WindowPadding.y + 4.5f * row, combo.min.y - style.WindowPadding.y - 0.5f * row}) {
    ui.click(*app, combo.centre());
    ui.click(*app, ImVec2(combo.min.x + 10, y));
    ui.frames(*app, 2);
    if (app->scene().fog->mode == FogMode::map) break;
  }
  ASSERT_EQ(app->scene().fog->mode, FogMode::map);
  ASSERT_TRUE(ui.until(*app, [&] { return !app->cone_worker().busy() && viewport.fog_maps_calls > 0; }));
  ASSERT_TRUE(viewport.last_maps);
  ASSERT_EQ(viewport.last_maps->size(), 1u) << "a point sun: one map";
  EXPECT_GT(viewport.last_maps->front().allocated_tiles(), 0u) << "the tree's tiles";
  const uint64_t asked = app->cone_requests();
  ASSERT_TRUE(ui.orbit(*app));
  ui.frames(*app, 5);
  EXPECT_EQ(app->cone_requests(), asked) << "a camera move never rebuilds the maps";
  const int given = viewport.fog_maps_calls;
  ASSERT_TRUE(drag_slider(*app, "sun azimuth"));
  EXPECT_GT(app->cone_requests(), asked);
  ASSERT_TRUE(ui.until(*app, [&] { return !app->cone_worker().busy() && viewport.fog_maps_calls > given; }));
}

TEST_F(FogFixture, FogSettingsAreSavedIntoTheScene) {
  auto app = opened();
  ASSERT_TRUE(drag_slider(*app, "fog:sigma_s"));
  ASSERT_TRUE(drag_slider(*app, "fog:steps"));
  const Fog shown = *app->scene().fog;
  EXPECT_NE(shown.steps, 16u);
  const std::string saved = dir.file("saved.scene.json");
  ASSERT_FALSE(app->save_scene(saved));
  Expected<Scene> read = read_scene_file(saved);
  ASSERT_TRUE(read) << read.error().format();
  ASSERT_TRUE(read->fog);
  EXPECT_EQ(*read->fog, shown) << "every fog key as the panel shows it";
  EXPECT_EQ(read->fog->mode, FogMode::fast);
  EXPECT_EQ(read->fog->photons, 4000u);

  // Removing the fog from the panel removes it from the saved scene.
  ASSERT_TRUE(show(*app, "fog:remove"));
  ui.click(*app, app->rect("fog:remove")->centre());
  EXPECT_FALSE(app->scene().fog);
  ASSERT_FALSE(app->save_scene(saved));
  read = read_scene_file(saved);
  ASSERT_TRUE(read) << read.error().format();
  EXPECT_FALSE(read->fog);
}

// Issue 31 §5: "add fog" scales the medium to the view, so a single tree is not washed out.
TEST(StudioAddFog, TheAddedFogLetsThePlantKeepThreeQuartersOfItsLight) {
  Camera near, far;
  near.eye = {0, 2, 10}, near.target = {0, 2, 0};
  far.eye = {0, 20, 400}, far.target = {0, 20, 0};
  for (const Camera& c : {near, far}) {
    const Fog f = fog_for_view(c);
    const double d = glm::length(c.eye - c.target);
    EXPECT_NEAR(std::exp(-(f.sigma_s + f.sigma_a) * d), std::exp(-kAddedFogOpticalDepth), 1e-9) << d;
    EXPECT_NEAR(f.sigma_a, f.sigma_s / 10, 1e-15);
  }
  EXPECT_LT(fog_for_view(far).sigma_s, fog_for_view(near).sigma_s);
  Camera degenerate;
  degenerate.eye = degenerate.target = {1, 1, 1};
  EXPECT_LE(fog_for_view(degenerate).sigma_s, 0.5);  // finite, within the panel's range
}

}  // namespace
}  // namespace sylva::studio::test
