// python_render.cpp — sylva.render: the CPU reference ray caster (core/render_cpu.h)
// on one skeleton in its default scene (docs/spec/scene.md: sun, sky, ground, framing camera).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <future>
#include <optional>
#include <string>

#include "app/python/sylva_python.h"
#include "core/cpu/render_cpu.h"
#include "core/util/limits.h"
#include "core/scene/scene.h"

namespace py = pybind11;
using namespace pybind11::literals;

namespace sylva::python {

namespace {

py::array_t<float> python_render(const Skeleton& skeleton, uint32_t width, uint32_t height, const std::string& backend,
                                 uint32_t spp, unsigned threads, const std::string& skin) {
  const SkinStyle style = skin_style_argument(skin);
  if (backend != "auto" && backend != "cpu") {
    if (backend == "gpu") throw py::value_error("backend 'gpu': the GPU renderer is not available from Python yet; use 'cpu'");
    throw py::value_error("backend must be 'auto' or 'cpu', got '" + backend + "'");
  }
  if (width == 0 || height == 0) throw py::value_error("width and height must be > 0");
  if (spp == 0) throw py::value_error("spp must be >= 1");
  // The documented limits (docs/limits.md), checked before anything is allocated.
  if (auto problem = image_size_problem(width, height, spp)) throw py::value_error(*problem);
  if (auto problem = plant_extent_problem(skeleton)) throw py::value_error("render: " + *problem);
  // The render runs on its own thread while this one, the GIL released, runs Python's
  // signal handlers every 50 ms (only the main thread can, and the render's progress comes
  // from its workers): Ctrl-C cancels the render between tiles and raises KeyboardInterrupt.
  std::atomic<bool> cancel{false};
  std::optional<py::error_already_set> interrupted;
  std::future<RenderResult> rendering;
  {
    py::gil_scoped_release release;
    rendering = std::async(std::launch::async, [&] {
      Scene scene = default_scene_for(skeleton, width, height);
      override_skin(scene, style);
      RenderOptions options;
      options.spp = spp;
      options.threads = threads;
      options.progress = Progress(&cancel);
      return render_cpu(scene, options);
    });
    while (rendering.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
      if (interrupted) continue;  // cancelled: waiting for the tiles in flight
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) {
        interrupted.emplace();  // takes the pending exception
        cancel.store(true);
      }
    }
  }
  RenderResult result = rendering.get();  // rethrows what the render threw
  if (interrupted) throw std::move(*interrupted);
  const RenderImage& image = result.image;
  if (image.beauty.size() != static_cast<size_t>(width) * height * 4)
    throw std::runtime_error("render: the renderer returned an image of the wrong size");
  py::array_t<float> pixels({static_cast<py::ssize_t>(height), static_cast<py::ssize_t>(width), py::ssize_t{4}});
  std::memcpy(pixels.mutable_data(), image.beauty.data(), image.beauty.size() * sizeof(float));
  return pixels;
}

}  // namespace

void bind_render(py::module_& m) {
  m.def("render", &python_render, "skeleton"_a, py::kw_only(), "width"_a = 640u, "height"_a = 480u,
        "backend"_a = "auto", "spp"_a = kDefaultRenderSpp, "threads"_a = 0u, "skin"_a = "smooth",
        R"doc(Renders a Skeleton with the CPU ray caster and returns an (H, W, 4) float32 array.

The plant stands in its default scene (as `sylva render plant.skel.json`): sun, sky,
ground at its lowest point and a camera framing it. Pixels are linear RGBA, row 0 at
the top, alpha 1 (the sky is part of the picture); convert to sRGB for display.
Keyword-only: width, height (pixels), backend ('auto' or 'cpu'; the GPU renderer is
not exposed yet), spp (stratified samples per pixel; default 8, as `sylva render`), threads (0: every core),
skin ("smooth", or "paper": Bhagvat et al. 2009's mitred chains, as `--skin`). The GIL
is released while rendering; the image is the same for every thread count.)doc");
}

}  // namespace sylva::python
