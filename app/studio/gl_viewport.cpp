// gl_viewport.cpp — see gl_viewport.h.
#include "app/studio/gl_viewport.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <future>

#include "core/gl/gl_api.h"
#include "core/gl/gl_context.h"
#include "core/gl/gl_frame_stats.h"
#include "core/gl/gl_program.h"
#include "core/gl/gl_target.h"
#include "core/gl/render_gl.h"
#include "core/scene/render_output.h"

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
          s.sky.x, s.sky.y, s.sky.z, s.ground.height, s.ground.albedo.x, s.ground.albedo.y, s.ground.albedo.z,
          s.fog ? 1.0 : 0.0, s.fog ? s.fog->sigma_s : 0, s.fog ? s.fog->sigma_a : 0, s.fog ? s.fog->g : 0,
          s.fog ? s.fog->height_falloff : 0, s.fog ? s.fog->top : 0, s.fog ? static_cast<double>(s.fog->mode) : 0,
          s.fog ? static_cast<double>(s.fog->steps) : 0};
}

// The scene the renderer draws: a cone mode without cones yet (mode map without maps) is
// drawn brute (the same fog, slower) until the cone worker's first cones (maps) arrive.
Scene drawable(const Scene& scene, bool have_cones, bool have_maps) {
  if (!scene.fog || scene.fog->mode == FogMode::brute) return scene;
  if (gl_fog_walks_maps(scene.fog->mode) ? have_maps : have_cones) return scene;
  Scene s = scene;
  s.fog->mode = FogMode::brute;
  return s;
}

struct Picture {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;  // sRGB-encoded, rows top-down
  uint64_t plants_version = 0;
  std::vector<RenderPass> passes;
  double render_ms = 0;
  bool preview = false;
};

constexpr uint32_t kPreviewShadowTexels = 512;

// The preview of `scene`: half the pixels a side (ImGui::Image stretches it to the panel)
// and a 512² shadow map — on llvmpipe about a quarter of the fill of the full picture,
// which dominates its cost (docs/benchmarks.md, the studio).
Scene preview_of(const Scene& scene) {
  Scene small = scene;
  small.width = std::max<uint32_t>(1, scene.width / 2);
  small.height = std::max<uint32_t>(1, scene.height / 2);
  return small;
}

