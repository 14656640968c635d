// gl_viewport.h — the studio's viewport: the GL ray caster (core/gl/render_gl.h) over the
// plants, shown as a texture with ImGui::Image.
//
// The pictures are made on a render thread of its own with its own window-less OpenGL
// context (gl_context.h: EGL), so a slow picture — hundreds of milliseconds per frame on
// llvmpipe — never stalls the window: the UI thread posts what to draw (latest wins, like
// the grow worker's mailbox), keeps drawing frames, and uploads each finished picture into
// the window's texture, on its own context (the one GL upload the UI thread does).
// The ladder (viewport.h): set_plants() makes the render thread build a new GlRenderer
// (skin + upload to its context); image() asks for a new picture only when the camera,
// sun, sky, ground or size changed, or new plants arrived.
//
// How a picture reaches the texture is one function, present(): for now
// GlRenderer::render()'s readback (rows top-down, no flip), copied to the UI thread.
// Preconditions: construct, call and destroy on the UI thread with the window's context
// current (the texture lives there).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/studio/view_picture.h"
#include "app/studio/viewport.h"

namespace sylva::studio {

class GlViewport : public PictureViewport {
 public:
  // `on_picture` is called on the render thread when a picture is ready (the window loop
  // wakes itself with it). New plants are first shown as a preview (half the pixels a side,
  // a 512² shadow map; ViewStats::preview) when the last full picture took longer than
  // `preview_above_ms`, then in full. Throws GlError when the render thread gets no GL
  // context. The default, 1 s, was measured (docs/benchmarks.md, the studio): on llvmpipe
  // a preview of the pine (a ~0.3 s picture) cost more than the full picture it stood in for
  // (the half-size targets and the small shadow map are reallocated twice), so previews are
  // kept for pictures slow enough that a quarter of the pixels pays for that.
  explicit GlViewport(std::function<void()> on_picture = {}, double preview_above_ms = 1000);
  ~GlViewport() override;
  GlViewport(const GlViewport&) = delete;
  GlViewport& operator=(const GlViewport&) = delete;

  void set_plants(const Scene& scene, const RenderOptions& options) override;
  void set_fog_cones(std::shared_ptr<const ConeSet> cones) override;
  void set_fog_maps(std::shared_ptr<const std::vector<SunDepthMap>> maps) override;
  bool busy() const override;
  std::optional<std::string> write_image(const Scene& scene, const RenderOptions& options,
                                         const std::string& path) override;

 private:
  struct Shared;
  void run();  // the render thread
  void interrupt(bool new_plants) override;

  Shared* shared_;  // the mailbox, extended (owned by PictureViewport)
  std::thread thread_;
};

}  // namespace sylva::studio
