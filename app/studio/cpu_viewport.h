// cpu_viewport.h — the studio's viewport where OpenGL is a software rasteriser (Mesa's
// llvmpipe): the CPU ray caster (core/cpu/render_cpu.h), which is several times faster
// than the GL one there (docs/benchmarks.md), drawn progressively.
//
// Pictures are made on a render thread of its own (the CPU renderer's worker threads run
// under it at a lower priority, nice +5, so the window's frames keep their core); the UI
// thread posts what to draw (latest wins) and uploads each finished picture into the
// window's texture. Each view is drawn coarse to fine — a quarter of the pixels a side,
// then half, then full at one sample a pixel, then, when that took under
// `refine_below_ms`, full at 4 samples (antialiased) — each shown as soon as it is done;
// a newer view or newer plants stop the one in flight between tiles (render_cpu's cancel
// flag) and start over. As GlViewport: image() asks for a picture only when the camera,
// sun, sky, ground, fog or size changed or new plants arrived (a cached picture
// otherwise); the fog uses the cone worker's cones or sun maps once they arrive (before
// them the CPU builds its own for each picture).
// Preconditions: construct, call and destroy on the UI thread with the window's context
// current (the texture lives there).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/studio/view_picture.h"
#include "app/studio/viewport.h"

namespace sylva::studio {

class CpuViewport : public PictureViewport {
 public:
  // `on_picture` is called on the render thread when a picture is ready (the window loop
  // wakes itself with it); `why` says why the CPU draws (shown as the renderer's name).
  explicit CpuViewport(std::function<void()> on_picture = {}, std::string why = {},
                       double refine_below_ms = 1500);
  ~CpuViewport() override;
  CpuViewport(const CpuViewport&) = delete;
  CpuViewport& operator=(const CpuViewport&) = delete;

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