// The picture of `scene` from `renderer` as 8-bit sRGB RGBA through the frame API
// (gl_target.h): the renderer draws into `target` (rgba8, resized to the view), whose
// present pass encodes sRGB on the GPU, and only those 4 bytes a pixel come back — no
// AOVs, no float beauty. The rows stay bottom-up as GL's (the view shows them flipped).
// The render thread has its own context (a slow software frame never stalls the UI), so
// the bytes cross to the window's context as an upload rather than a shared texture.
Picture present(GlRenderer& renderer, const Scene& scene, std::unique_ptr<GlTextureTarget>& target) {
  const auto start = Clock::now();
  if (!target) target = std::make_unique<GlTextureTarget>(scene.width, scene.height, GlTextureTarget::Format::rgba8);
  else target->resize(scene.width, scene.height);
  renderer.draw(scene, target->target());
  Picture p;
  p.width = scene.width;
  p.height = scene.height;
  p.rgba.resize(static_cast<size_t>(p.width) * p.height * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(target->texture(), 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(p.rgba.size()),
                    p.rgba.data());
  p.passes = describe_frame(renderer.wait_for_frame());
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
  // Set by set_plants while a renderer is being built: newer plants make the skinning in
  // flight stop (GlRenderer checks it every 1024 chains) instead of finishing for nothing.
  std::atomic<bool> cancel_build{false};
  std::function<void()> on_picture;
  double preview_above_ms = 1000;  // see the constructor
  uint64_t previews = 0;         // made so far
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
  std::function<void(GlRenderer*, const RenderOptions&, bool, bool)> task;  // an export, run and waited for
  std::shared_ptr<const ConeSet> cones;  // newer fog cones, not yet taken
  std::shared_ptr<const std::vector<SunDepthMap>> maps;  // newer sun maps, not yet taken
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

GlViewport::GlViewport(std::function<void()> on_picture, double preview_above_ms)
    : shared_(std::make_unique<Shared>()) {
  shared_->on_picture = std::move(on_picture);
  shared_->preview_above_ms = preview_above_ms;
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
  // Every renderer of this thread's context shares its programs: a regrown plant's
  // renderer draws its first picture without recompiling (gl_program.h).
  auto programs = std::make_shared<GlProgramCache>();
  std::unique_ptr<GlRenderer> renderer;
  std::unique_ptr<GlTextureTarget> target;  // the picture's, on this thread's context
  double last_full_ms = 0;                   // the last full picture's time (preview_of)
  bool unshown_plants = false;               // the renderer's plants have no full picture yet
  RenderOptions options;
  uint64_t version = 0;
  std::shared_ptr<const ConeSet> cones;  // the last fog cones given: every renderer draws them
  bool cones_applied = false;            // uploaded into the current renderer
  std::shared_ptr<const std::vector<SunDepthMap>> maps;  // the same for the sun maps
  bool maps_applied = false;
  for (;;) {
    std::optional<Shared::Plants> plants;
    std::optional<Shared::View> view;
    std::function<void(GlRenderer*, const RenderOptions&, bool, bool)> task;
    {
      std::unique_lock<std::mutex> lock(sh.mutex);
      sh.wake.wait(lock, [&] { return sh.quit || sh.plants || sh.view || sh.task || sh.cones || sh.maps; });
      if (sh.quit) break;
      if (sh.maps) {
        maps = std::move(sh.maps);
        sh.maps.reset();
        maps_applied = false;
      }
      if (sh.cones) {
        cones = std::move(sh.cones);
        sh.cones.reset();
        cones_applied = false;
      }
      plants = std::move(sh.plants);
      sh.plants.reset();
      sh.cancel_build = false;
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
    bool build_cancelled = false;
    if (plants) {
      const auto start = Clock::now();
      renderer.reset();
      options = plants->options;
      options.progress = Progress(&sh.cancel_build);
      version = plants->version;
      bool any = false;
      for (const ScenePlant& p : plants->scene.plants)
        any |= p.skeleton && (p.skeleton->segment_count() > 0 || !p.skeleton->leaves.empty());
      if (!any) error = "the plant has no segments or leaves";
      else if (auto why = gl_unsupported(plants->scene, options)) error = *why;
      else {
        try {
          renderer = std::make_unique<GlRenderer>(plants->scene, options, programs);
        } catch (const GlCancelled&) {
          build_cancelled = true;  // newer plants wait in the mailbox
        } catch (const std::exception& e) {
          error = e.what();
        }
      }
      upload_ms = ms_since(start);
      unshown_plants = renderer != nullptr;
      cones_applied = false;
      maps_applied = false;
    }
    if (renderer && cones && !cones_applied) {
      renderer->set_fog_cones(*cones);
      cones_applied = true;
    }
    if (renderer && maps && !maps_applied && !maps->empty()) {
      renderer->set_fog_maps(*maps);
      maps_applied = true;
    }
    if (task) task(renderer.get(), options, cones_applied, maps_applied);
    // Hands a picture (or the error) to the UI thread; `last`: the render thread is done.
    auto publish = [&](std::optional<Picture> picture, bool last) {
      const bool any = picture || !error.empty();
      {
        std::lock_guard<std::mutex> lock(sh.mutex);
        if (last) sh.working = false;
        if (plants && !build_cancelled) {
          sh.built_version = version;
          sh.error = error;
          sh.frusta = renderer ? renderer->frusta() : 0;
          sh.upload_ms = upload_ms;
        } else if (!error.empty()) {
          sh.error = error;
        }
        if (picture) sh.picture = std::move(picture);
      }
      if (any && sh.on_picture) sh.on_picture();
    };
    std::optional<Picture> picture;
    if (view && renderer && view->version == version) {
      try {
        // New plants on a slow renderer: a quick preview first, so the edit shows at once;
        // the full picture follows unless newer plants are already waiting.
        bool newer_waiting = false;
        if (unshown_plants && last_full_ms > sh.preview_above_ms) {
          renderer->set_shadow_map_texels(kPreviewShadowTexels);
          Picture quick = present(*renderer, preview_of(drawable(view->scene, cones_applied, maps_applied)), target);
          renderer->set_shadow_map_texels(0);
          quick.plants_version = version;
          quick.preview = true;
          publish(std::move(quick), false);
          std::lock_guard<std::mutex> lock(sh.mutex);
          ++sh.previews;
          newer_waiting = sh.plants.has_value();
        }
        if (!newer_waiting) {
          picture = present(*renderer, drawable(view->scene, cones_applied, maps_applied), target);
          picture->plants_version = version;
          last_full_ms = picture->render_ms;
          unshown_plants = false;
        }
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    publish(std::move(picture), true);
  }
  target.reset();
  renderer.reset();
  programs.reset();  // while the context is current
}

void GlViewport::set_plants(const Scene& scene, const RenderOptions& options) {
  ++plants_version_;
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->plants = Shared::Plants{scene, options, plants_version_};
    if (shared_->working) shared_->cancel_build = true;
  }
  shared_->wake.notify_all();
}

void GlViewport::set_fog_maps(std::shared_ptr<const std::vector<SunDepthMap>> maps) {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->maps = std::move(maps);
  }
  shared_->wake.notify_all();
  asked_view_.clear();  // the next image() asks for the picture with them
}

void GlViewport::set_fog_cones(std::shared_ptr<const ConeSet> cones) {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->cones = std::move(cones);
  }
  shared_->wake.notify_all();
  asked_view_.clear();  // the next image() asks for the picture with them
}

ImTextureID GlViewport::make_texture(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) {
  if (width == 0 || height == 0 || rgba.size() != size_t{width} * height * 4) return nullptr;
  GLuint texture = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &texture);
  glTextureStorage2D(texture, 1, GL_RGBA8, static_cast<GLsizei>(width), static_cast<GLsizei>(height));
  glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(texture, 0, 0, 0, static_cast<GLsizei>(width), static_cast<GLsizei>(height), GL_RGBA,
                      GL_UNSIGNED_BYTE, rgba.data());
  return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture));
}

