// cone_worker.cpp — see cone_worker.h.
#include "app/studio/cone_worker.h"

#include <chrono>
#include <exception>

#include "app/front/render.h"
#include "core/cpu/photons.h"
#include "core/cpu/render_cpu.h"

namespace sylva::studio {

ConeWorker::ConeWorker() : thread_([this] { run(); }) {}

ConeWorker::~ConeWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    quit_ = true;
    cancel_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

uint64_t ConeWorker::submit(ConeRequest request) {
  const uint64_t generation = ++generation_;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = std::move(request);
    pending_generation_ = generation;
    if (running_) cancel_ = true;
  }
  wake_.notify_all();
  return generation;
}

std::optional<ConeResult> ConeWorker::poll() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<ConeResult> out = std::move(done_);
  done_.reset();
  if (out && out->generation != generation_.load()) return std::nullopt;  // stale
  return out;
}

bool ConeWorker::busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return running_ || pending_.has_value();
}

uint64_t ConeWorker::builds_started() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return started_;
}

uint64_t ConeWorker::builds_finished() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return finished_;
}

bool ConeWorker::wait_idle(double timeout_s) const {
  std::unique_lock<std::mutex> lock(mutex_);
  return idle_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return !running_ && !pending_; });
}

void ConeWorker::run() {
  for (;;) {
    ConeRequest request;
    uint64_t generation = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return quit_ || pending_.has_value(); });
      if (quit_) return;
      request = std::move(*pending_);
      pending_.reset();
      generation = pending_generation_;
      running_ = true;
      cancel_ = false;
      ++started_;
    }
    ConeResult result;
    result.generation = generation;
    bool completed = false;
    const auto start = std::chrono::steady_clock::now();
    try {
      if (request.mode == FogMode::map) {
        RenderOptions options;
        options.skin = request.skin;
        options.fog.photons = request.photons;
        options.progress = Progress(&cancel_);
        SunMaps maps = sun_maps_for(request.scene, options, nullptr);
        if (!maps.cancelled) {
          result.maps = std::make_shared<const std::vector<SunDepthMap>>(std::move(maps.maps));
          completed = true;
        }
      } else {
        const SceneGeometry geometry = build_scene_geometry(request.scene, request.skin);
        std::unique_ptr<const SunCones> built = build_sun_cones(
            geometry, request.scene, sun_cone_options_for(request.mode, request.photons, std::nullopt, 0, &cancel_));
        if (!built->cancelled) {
          const ConeSet* set = &built->cones;
          const std::shared_ptr<const SunCones> owner(std::move(built));
          result.cones = std::shared_ptr<const ConeSet>(owner, set);  // keeps the whole SunCones
          completed = true;
        }
      }
    } catch (const std::exception&) {
      completed = false;  // the plants cannot be traced (none): no cones, the fog draws brute
    }
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      running_ = false;
      if (completed) {
        ++finished_;
        done_ = std::move(result);
      }
    }
    idle_.notify_all();
  }
}

}  // namespace sylva::studio
