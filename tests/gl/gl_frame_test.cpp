// gl_frame_test.cpp — the GL frame API a window uses (render_gl.h, gl_target.h,
// gl_frame_stats.h): drawing into a caller's target gives the picture read_back gives and
// the one the CLI's readback always gave; a new camera, sun or size redraws without
// re-sending the plants, a new size reallocating the render targets alone; GPU times
// arrive a frame later without waiting, or when waited for; and the window path (the
// default framebuffer) draws into an EGL pbuffer's.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/gl/gl_api.h"
#include "core/gl/gl_frame_targets.h"
#include "core/gl/render_gl.h"
#include "core/util/color.h"
#include "tests/support/gl_checks.h"
#include "tests/support/plants.h"

namespace sylva {
namespace {

// The saguaro at a small size: a sunlit plant, enough frusta for a real frame.
Scene saguaro(uint32_t width = 64, uint32_t height = 48) {
  return gl_test::scene_around(test::grow_preset("saguaro"), width, height);
}

RenderOptions two_samples_with_depth() {
  RenderOptions options;
  options.spp = 2;  // the beauty is a sum ÷ spp, the AOVs a pass of their own
  options.aovs = kAovDepth | kAovNormal;
  return options;
}

// A w × h RGBA float texture's texels, rows bottom-up as GL keeps them.
std::vector<float> texture_texels(uint32_t texture, uint32_t w, uint32_t h) {
  std::vector<float> texels(static_cast<size_t>(w) * h * 4);
  glGetTextureImage(texture, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(texels.size() * sizeof(float)), texels.data());
  return texels;
}

TEST(GlFrame, DrawingIntoACallersTargetThenReadingBackGivesTheCliReadback) {
  SYLVA_REQUIRE_GL();
  const Scene scene = saguaro();
  const RenderOptions options = two_samples_with_depth();
  const RenderResult cli = gl_test::gl_render(scene, options);  // what `sylva render` writes

  GlRenderer renderer(scene, options);
  GlTextureTarget target(scene.width, scene.height);
  const GlFrameStats& drawn = renderer.draw(scene, target.target());
  EXPECT_TRUE(drawn.presented);
  EXPECT_EQ(drawn.pass(GlPass::present).runs, 1u);
  EXPECT_EQ(drawn.pass(GlPass::present).program, "present[]");
  const RenderImage image = renderer.read_back();
  EXPECT_EQ(image.beauty, cli.image.beauty);
  EXPECT_EQ(image.depth, cli.image.depth);
  EXPECT_EQ(image.normal, cli.image.normal);

  // The target holds the same floats, upright once GL's bottom-up rows are flipped.
  const std::vector<float> texels = texture_texels(target.texture(), scene.width, scene.height);
  size_t differing = 0;
  for (uint32_t y = 0; y < scene.height; ++y)
    for (uint32_t x = 0; x < scene.width; ++x)
      for (int k = 0; k < 4; ++k)
        differing += texels[((scene.height - 1 - y) * scene.width + x) * 4 + k] !=
                     image.beauty[(static_cast<size_t>(y) * scene.width + x) * 4 + k];
  EXPECT_EQ(differing, 0u);
}

TEST(GlFrame, AnSrgbTargetHoldsTheEncodedPicture) {
  SYLVA_REQUIRE_GL();
  const Scene scene = saguaro(32, 24);
  GlRenderer renderer(scene, {});
  GlTextureTarget target(scene.width, scene.height, GlTextureTarget::Format::rgba8);
  EXPECT_EQ(target.target().encoding, GlTargetEncoding::srgb);
  renderer.draw(scene, target.target());
  EXPECT_EQ(renderer.wait_for_frame().pass(GlPass::present).program, "present[SRGB]");
  const RenderImage image = renderer.read_back();
  std::vector<uint8_t> texels(static_cast<size_t>(scene.width) * scene.height * 4);
  glGetTextureImage(target.texture(), 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(texels.size()), texels.data());
  int worst = 0;
  for (uint32_t y = 0; y < scene.height; ++y)
    for (uint32_t x = 0; x < scene.width; ++x)
      for (int k = 0; k < 3; ++k) {
        const float linear = image.beauty[(static_cast<size_t>(y) * scene.width + x) * 4 + k];
        const int expected = static_cast<int>(std::lround(255 * linear_to_srgb(linear)));
        const int got = texels[((scene.height - 1 - y) * scene.width + x) * 4 + k];
        worst = std::max(worst, std::abs(got - expected));
      }
  EXPECT_LE(worst, 1) << "8-bit sRGB codes differ from color.h's encoding by more than rounding";
}

TEST(GlFrame, ANewCameraOrSunRedrawsWithoutSendingThePlants) {
  SYLVA_REQUIRE_GL();
  Scene scene = saguaro();
  const RenderOptions options = two_samples_with_depth();
  GlRenderer renderer(scene, options);
  const GlFrameStats first = renderer.draw(scene);
  EXPECT_EQ(first.frame, 1u);
  EXPECT_GE(first.plant_bytes_uploaded, renderer.uploaded_bytes()) << "frame 1 carries the constructor's upload";
  EXPECT_EQ(first.targets_allocated, 3u) << "G-buffer, accumulation, shadow map";

  scene.camera.eye += glm::dvec3(1.5, 0.5, -1);
  const GlFrameStats moved = renderer.draw(scene);
  EXPECT_EQ(moved.plant_bytes_uploaded, 0u);
  EXPECT_EQ(moved.targets_allocated, 0u);
  EXPECT_EQ(moved.geometry_bytes, first.geometry_bytes);
  EXPECT_EQ(moved.compile_s, 0.0) << moved.compiled;
  const RenderImage moved_image = renderer.read_back();
  EXPECT_EQ(moved_image.beauty, gl_test::gl_render(scene, options).image.beauty) << "the moved camera's own picture";

  scene.sun.direction = {-0.6, 0.8, 0.1};
  const GlFrameStats sunset = renderer.draw(scene);
  EXPECT_EQ(sunset.plant_bytes_uploaded, 0u);
  EXPECT_EQ(sunset.targets_allocated, 0u);
  EXPECT_EQ(renderer.read_back().beauty, gl_test::gl_render(scene, options).image.beauty);

  // Only update_plants sends plant data, and the next frame says how much.
  const uint64_t sent = renderer.update_plants(scene);
  EXPECT_EQ(renderer.draw(scene).plant_bytes_uploaded, sent);
  EXPECT_EQ(renderer.draw(scene).plant_bytes_uploaded, 0u);
}

TEST(GlFrame, AResizeReallocatesTheRenderTargetsAlone) {
  SYLVA_REQUIRE_GL();
  Scene scene = saguaro(64, 48);
  const RenderOptions options = two_samples_with_depth();
  GlRenderer renderer(scene, options);
  const GlFrameStats small = renderer.draw(scene);
  scene.width = 96;
  scene.height = 72;
  const GlFrameStats large = renderer.draw(scene);
  EXPECT_EQ(large.targets_allocated, 2u) << "G-buffer and accumulation; the shadow map keeps its size";
  EXPECT_EQ(large.shadow_texels, small.shadow_texels);
  EXPECT_EQ(large.plant_bytes_uploaded, 0u);
  EXPECT_EQ(large.target_bytes, GlFrameTargets::kBytesPerPixel * 96 * 72 + 4ull * large.shadow_texels * large.shadow_texels);
  const RenderImage image = renderer.read_back();
  EXPECT_EQ(image.width, 96u);
  EXPECT_EQ(image.beauty, gl_test::gl_render(scene, options).image.beauty);
  EXPECT_EQ(renderer.draw(scene).targets_allocated, 0u) << "the same size again: nothing reallocated";

  // A caller's texture target follows the same rule.
  GlTextureTarget target(64, 48);
  const uint32_t texture = target.texture();
  EXPECT_FALSE(target.resize(64, 48));
  EXPECT_EQ(target.texture(), texture);
  EXPECT_TRUE(target.resize(96, 72));
  EXPECT_EQ(target.width(), 96u);
  renderer.draw(scene, target.target());
  EXPECT_EQ(renderer.read_back().beauty, image.beauty);
}

TEST(GlFrame, PassTimesArriveAFrameLaterWithoutWaitingAndAreNonNegative) {
  SYLVA_REQUIRE_GL();
  const Scene scene = saguaro(48, 36);
  GlRenderer renderer(scene, two_samples_with_depth());
  EXPECT_THROW(renderer.wait_for_frame(), std::logic_error) << "no frame yet";
  const GlFrameStats first = renderer.draw(scene);
  // draw() does not wait for the GPU; whether the times happen to be ready when it returns
  // is a race (llvmpipe can finish a 48x36 frame first), so only polling is asserted below.
  EXPECT_EQ(first.pass(GlPass::shadow).runs, 2u) << "the sun is a disc: a shadow map per sample";
  EXPECT_EQ(first.pass(GlPass::geometry).runs, 3u) << "two samples and the AOVs at pixel centres";
  EXPECT_EQ(first.pass(GlPass::shade).runs, 2u);
  EXPECT_EQ(first.pass(GlPass::present).runs, 0u) << "no target, no present pass";
  EXPECT_GE(first.cpu_s, 0.0);
  renderer.draw(scene);

  // Polling never waits: the first frame's times come in once the GPU has run it.
  std::optional<GlFrameStats> timed;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!(timed = renderer.timed_frame()) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_TRUE(timed) << "no frame's GPU times arrived within 60 s";
  EXPECT_TRUE(timed->gpu_times_ready);
  EXPECT_LE(timed->frame, 2u);
  for (size_t p = 0; p < kGlPassCount; ++p) EXPECT_GE(timed->passes[p].gpu_s, 0.0) << p;
  EXPECT_GT(timed->gpu_s(), 0.0);

  // Waiting gives the last frame's; more frames than the ring holds lose none.
  for (int i = 0; i < 6; ++i) renderer.draw(scene);
  const GlFrameStats& last = renderer.wait_for_frame();
  EXPECT_EQ(last.frame, 8u);
  EXPECT_TRUE(last.gpu_times_ready);
  EXPECT_GT(last.pass(GlPass::geometry).gpu_s, 0.0);
  const std::optional<GlFrameStats> newest = renderer.timed_frame();
  ASSERT_TRUE(newest);
  EXPECT_EQ(newest->frame, 8u);
  EXPECT_FALSE(renderer.timed_frame()) << "each timed frame is handed out once";
}

TEST(GlFrame, SkinningStopsWhenCancelledAndRenderGlFlagsIt) {
  SYLVA_REQUIRE_GL();
  const Scene scene = saguaro();
  std::atomic<bool> cancel{true};
  RenderOptions options;
  options.progress = Progress(&cancel);
  EXPECT_THROW(GlRenderer(scene, options), GlCancelled);
  const RenderResult flagged = gl_test::gl_render(scene, options);
  EXPECT_TRUE(flagged.cancelled);
  EXPECT_TRUE(flagged.image.beauty.empty());

  // A renderer whose update is cancelled keeps drawing the plants it has.
  cancel = false;
  GlRenderer renderer(scene, options);
  renderer.draw(scene);
  const RenderImage before = renderer.read_back();
  cancel = true;
  Scene moved = scene;
  moved.plants[0].position.x += 0.5;
  EXPECT_THROW(renderer.update_plants(moved), GlCancelled);
  cancel = false;
  renderer.draw(scene);
  EXPECT_EQ(renderer.read_back().beauty, before.beauty);
  EXPECT_GT(renderer.update_plants(moved), 0u);  // not cancelled: uploaded
  renderer.draw(moved);
  EXPECT_NE(renderer.read_back().beauty, before.beauty);
}

TEST(GlFrame, ATargetOfAnotherSizeOrNoDefaultFramebufferIsRefused) {
  SYLVA_REQUIRE_GL();
  const Scene scene = saguaro(32, 24);
  GlRenderer renderer(scene, {});
  EXPECT_THROW(renderer.read_back(), std::logic_error) << "nothing drawn yet";
  GlTextureTarget wrong(33, 24);
  EXPECT_THROW(renderer.draw(scene, wrong.target()), std::invalid_argument);
  // The shared test context has no surface, so no default framebuffer.
  try {
    renderer.draw(scene, GlTarget{0, scene.width, scene.height, GlTargetEncoding::srgb});
    FAIL() << "drew into a default framebuffer that does not exist";
  } catch (const GlError& e) {
    EXPECT_NE(std::string(e.what()).find("no surface"), std::string::npos) << e.what();
  }
}

// Makes the shared context current with a pbuffer for its life, without a surface after.
class PbufferCurrent {
 public:
  PbufferCurrent(GlContext& context, const GlPbuffer& pbuffer) : context_(context) { context.make_current(pbuffer); }
  ~PbufferCurrent() { context_.make_current(); }
  PbufferCurrent(const PbufferCurrent&) = delete;
  PbufferCurrent& operator=(const PbufferCurrent&) = delete;