void GlViewport::free_texture(ImTextureID texture) {
  const GLuint name = static_cast<GLuint>(reinterpret_cast<intptr_t>(texture));
  if (name) glDeleteTextures(1, &name);
}

bool GlViewport::busy() const {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  return shared_->working || shared_->plants || shared_->view || shared_->picture || shared_->cones || shared_->maps;
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
    stats_.previews = shared_->previews;
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
  stats_.preview = p->preview;
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
    // New plants that cannot be drawn (no segments or leaves, an error): nothing newer will come.
    std::lock_guard<std::mutex> lock(shared_->mutex);
    if (shared_->built_version == plants_version_ && !shared_->error.empty() && !shared_->working && !shared_->view)
      current = true;
  }
  return ViewImage{reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture_)), true, texture_w_, texture_h_,
                   current};
}

std::optional<std::string> GlViewport::write_image(const Scene& scene, const RenderOptions& options,
                                                   const std::string& path) {
  // Run on the render thread (its renderer when it was built with these options) and wait.
  std::promise<std::optional<std::string>> done;
  auto result = done.get_future();
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->task = [&](GlRenderer* current, const RenderOptions& current_options, bool current_has_cones,
                        bool current_has_maps) {
      try {
        std::unique_ptr<GlRenderer> own;
        GlRenderer* r = current;
        if (!r || options.skin.knuckle_frusta != current_options.skin.knuckle_frusta ||
            options.geometry.relief != current_options.geometry.relief || options.spp != current_options.spp) {
          own = std::make_unique<GlRenderer>(scene, options);
          r = own.get();
        }
        RenderResult rendered =
            r->render(drawable(scene, r == current && current_has_cones, r == current && current_has_maps));
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
