// gl_viewport_test.cpp — the studio's viewports on a headless context standing in for the
// window's. GL (app/studio/gl_viewport.h): the first picture of a document is full size;
// new plants on a slow renderer show first as a preview (half the pixels a side), then in
// full; a fast renderer shows them in full at once. CPU (app/studio/cpu_viewport.h): each
// view coarse to fine, ending in exactly the CPU renderer's picture; nothing re-rendered
// while nothing changes; the newest plants win. No window, no X.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "app/studio/cone_worker.h"
#include "app/studio/cpu_viewport.h"
#include "app/studio/gl_viewport.h"
#include "core/cpu/render_cpu.h"
#include "core/gl/gl_api.h"
#include "core/gl/gl_context.h"
#include "core/grow/grow.h"
#include "core/scene/scene.h"
#include "core/light/shadow_cones.h"
#include "tests/support/requirements.h"

namespace sylva::studio {
namespace {

Scene saguaro(uint32_t width, uint32_t height) {
  Scene grown;
  ScenePlant plant;
  plant.grammar = std::string(SYLVA_SOURCE_DIR) + "/presets/saguaro.lsys";
  grown.plants.push_back(plant);
  EXPECT_TRUE(grow_scene_plants(grown).ok());
  Scene scene = default_scene_for(*grown.plants[0].skeleton, width, height);
  scene.plants[0] = grown.plants[0];
  return scene;
}

// Asks for `scene`'s picture until the viewport is idle; the last image asked.
ViewImage settle(Viewport& viewport, const Scene& scene) {
  ViewImage image;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  do {
    image = viewport.image(scene);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  } while ((viewport.busy() || !image.current || !image.texture) && std::chrono::steady_clock::now() < give_up);
  return viewport.image(scene);
}

struct Viewports : ::testing::Test {
  void SetUp() override {
    context = create_headless_gl_context();  // the window's context, for the UI texture
    if (!context.context) SYLVA_SKIP_WITHOUT_GL("no OpenGL 4.5 context: " << context.error);
  }
  GlContextResult context;
};

TEST_F(Viewports, NewPlantsOnASlowRendererShowAPreviewThenTheFullPicture) {
  GlViewport viewport({}, /*preview_above_ms=*/0);  // every renderer counts as slow
  Scene scene = saguaro(96, 64);
  viewport.set_plants(scene, RenderOptions{});
  ViewImage first = settle(viewport, scene);
  EXPECT_EQ(first.width, 96u) << "a document's first picture is full size";
  EXPECT_EQ(first.height, 64u);
  EXPECT_TRUE(first.flip_v) << "GL rows are bottom-up";
  EXPECT_EQ(viewport.stats().previews, 0u);

  scene.plants[0].position.x += 0.3;
  viewport.set_plants(scene, RenderOptions{});
  const ViewImage full = settle(viewport, scene);
  EXPECT_EQ(viewport.stats().previews, 1u) << "new plants: one preview";
  EXPECT_FALSE(viewport.stats().preview) << "then the full picture";
  EXPECT_EQ(full.width, 96u);
  EXPECT_EQ(full.height, 64u);
  EXPECT_TRUE(viewport.stats().error.empty()) << viewport.stats().error;
}

TEST_F(Viewports, AFastRendererShowsNewPlantsInFullAtOnce) {
  GlViewport viewport({}, /*preview_above_ms=*/1e9);
  Scene scene = saguaro(96, 64);
  viewport.set_plants(scene, RenderOptions{});
  settle(viewport, scene);
  scene.plants[0].position.x += 0.3;
  viewport.set_plants(scene, RenderOptions{});
  const ViewImage full = settle(viewport, scene);
  EXPECT_EQ(viewport.stats().previews, 0u);
  EXPECT_EQ(full.width, 96u);
}

// A plant of leaves alone (a grammar of one polygon) is drawn; a plant of nothing says why.
TEST_F(Viewports, APlantOfLeavesAloneIsDrawnAndAnEmptyOneSaysWhy) {
  GlViewport viewport({}, /*preview_above_ms=*/1e9);
  Skeleton leaf;
  leaf.leaves = {Leaf{std::nullopt, 1, {{0, 0, 0}, {0.1, 0.1, 0}, {0, 0.3, 0}, {-0.1, 0.1, 0}}, std::nullopt}};
  Scene scene = default_scene_for(leaf, 64, 48);
  viewport.set_plants(scene, RenderOptions{});
  const ViewImage image = settle(viewport, scene);
  EXPECT_TRUE(viewport.stats().error.empty()) << viewport.stats().error;
  EXPECT_TRUE(image.texture);

  scene.plants[0].skeleton = Skeleton{};
  viewport.set_plants(scene, RenderOptions{});
  settle(viewport, scene);
  EXPECT_EQ(viewport.stats().error, "the plant has no segments or leaves");
}

// The passes' detail of the last picture's pass named `name`, or "" when it did not run.
std::string pass_detail(const GlViewport& viewport, const std::string& name) {
  for (const RenderPass& p : viewport.stats().passes)
    if (p.name == name) return p.detail;
  return "";
}

// A scene in a fog cone mode is drawn brute until its cones come (the cone worker builds
// them off the UI thread), then with them; a new medium is a new picture of the same cones.
TEST_F(Viewports, FogInAConeModeDrawsBruteUntilTheConesComeThenWithThem) {
  GlViewport viewport({}, /*preview_above_ms=*/1e9);
  Scene scene = saguaro(96, 64);
  Fog fog;
  fog.sigma_s = 0.05;
  fog.top = 30;
  fog.mode = FogMode::fast;
  fog.steps = 8;
  fog.photons = 4000;
  scene.fog = fog;
  viewport.set_plants(scene, RenderOptions{});
  settle(viewport, scene);
  ASSERT_TRUE(viewport.stats().error.empty()) << viewport.stats().error;
  EXPECT_EQ(pass_detail(viewport, "fog (GPU)").rfind("brute, 8 steps", 0), 0u) << pass_detail(viewport, "fog (GPU)");
  EXPECT_EQ(pass_detail(viewport, "fog cones (GPU)"), "");

  ConeWorker worker;
  worker.submit(ConeRequest{scene, SkinOptions{}, FogMode::fast, fog.photons});
  ASSERT_TRUE(worker.wait_idle(60));
  std::optional<ConeResult> cones = worker.poll();
  ASSERT_TRUE(cones);
  ASSERT_GT(cones->cones->size(), 0u);
  EXPECT_EQ(worker.builds_finished(), 1u);
  viewport.set_fog_cones(cones->cones);
  settle(viewport, scene);
  EXPECT_EQ(pass_detail(viewport, "fog (GPU)").rfind("fast", 0), 0u) << pass_detail(viewport, "fog (GPU)");
  EXPECT_NE(pass_detail(viewport, "fog cones (GPU)"), "");

  scene.fog->mode = FogMode::medium;  // the same cones serve the other cone mode
  settle(viewport, scene);
  EXPECT_EQ(pass_detail(viewport, "fog (GPU)").rfind("medium, 8 steps", 0), 0u) << pass_detail(viewport, "fog (GPU)");
  EXPECT_TRUE(viewport.stats().error.empty()) << viewport.stats().error;
}

// The bytes of a viewport's texture (RGBA8, as uploaded: the CPU's rows top-down).
std::vector<uint8_t> texture_bytes(const ViewImage& image) {
  std::vector<uint8_t> out(size_t{image.width} * image.height * 4);
  const GLuint name = static_cast<GLuint>(reinterpret_cast<intptr_t>(image.texture));
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(name, 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(out.size()), out.data());
  return out;
}

std::vector<uint8_t> cpu_picture(const Scene& scene, uint32_t spp) {
  RenderOptions o;
  o.spp = spp;
  return srgb8_rgba(render_cpu(scene, o).image);
}

TEST_F(Viewports, TheCpuViewportDrawsCoarseToFineEndingInTheCpuRenderersPicture) {
  CpuViewport viewport({}, "test", /*refine_below_ms=*/1e9);
  EXPECT_EQ(viewport.stats().renderer, "CPU ray caster (test)");
  Scene scene = saguaro(96, 64);
  viewport.set_plants(scene, RenderOptions{});
  const ViewImage image = settle(viewport, scene);
  ASSERT_TRUE(image.texture);
  EXPECT_EQ(image.width, 96u);
  EXPECT_EQ(image.height, 64u);
  EXPECT_FALSE(image.flip_v) << "the CPU's rows are top-down";
  EXPECT_EQ(viewport.stats().previews, 3u) << "a quarter, a half, then full at 1 sample";
  EXPECT_FALSE(viewport.stats().preview) << "then the antialiased picture";
  EXPECT_EQ(texture_bytes(image), cpu_picture(scene, 4));
  EXPECT_TRUE(viewport.stats().error.empty()) << viewport.stats().error;

  // Nothing changed: the cached picture, no work.
  EXPECT_EQ(viewport.image(scene).texture, image.texture);
  EXPECT_FALSE(viewport.busy());
  // The camera moved: drawn again, coarse to fine.
  scene.camera.eye.x += 0.5;
  const ViewImage moved = settle(viewport, scene);
  EXPECT_EQ(viewport.stats().previews, 6u);
  EXPECT_EQ(texture_bytes(moved), cpu_picture(scene, 4));
}

TEST_F(Viewports, TheCpuViewportSkipsTheRefinementWhenTheFullPictureIsSlow) {
  CpuViewport viewport({}, "test", /*refine_below_ms=*/0);
  Scene scene = saguaro(96, 64);
  viewport.set_plants(scene, RenderOptions{});
  const ViewImage image = settle(viewport, scene);
  EXPECT_EQ(viewport.stats().previews, 2u) << "a quarter and a half, then full at 1 sample: the last";
  EXPECT_FALSE(viewport.stats().preview);
  EXPECT_EQ(texture_bytes(image), cpu_picture(scene, 1));
}

TEST_F(Viewports, TheCpuViewportShowsTheNewestPlantsAndSaysWhyAnEmptyOneIsNotDrawn) {
  CpuViewport viewport({}, "test", 1e9);
  Scene scene = saguaro(96, 64);
  viewport.set_plants(scene, RenderOptions{});
  viewport.image(scene);
  scene.plants[0].position.x += 0.4;  // newer plants at once: the older picture is dropped
  viewport.set_plants(scene, RenderOptions{});
  const ViewImage image = settle(viewport, scene);
  EXPECT_TRUE(image.current);
  EXPECT_EQ(texture_bytes(image), cpu_picture(scene, 4));

  Scene empty = scene;
  empty.plants[0].skeleton = Skeleton{};
  viewport.set_plants(empty, RenderOptions{});
  settle(viewport, empty);
  EXPECT_EQ(viewport.stats().error, "the plant has no segments or leaves");
}

TEST_F(Viewports, TheCpuViewportSaysWhyAViewOfPlantsItHadShownCannotBeDrawn) {
  CpuViewport viewport({}, "test", 1e9);
  Scene scene = saguaro(96, 64);
  viewport.set_plants(scene, RenderOptions{});
  ASSERT_TRUE(settle(viewport, scene).texture);
  ASSERT_TRUE(viewport.stats().error.empty()) << viewport.stats().error;
  // The same plants under a new view whose materials name an image that is not there:
  // render_cpu throws, and the viewport says so instead of keeping the old picture mute.
  Scene broken = scene;
  broken.camera.eye.x += 0.3;
  SceneMaterial wood;
  wood.albedo_image = "/nonexistent/sylva/bark.png";
  wood.segment_repeat = SegmentRepeat{};
  broken.materials[0] = wood;
  settle(viewport, broken);
  EXPECT_NE(viewport.stats().error.find("bark.png"), std::string::npos) << viewport.stats().error;
  // A view that can be drawn again clears it.
  scene.camera.eye.x -= 0.3;
  settle(viewport, scene);
  EXPECT_TRUE(viewport.stats().error.empty()) << viewport.stats().error;
}

}  // namespace
}  // namespace sylva::studio
