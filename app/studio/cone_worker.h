// cone_worker.h — the studio's fog cone thread: sun photons and shadow cones
// (core/cpu/photons.h build_sun_cones, Hougs and Day 2001 sec. 3) — or for fog mode map the
// sun maps (core/cpu/sun_maps.h, app/front/render.h sun_maps_for) — for the plants and sun on screen,
// built off the UI thread, because they are viewpoint independent but cost seconds on a
// dense canopy (docs/benchmarks.md). The UI submits whenever the plants, the sun, the
// photon count or the cone kind changed — never for a camera move — and hands each result
// to the viewport (Viewport::set_fog_cones), which keeps drawing the last cones until it
// arrives (docs/gl-fog.md, "The studio").
//
// Mailbox of one, the latest (as GrowWorker): submit() replaces a queued request and
// cancels the running one (the photon tracer's cancel flag); poll() hands out only the
// newest request's cones. Construct, submit, poll and destroy on one thread (the UI's).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "core/light/sun_map.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"

namespace sylva {
class ConeSet;
}

namespace sylva::studio {

struct ConeRequest {
  Scene scene;         // the plants with their skeletons, the sun, the fog
  SkinOptions skin;    // how the plants are skinned (the photons hit those frusta)
  FogMode mode = FogMode::fast;  // medium or fast: what the automatic parameters weigh; map: the sun maps
  uint64_t photons = 0;
};

struct ConeResult {
  uint64_t generation = 0;
  std::shared_ptr<const ConeSet> cones;  // empty set: a sun below the horizon
  std::shared_ptr<const std::vector<SunDepthMap>> maps;  // mode map's instead (none: a sun below the horizon)
  double seconds = 0;                    // photons + cones (or maps), on the worker
};

class ConeWorker {
 public:
  ConeWorker();
  ~ConeWorker();  // cancels and joins
  ConeWorker(const ConeWorker&) = delete;
  ConeWorker& operator=(const ConeWorker&) = delete;

  uint64_t submit(ConeRequest request);  // the latest; returns its generation
  std::optional<ConeResult> poll();      // the newest generation's cones, once
  bool busy() const;                     // queued or running
  uint64_t builds_started() const;       // requests the worker began (tests count them)
  uint64_t builds_finished() const;      // ... that ran to the end
  bool wait_idle(double timeout_s) const;  // tests

 private:
  void run();

  mutable std::mutex mutex_;
  mutable std::condition_variable wake_, idle_;
  std::optional<ConeRequest> pending_;
  uint64_t pending_generation_ = 0;
  bool running_ = false, quit_ = false;
  std::optional<ConeResult> done_;
  uint64_t started_ = 0, finished_ = 0;
  std::atomic<uint64_t> generation_{0};
  std::atomic<bool> cancel_{false};
  std::thread thread_;
};

}  // namespace sylva::studio
