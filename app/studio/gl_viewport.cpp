// gl_viewport.cpp — see gl_viewport.h.
#include "app/studio/gl_viewport.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>

#include "core/gl/gl_api.h"
#include "core/gl/gl_context.h"
#include "core/gl/render_gl.h"
#include "core/render_output.h"
#include "core/util/color.h"

namespace sylva::studio {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Everything a picture depends on besides the plants.
std::vector<double> view_key(const Scene& s) {
  const Camera& c = s.camera;
  return {c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z, c.fov_y_deg,
          static_cast<double>(s.width), static_cast<double>(s.height), s.sun.direction.x, s.sun.direction.y,
          s.sun.direction.z, s.sun.angular_radius_deg, s.sun.radiance.x, s.sun.radiance.y, s.sun.radiance.z,
          s.sky.x, s.sky.y, s.sky.z, s.ground.height, s.ground.albedo.x, s.ground.albedo.y, s.ground.albedo.z};
}

struct Picture {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;  // sRGB-encoded, rows top-down
  uint64_t plants_version = 0;
  std::vector<RenderPass> passes;
  double render_ms = 0;
};

// The picture of `scene` from `renderer` as 8-bit sRGB RGBA: GlRenderer::render()'s
// readback, encoded. (A renderer that draws into a caller's framebuffer would draw into
// a texture shared with the window instead.)
Picture present(GlRenderer& renderer, const Scene& scene) {
  const auto start = Clock::now();
  RenderResult result = renderer.render(scene);
  Picture p;
  p.width = result.image.width;
  p.height = result.image.height;
  p.rgba.resize(static_cast<size_t>(p.width) * p.height * 4);
  const std::vector<float>& src = result.image.beauty;
  for (size_t i = 0; i < p.rgba.size(); ++i)
    p.rgba[i] = (i % 4 == 3) ? 255
                             : static_cast<uint8_t>(std::lround(std::clamp(linear_to_srgb(src[i]), 0.0f, 1.0f) * 255));
  p.passes = std::move(result.passes);
  p.render_ms = ms_since(start);
  return p;
}

}  // namespace

// What the UI thread and the render thread share, under `mutex`.
struct GlViewport::Shared {
  std::mutex mutex;
  std::condition_variable wake;
  bool quit = false;
  bool working = false;
  std::function<void()> on_picture;
  // Requests (latest wins).
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
  std::function<void(GlRenderer*, const RenderOptions&)> task;  // an export, run and waited for
  // Results.
  std::optional<Picture> picture;
  uint64_t built_version = 0;  // the plants the render thread's renderer holds
  std::string error;           // why there is no renderer / no picture
  uint64_t frusta = 0;
  double upload_ms = 0;
  std::string renderer_name;
  bool started = false;
  std::string start_error;
};

GlViewport::GlViewport(std::function<void()> on_picture) : shared_(std::make_unique<Shared>()) {
  shared_->on_picture = std::move(on_picture);
  thread_ = std::thread([this] { run(); });
  std::unique_lock<std::mutex> lock(shared_->mutex);
  shared_->wake.wait(lock, [this] { return shared_->started; });
  if (!shared_->start_error.empty()) {
    lock.unlock();
    thread_.join();
    throw GlError(shared_->start_error);
  }
  stats_.renderer = shared_->renderer_name;
}

GlViewport::~GlViewport() {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->quit = true;
  }
  shared_->wake.notify_all();
  if (thread_.joinable()) thread_.join();
  if (texture_) glDeleteTextures(1, &texture_);
}

