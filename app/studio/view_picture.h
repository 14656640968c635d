// view_picture.h — what both studio viewports (gl_viewport.h, cpu_viewport.h) share: the
// key of what a picture shows besides the plants, and what they do with a finished
// picture on the UI thread — 8-bit sRGB RGBA bytes (from a CPU render's float image) into
// a texture of the window's context for ImGui::Image.
// Preconditions: the GL calls run on the UI thread with the window's context current.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <imgui.h>

#include "app/studio/viewport.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"

namespace sylva::studio {

// Everything a picture depends on besides the plants: camera, size, sun, sky, ground, fog.
std::vector<double> view_key(const Scene& scene);

// `image`'s beauty as 8-bit RGBA, sRGB-encoded (alpha linear), rows top-down as the image.
std::vector<uint8_t> srgb8_rgba(const RenderImage& image);

// A texture of `rgba` (width × height, top row first; linear filtering), or null for an
// empty or mis-sized picture. Freed with free_rgba_texture.
ImTextureID make_rgba_texture(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba);
void free_rgba_texture(ImTextureID texture);

// The one texture a viewport shows, re-made only when the picture's size changes.
class ViewTexture {
 public:
  ViewTexture() = default;
  ~ViewTexture();
  ViewTexture(const ViewTexture&) = delete;
  ViewTexture& operator=(const ViewTexture&) = delete;

  void upload(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba);
  ImTextureID id() const;  // null before the first upload
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }

 private:
  unsigned texture_ = 0;  // GLuint
  uint32_t width_ = 0, height_ = 0;
};

// A finished picture, handed from a viewport's render thread to the UI thread.
struct ViewPicture {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;  // sRGB-encoded; rows as the viewport's ViewImage::flip_v says
  uint64_t plants_version = 0;
  std::vector<RenderPass> passes;
  double render_ms = 0;
  bool preview = false;  // a quicker picture; a better one follows unless newer work comes
};

// What a viewport's UI thread and its render thread share, under `mutex`: requests (the
// latest wins) and results. Each viewport's own state extends it.
struct PictureMailbox {
  std::mutex mutex;
  std::condition_variable wake;
  bool quit = false;
  bool working = false;              // the render thread is at work
  std::function<void()> on_picture;  // called on the render thread when a picture is ready
  // Requests.
  struct Plants {
    Scene scene;
    RenderOptions options;
    uint64_t version;
  };
  std::optional<Plants> plants;
  struct View {
    Scene scene;
    uint64_t version;
  };
  std::optional<View> view;
  std::shared_ptr<const ConeSet> cones;                  // the fog's cones (cone_worker.h)
  std::shared_ptr<const std::vector<SunDepthMap>> maps;  // fog mode map's sun maps
  // Results.
  std::optional<ViewPicture> picture;
  uint64_t built_version = 0;  // the plants the render thread holds
  std::string error;           // why there is no picture
  uint64_t frusta = 0;
  double upload_ms = 0;
  uint64_t previews = 0;       // made so far
};

// What the GL and CPU viewports share on the UI thread: the texture, which plants were
// asked for and which the texture shows, the last view asked for, and image()'s rule — ask
// for a picture only when the view (view_key) or the plants changed, show the newest
// finished one at once.
class PictureViewport : public Viewport {
 public:
  ViewImage image(const Scene& scene) override;
  const ViewStats& stats() const override { return stats_; }
  ImTextureID make_texture(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) override {
    return make_rgba_texture(width, height, rgba);
  }
  void free_texture(ImTextureID texture) override { free_rgba_texture(texture); }

 protected:
  // `mailbox`: the viewport's own, extended (the subclass reaches it through mailbox()).
  PictureViewport(std::unique_ptr<PictureMailbox> mailbox, bool flip_v)
      : mailbox_(std::move(mailbox)), flip_v_(flip_v) {}
  PictureMailbox& mailbox() { return *mailbox_; }
  // set_plants: posts the plants (a newer version) to the render thread.
  void post_plants(const Scene& scene, const RenderOptions& options);
  // New plants (or, `new_plants` false, a new view) were just posted, the mailbox locked:
  // stop the work in flight that they make useless, where the viewport can.
  virtual void interrupt(bool new_plants) { (void)new_plants; }
  void ask_again() { asked_view_.clear(); }  // the next image() asks anew
  ViewStats stats_;

 private:
  // The newest finished picture, if any, refreshing the stats the render thread keeps.
  std::optional<ViewPicture> take_finished();
  std::unique_ptr<PictureMailbox> mailbox_;
  bool flip_v_;
  ViewTexture texture_;             // in the UI thread's context
  uint64_t plants_version_ = 0;     // set_plants calls
  uint64_t shown_version_ = 0;      // the plants the texture shows
  std::vector<double> asked_view_;  // the last picture asked for
  uint64_t asked_version_ = 0;
};

}  // namespace sylva::studio
