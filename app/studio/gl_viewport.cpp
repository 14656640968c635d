// gl_viewport.cpp — see gl_viewport.h.
#include "app/studio/gl_viewport.h"

#include "app/studio/view_picture.h"

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

// The scene the renderer draws: a cone mode without cones yet (mode map without maps) is
// drawn brute (the same fog, slower) until the cone worker's first cones (maps) arrive.
Scene drawable(const Scene& scene, bool have_cones, bool have_maps) {
  if (!scene.fog || scene.fog->mode == FogMode::brute) return scene;
  if (gl_fog_walks_maps(scene.fog->mode) ? have_maps : have_cones) return scene;
  Scene s = scene;
  s.fog->mode = FogMode::brute;
  return s;
}

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
ViewPicture present(GlRenderer& renderer, const Scene& scene, std::unique_ptr<GlTextureTarget>& target) {
  const auto start = Clock::now();
  if (!target) target = std::make_unique<GlTextureTarget>(scene.width, scene.height, GlTextureTarget::Format::rgba8);
  else target->resize(scene.width, scene.height);
  renderer.draw(scene, target->target());
  ViewPicture p;
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

// The mailbox (view_picture.h) and what only the GL render thread needs.
struct GlViewport::Shared : PictureMailbox {
  // Set by set_plants while a renderer is being built: newer plants make the skinning in
  // flight stop (GlRenderer checks it every 1024 chains) instead of finishing for nothing.
  std::atomic<bool> cancel_build{false};
  double preview_above_ms = 1000;  // see the constructor
  std::function<void(GlRenderer*, const RenderOptions&, bool, bool)> task;  // an export, run and waited for
  std::string renderer_name;
  bool started = false;
  std::string start_error;
};

GlViewport::GlViewport(std::function<void()> on_picture, double preview_above_ms)
    : PictureViewport(std::make_unique<Shared>(), /*flip_v=*/true), shared_(static_cast<Shared*>(&mailbox())) {
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
    std::optional<PictureMailbox::Plants> plants;
    std::optional<PictureMailbox::View> view;
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
      options.geometry.cull = false;  // the camera moves: keep every crotch's fillet (gl_mesh.cpp)
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
    auto publish = [&](std::optional<ViewPicture> picture, bool last) {
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
    std::optional<ViewPicture> picture;
    if (view && renderer && view->version == version) {
      try {
        // New plants on a slow renderer: a quick preview first, so the edit shows at once;
        // the full picture follows unless newer plants are already waiting.
        bool newer_waiting = false;
        if (unshown_plants && last_full_ms > sh.preview_above_ms) {
          renderer->set_shadow_map_texels(kPreviewShadowTexels);
          ViewPicture quick = present(*renderer, preview_of(drawable(view->scene, cones_applied, maps_applied)), target);
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

void GlViewport::set_plants(const Scene& scene, const RenderOptions& options) { post_plants(scene, options); }

void GlViewport::interrupt(bool new_plants) {
  if (new_plants && shared_->working) shared_->cancel_build = true;
}

void GlViewport::set_fog_maps(std::shared_ptr<const std::vector<SunDepthMap>> maps) {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->maps = std::move(maps);
  }
  shared_->wake.notify_all();
  ask_again();  // the next image() asks for the picture with them
}

void GlViewport::set_fog_cones(std::shared_ptr<const ConeSet> cones) {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->cones = std::move(cones);
  }
  shared_->wake.notify_all();
  ask_again();  // the next image() asks for the picture with them
}

bool GlViewport::busy() const {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  return shared_->working || shared_->plants || shared_->view || shared_->picture || shared_->cones || shared_->maps;
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
  ask_again();  // the targets were resized: ask for the view again
  return result.get();
}

}  // namespace sylva::studio