 private:
  GlContext& context_;
};

TEST(GlFrame, TheWindowPathDrawsIntoTheDefaultFramebufferOfAPbuffer) {
  SYLVA_REQUIRE_GL();
  std::string why;
  GlContext* context = gl_test::shared_context(&why);
  const Scene scene = saguaro(40, 30);
  GlPbufferResult made = context->create_pbuffer(scene.width, scene.height);
  if (!made.pbuffer) GTEST_SKIP() << "no EGL pbuffer on this display (" << made.error << "): the studio's window covers this path";
  GlRenderer renderer(scene, {});
  std::vector<uint8_t> pixels(static_cast<size_t>(scene.width) * scene.height * 4);
  RenderImage image;
  {
    PbufferCurrent current(*context, *made.pbuffer);
    renderer.draw(scene, GlTarget{0, scene.width, scene.height, GlTargetEncoding::srgb});
    image = renderer.read_back();
    GLint drawn_to = GL_BACK;  // the surface's draw buffer, the one present wrote
    glGetIntegerv(GL_DRAW_BUFFER, &drawn_to);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(static_cast<GLenum>(drawn_to));
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, static_cast<GLsizei>(scene.width), static_cast<GLsizei>(scene.height), GL_RGBA,
                 GL_UNSIGNED_BYTE, pixels.data());
    ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  }
  int worst = 0;
  size_t plant_pixels = 0;
  for (uint32_t y = 0; y < scene.height; ++y)
    for (uint32_t x = 0; x < scene.width; ++x) {
      const size_t p = static_cast<size_t>(y) * scene.width + x;
      for (int k = 0; k < 3; ++k) {
        const int expected = static_cast<int>(std::lround(255 * linear_to_srgb(image.beauty[p * 4 + k])));
        const int got = pixels[((scene.height - 1 - y) * scene.width + x) * 4 + k];
        worst = std::max(worst, std::abs(got - expected));
      }
      plant_pixels += image.beauty[p * 4 + 1] > image.beauty[p * 4 + 2];  // green over the blue sky
    }
  EXPECT_LE(worst, 1);
  EXPECT_GT(plant_pixels, 0u) << "the window shows the plant";
}

TEST(GlFrame, VerboseListsThePassesFromTheStats) {
  GlFrameStats s;
  s.width = 64, s.height = 48, s.spp = 2;
  s.frusta = 120;
  s.eye_inside = 1;
  s.shadow_texels = 1024;
  s.pass(GlPass::shadow) = {1, 0.002, "frusta[SHADOW_PASS]"};
  s.pass(GlPass::geometry) = {3, 0.004, "frusta[GBUFFER_PASS]"};
  s.pass(GlPass::shade) = {2, 0.001, "shade[SUN]"};
  const std::vector<RenderPass> passes = describe_frame(s);
  ASSERT_EQ(passes.size(), 3u);
  EXPECT_EQ(passes[0].name, "shadow map (GPU)");
  EXPECT_EQ(passes[0].detail, "1024x1024, 1 pass(es), frusta[SHADOW_PASS]");
  EXPECT_EQ(passes[1].name, "frusta (GPU)");
  EXPECT_EQ(passes[1].detail, "120 frusta, 3 pass(es), frusta[GBUFFER_PASS], 1 around the eye");
  EXPECT_EQ(passes[1].seconds, 0.004);
  EXPECT_EQ(passes[2].name, "shade (GPU)");
  EXPECT_EQ(passes[2].detail, "2 pass(es), shade[SUN]");
  EXPECT_DOUBLE_EQ(s.gpu_s(), 0.007);
  s.geometry = GeometryKind::mesh;
  s.geometry_label = "GS 1";
  s.triangles = 96;
  s.compile_s = 0.5;
  s.compiled = "frusta[GBUFFER_PASS EYE_INSIDE]";
  s.presented = true;
  s.pass(GlPass::present) = {1, 0.0001, "present[SRGB]"};
  const std::vector<RenderPass> mesh = describe_frame(s);
  ASSERT_EQ(mesh.size(), 5u);
  EXPECT_EQ(mesh[0].name, "programs");
  EXPECT_EQ(mesh[0].detail, "built for this frame: frusta[GBUFFER_PASS EYE_INSIDE]");
  EXPECT_EQ(mesh[2].name, "mesh (GPU)");
  EXPECT_EQ(mesh[2].detail, "96 triangles (GS 1), 3 pass(es), frusta[GBUFFER_PASS]");
  EXPECT_EQ(mesh[4].name, "present (GPU)");
  EXPECT_EQ(mesh[4].detail, "64x48, present[SRGB]");
}

}  // namespace
}  // namespace sylva
