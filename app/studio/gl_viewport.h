// gl_viewport.h — the studio's viewport on the window's OpenGL 4.5 context: the GL ray
// caster (core/gl/render_gl.h) over the plants, shown as a texture with ImGui::Image.
// Preconditions: the window's context is current on the calling (UI) thread for the
// viewport's whole life.
//
// The ladder (viewport.h): set_plants() builds a new GlRenderer (skin + upload);
// image() re-renders only when the camera, sun, sky, ground or size changed, or new
// plants arrived. How a picture reaches the texture is one function, present(): for now
// GlRenderer::render()'s readback uploaded into the texture (rows top-down, no flip);
// a renderer that draws into a caller's framebuffer makes it a direct draw into the
// texture's framebuffer (rows bottom-up: flip_v).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/studio/viewport.h"

namespace sylva {
class GlRenderer;
}

namespace sylva::studio {

class GlViewport : public Viewport {
 public:
  explicit GlViewport(std::string renderer_name);
  ~GlViewport() override;
  void set_plants(const Scene& scene, const RenderOptions& options) override;
  ViewImage image(const Scene& scene) override;
  const ViewStats& stats() const override { return stats_; }
  std::optional<std::string> write_image(const Scene& scene, const RenderOptions& options,
                                         const std::string& path) override;

 private:
  // Renders `scene` into texture_ (see above); false with stats_.error set on failure.
  bool present(const Scene& scene);

  std::unique_ptr<GlRenderer> renderer_;
  RenderOptions options_;
  unsigned texture_ = 0;  // GLuint
  uint32_t texture_w_ = 0, texture_h_ = 0;
  bool fresh_plants_ = false;
  std::vector<double> last_view_;  // what the last picture was of (view_key)
  ViewImage last_image_;
  ViewStats stats_;
};

}  // namespace sylva::studio
