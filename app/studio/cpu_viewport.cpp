// cpu_viewport.cpp — see cpu_viewport.h.
#include "app/studio/cpu_viewport.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <iterator>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>

#include "core/cpu/render_cpu.h"
#include "core/scene/fog_integrator.h"
#include "core/scene/render_output.h"

namespace sylva::studio {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// One step of the progression: pixels a side divided by `divisor`, `spp` samples a pixel.
struct Step {
  uint32_t divisor;
  uint32_t spp;
};
constexpr Step kSteps[] = {{4, 1}, {2, 1}, {1, 1}, {1, 4}};

// `options` with the fog's cones and sun maps the cone worker built (when there are any).
RenderOptions with_fog(RenderOptions options, const ConeSetFogSource* cones,
                       const std::shared_ptr<const std::vector<SunDepthMap>>& maps) {
  if (cones) options.fog.cones = cones;
  if (maps && !maps->empty()) options.fog.maps = *maps;
  return options;
}

}  // namespace

// The mailbox (view_picture.h) and what only the CPU render thread needs.
struct CpuViewport::Shared : PictureMailbox {
  std::atomic<bool> cancel{false};  // a newer view or plants: stop the picture in flight
  double refine_below_ms = 1500;
};

CpuViewport::CpuViewport(std::function<void()> on_picture, std::string why, double refine_below_ms)
    : PictureViewport(std::make_unique<Shared>(), /*flip_v=*/false), shared_(static_cast<Shared*>(&mailbox())) {
  shared_->on_picture = std::move(on_picture);
  shared_->refine_below_ms = refine_below_ms;
  stats_.renderer = "CPU ray caster" + (why.empty() ? std::string() : " (" + why + ")");
  thread_ = std::thread([this] { run(); });
}

CpuViewport::~CpuViewport() {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->quit = true;
  }
  shared_->cancel = true;
  shared_->wake.notify_all();
  if (thread_.joinable()) thread_.join();
}

void CpuViewport::run() {
  Shared& sh = *shared_;
  // Below the UI thread: render_cpu's workers inherit this thread's niceness (Linux).
  setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 5);
  std::optional<PictureMailbox::Plants> plants;  // the plants drawn
  for (;;) {
    std::optional<PictureMailbox::View> view;
    std::shared_ptr<const ConeSet> cones;
    std::shared_ptr<const std::vector<SunDepthMap>> maps;
    bool new_plants = false;
    {
      std::unique_lock<std::mutex> lock(sh.mutex);
      sh.wake.wait(lock, [&] { return sh.quit || sh.plants || sh.view; });
      if (sh.quit) break;
      if (sh.plants) {
        plants = std::move(sh.plants);
        sh.plants.reset();
        new_plants = true;
      }
      view = std::move(sh.view);
      sh.view.reset();
      cones = sh.cones;
      maps = sh.maps;
      sh.cancel = false;
      sh.working = true;
    }
    std::string error;
    if (plants) {
      bool any = false;
      for (const ScenePlant& p : plants->scene.plants)
        any |= p.skeleton && (p.skeleton->segment_count() > 0 || !p.skeleton->leaves.empty());
      if (!any) error = "the plant has no segments or leaves";
    }
    auto publish = [&](std::optional<ViewPicture> picture, bool last, uint64_t frusta) {
      const bool any = picture || !error.empty();
      {
        std::lock_guard<std::mutex> lock(sh.mutex);
        if (last) sh.working = false;
        if (plants && (new_plants || picture || !error.empty())) {  // an error of a new view too
          sh.built_version = plants->version;
          sh.error = error;
          if (frusta) sh.frusta = frusta;
        }
        if (picture) {
          if (picture->preview) ++sh.previews;
          sh.picture = std::move(picture);
        }
      }
      if (any && sh.on_picture) sh.on_picture();
    };
    if (!view || !plants || view->version != plants->version || !error.empty()) {
      publish(std::nullopt, true, 0);
      continue;
    }
    // Scene plants the view draws: the plants' skeletons under the view's camera, sun...
    Scene scene = view->scene;
    scene.plants = plants->scene.plants;
    std::optional<ConeSetFogSource> cone_source;
    if (cones) cone_source.emplace(*cones);
    RenderOptions options = with_fog(plants->options, cone_source ? &*cone_source : nullptr, maps);
    options.progress = Progress(&sh.cancel);
    options.aovs = 0;
    double full_ms = 0;
    for (const Step& step : kSteps) {
      if (step.spp > 1 && !(full_ms < sh.refine_below_ms)) break;  // too slow to refine now
      Scene s = scene;
      s.width = std::max<uint32_t>(1, scene.width / step.divisor);
      s.height = std::max<uint32_t>(1, scene.height / step.divisor);
      RenderOptions o = options;
      o.spp = step.spp;
      const auto start = Clock::now();
      RenderResult r;
      try {
        r = render_cpu(s, o);
      } catch (const std::exception& e) {
        error = e.what();
        break;
      }
      if (r.cancelled) break;
      ViewPicture p;
      p.width = r.image.width;
      p.height = r.image.height;
      p.rgba = srgb8_rgba(r.image);
      p.plants_version = plants->version;
      p.passes = std::move(r.passes);
      p.render_ms = ms_since(start);
      if (step.divisor == 1 && step.spp == 1) full_ms = p.render_ms;
      // A finer step follows: any but the last, and the refinement only when affordable.
      const Step* next = &step + 1;
      p.preview = next != std::end(kSteps) && (next->spp == 1 || full_ms < sh.refine_below_ms);
      publish(std::move(p), false, r.frusta);
      std::lock_guard<std::mutex> lock(sh.mutex);
      if (sh.plants || sh.view || sh.quit) break;  // newer work waits: start over
    }
    publish(std::nullopt, true, 0);
  }
}

void CpuViewport::set_plants(const Scene& scene, const RenderOptions& options) { post_plants(scene, options); }

void CpuViewport::interrupt(bool) { shared_->cancel = true; }

void CpuViewport::set_fog_cones(std::shared_ptr<const ConeSet> cones) {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  shared_->cones = std::move(cones);
  ask_again();  // the next image() asks for the picture with them
}

void CpuViewport::set_fog_maps(std::shared_ptr<const std::vector<SunDepthMap>> maps) {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  shared_->maps = std::move(maps);
  ask_again();
}

bool CpuViewport::busy() const {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  return shared_->working || shared_->plants || shared_->view || shared_->picture;
}

std::optional<std::string> CpuViewport::write_image(const Scene& scene, const RenderOptions& options,
                                                    const std::string& path) {
  // On the UI thread, as `sylva render --backend cpu` would (the export waits for it).
  std::shared_ptr<const ConeSet> cones;
  std::shared_ptr<const std::vector<SunDepthMap>> maps;
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    cones = shared_->cones;
    maps = shared_->maps;
  }
  try {
    std::optional<ConeSetFogSource> cone_source;
    if (cones) cone_source.emplace(*cones);
    const RenderResult rendered = render_cpu(scene, with_fog(options, cone_source ? &*cone_source : nullptr, maps));
    Expected<std::vector<std::string>> written = write_render(path, rendered.image);
    if (!written) {
      std::string error = written.error().format();
      error.pop_back();  // the one line, without format()'s newline
      return error;
    }
    return std::nullopt;
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
}

}  // namespace sylva::studio