void GlViewport::run() {
  Shared& sh = *shared_;
  GlContextResult context = create_headless_gl_context();
  {
    std::lock_guard<std::mutex> lock(sh.mutex);
    sh.started = true;
    if (!context.context) sh.start_error = "no OpenGL 4.5 context for the viewport: " + context.error;
    else sh.renderer_name = context.context->info().renderer;
  }
  sh.wake.notify_all();
  if (!context.context) return;
  std::unique_ptr<GlRenderer> renderer;
  RenderOptions options;
  uint64_t version = 0;
  for (;;) {
    std::optional<Shared::Plants> plants;
    std::optional<Shared::View> view;
    std::function<void(GlRenderer*, const RenderOptions&)> task;
    {
      std::unique_lock<std::mutex> lock(sh.mutex);
      sh.wake.wait(lock, [&] { return sh.quit || sh.plants || sh.view || sh.task; });
      if (sh.quit) break;
      plants = std::move(sh.plants);
      sh.plants.reset();
      task = std::move(sh.task);
      sh.task = nullptr;
      // A picture of older plants than those about to be built is not worth making.
      if (!plants || (sh.view && sh.view->version >= plants->version)) {
        view = std::move(sh.view);
        sh.view.reset();
      }
      sh.working = true;
    }
    std::string error;
    double upload_ms = 0;
    if (plants) {
      const auto start = Clock::now();
      renderer.reset();
      options = plants->options;
      version = plants->version;
      bool any = false;
      for (const ScenePlant& p : plants->scene.plants) any |= p.skeleton && p.skeleton->segment_count() > 0;
      if (!any) error = "the plant has no segments";
      else if (auto why = gl_unsupported(plants->scene, options)) error = *why;
      else {
        try {
          renderer = std::make_unique<GlRenderer>(plants->scene, options);
        } catch (const std::exception& e) {
          error = e.what();
        }
      }
      upload_ms = ms_since(start);
    }
    if (task) task(renderer.get(), options);
    std::optional<Picture> picture;
    if (view && renderer && view->version == version) {
      try {
        picture = present(*renderer, view->scene);
        picture->plants_version = version;
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    {
      std::lock_guard<std::mutex> lock(sh.mutex);
      sh.working = false;
      if (plants) {
        sh.built_version = version;
        sh.error = error;
        sh.frusta = renderer ? renderer->frusta() : 0;
        sh.upload_ms = upload_ms;
      } else if (!error.empty()) {
        sh.error = error;
      }
      if (picture) sh.picture = std::move(picture);
    }
    if ((picture || !error.empty()) && sh.on_picture) sh.on_picture();
  }
  renderer.reset();
}

void GlViewport::set_plants(const Scene& scene, const RenderOptions& options) {
  ++plants_version_;
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->plants = Shared::Plants{scene, options, plants_version_};
  }
  shared_->wake.notify_all();
}

bool GlViewport::busy() const {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  return shared_->working || shared_->plants || shared_->view || shared_->picture;
}

void GlViewport::take_picture() {
  std::optional<Picture> p;
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    p = std::move(shared_->picture);
    shared_->picture.reset();
    stats_.error = shared_->error;
    stats_.frusta = shared_->frusta;
    stats_.upload_ms = shared_->upload_ms;
  }
  if (!p) return;
  if (!texture_ || texture_w_ != p->width || texture_h_ != p->height) {
    if (texture_) glDeleteTextures(1, &texture_);
    glCreateTextures(GL_TEXTURE_2D, 1, &texture_);
    glTextureStorage2D(texture_, 1, GL_RGBA8, static_cast<GLsizei>(p->width), static_cast<GLsizei>(p->height));
    glTextureParameteri(texture_, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(texture_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(texture_, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(texture_, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    texture_w_ = p->width;
    texture_h_ = p->height;
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(texture_, 0, 0, 0, static_cast<GLsizei>(p->width), static_cast<GLsizei>(p->height), GL_RGBA,
                      GL_UNSIGNED_BYTE, p->rgba.data());
  shown_version_ = p->plants_version;
  stats_.passes = std::move(p->passes);
  stats_.render_ms = p->render_ms;
}

ViewImage GlViewport::image(const Scene& scene) {
  take_picture();
  std::vector<double> key = view_key(scene);
  if (key != asked_view_ || asked_version_ != plants_version_) {
    {
      std::lock_guard<std::mutex> lock(shared_->mutex);
      shared_->view = Shared::View{scene, plants_version_};
    }
    shared_->wake.notify_all();
    asked_view_ = std::move(key);
    asked_version_ = plants_version_;
  }
  if (!texture_) return {};
  bool current = shown_version_ == plants_version_;
  {
    // New plants that cannot be drawn (no segments, an error): nothing newer will come.
    std::lock_guard<std::mutex> lock(shared_->mutex);
    if (shared_->built_version == plants_version_ && !shared_->error.empty() && !shared_->working && !shared_->view)
      current = true;
  }
  return ViewImage{reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture_)), false, texture_w_, texture_h_,
                   current};
}

std::optional<std::string> GlViewport::write_image(const Scene& scene, const RenderOptions& options,
                                                   const std::string& path) {
  // Run on the render thread (its renderer when it was built with these options) and wait.
  std::promise<std::optional<std::string>> done;
  auto result = done.get_future();
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->task = [&](GlRenderer* current, const RenderOptions& current_options) {
      try {
        std::unique_ptr<GlRenderer> own;
        GlRenderer* r = current;
        if (!r || options.skin.knuckle_frusta != current_options.skin.knuckle_frusta ||
            options.geometry.relief != current_options.geometry.relief || options.spp != current_options.spp) {
          own = std::make_unique<GlRenderer>(scene, options);
          r = own.get();
        }
        RenderResult rendered = r->render(scene);
        Expected<std::vector<std::string>> written = write_render(path, rendered.image);
        std::optional<std::string> error;
        if (!written) {
          error = written.error().format();
          error->pop_back();  // the one line, without format()'s newline
        }
        done.set_value(std::move(error));
      } catch (const std::exception& e) {
        done.set_value(std::string(e.what()));
      }
    };
  }
  shared_->wake.notify_all();
  asked_view_.clear();  // the targets were resized: ask for the view again
  return result.get();
}

}  // namespace sylva::studio
