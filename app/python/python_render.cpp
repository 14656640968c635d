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
#include <vector>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <glm/vec3.hpp>

#include "app/front/light.h"
#include "app/python/sylva_python.h"
#include "core/cpu/render_cpu.h"
#include "core/util/limits.h"
#include "core/scene/scene.h"
#include "core/scene/scene_json.h"
#include "core/scene/render_output.h"
#include "core/grow/grow.h"
#include "core/util/file_io.h"
#include "core/util/image_io.h"

namespace py = pybind11;
using namespace pybind11::literals;

namespace sylva::python {

namespace {

// A point or direction argument: three finite numbers.
glm::dvec3 vec3_argument(const py::handle& value, const char* name) {
  const std::vector<double> v = cast_argument<std::vector<double>>(value, name, "an (x, y, z) sequence of numbers");
  if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
    throw py::value_error(std::string(name) + " must be three finite numbers (x, y, z)");
  return {v[0], v[1], v[2]};
}

// The scene `plant` stands for: a Skeleton in its default scene, or a .scene.json file
// read and grown. *inputs gets the files it was made from (never overwritten by `output`).
Scene scene_of(const py::object& plant, std::optional<uint32_t> width, std::optional<uint32_t> height,
               std::vector<std::string>* inputs) {
  if (py::isinstance<Skeleton>(plant)) {
    const Skeleton& skeleton = plant.cast<const Skeleton&>();
    if (auto problem = plant_extent_problem(skeleton)) throw py::value_error("render: " + *problem);
    if (!skeleton.source.grammar.empty() && skeleton.source.grammar.front() != '<')
      inputs->push_back(skeleton.source.grammar);
    py::gil_scoped_release release;
    return default_scene_for(skeleton, width.value_or(640), height.value_or(480));
  }
  if (!py::isinstance<py::str>(plant) && !py::hasattr(plant, "__fspath__"))
    throw py::type_error("render takes a sylva.Skeleton or the path of a .scene.json scene, got " +
                         std::string(py::str(py::type::handle_of(plant).attr("__name__"))));
  const std::string path = path_string(plant.cast<std::filesystem::path>());
  if (!path.ends_with(".scene.json"))
    throw py::value_error("render: " + path + " is not a .scene.json scene (grow a grammar with sylva.Grammar, "
                          "read a skeleton with sylva.Skeleton.from_file)");
  Expected<Scene> read = read_scene_file(path);
  if (!read) {
    if (read.error().error_number != 0 || read.error().loc.line == 0) throw_file_error(read.error());
    throw py::value_error(chomp(read.error().format()));
  }
  Status grown;
  {
    py::gil_scoped_release release;
    grown = grow_scene_plants(*read, 50'000'000, {}, &cpu_light_oracle());
  }
  if (!grown) throw py::value_error(chomp(grown.error().format()));
  inputs->push_back(path);
  for (const ScenePlant& p : read->plants)
    if (!p.grammar.empty()) inputs->push_back(p.grammar);
  if (width) read->width = *width;
  if (height) read->height = *height;
  return std::move(*read);
}

py::array_t<float> python_render(const py::object& plant, std::optional<uint32_t> width,
                                 std::optional<uint32_t> height, const std::string& backend, uint32_t spp,
                                 unsigned threads, const std::optional<std::string>& skin, const py::object& eye,
                                 const py::object& target, std::optional<double> fov_y_deg, const py::object& sun,
                                 const py::object& output) {
  if (backend != "auto" && backend != "cpu") {
    if (backend == "gpu" || backend == "gl")
      throw py::value_error("backend '" + backend + "': the OpenGL renderer is not available from Python; use 'cpu' "
                            "('auto' is the CPU here, as on a machine whose only GL is a software rasteriser)");
    throw py::value_error("backend must be 'auto' or 'cpu', got '" + backend + "'");
  }
  if ((width && *width == 0) || (height && *height == 0)) throw py::value_error("width and height must be > 0");
  if (spp == 0) throw py::value_error("spp must be >= 1");
  const SkinStyle style = skin ? skin_style_argument(*skin) : SkinStyle::smooth;  // used with `skin` only
  std::vector<std::string> inputs;
  Scene scene = scene_of(plant, width, height, &inputs);
  // The documented limits (docs/limits.md), checked before anything is allocated.
  if (auto problem = image_size_problem(scene.width, scene.height, spp)) throw py::value_error(*problem);
  if (skin) override_skin(scene, style);
  if (!eye.is_none()) scene.camera.eye = vec3_argument(eye, "eye");
  if (!target.is_none()) scene.camera.target = vec3_argument(target, "target");
  if (fov_y_deg) scene.camera.fov_y_deg = *fov_y_deg;
  if (auto problem = camera_problem(scene.camera)) throw py::value_error("render: the camera: " + *problem);
  if (!sun.is_none()) {
    const glm::dvec3 d = vec3_argument(sun, "sun");
    if (d == glm::dvec3(0)) throw py::value_error("sun: the direction toward the sun must not be zero");
    scene.sun.direction = unit_sun_direction(d);
  }
  std::optional<std::string> out;
  if (!output.is_none()) {
    out = path_string(cast_argument<std::filesystem::path>(output, "output", "a path"));
    if (Status allowed = check_not_an_input(*out, inputs); !allowed) throw_file_error(allowed.error());
    if (auto problem = image_format_size_problem(*out, scene.width, scene.height))
      throw py::value_error(*out + ": " + *problem);
  }
  // The render runs on its own thread while this one, the GIL released, runs Python's
  // signal handlers every 50 ms (only the main thread can, and the render's progress comes
  // from its workers): Ctrl-C cancels the render between tiles and raises KeyboardInterrupt.
  std::atomic<bool> cancel{false};
  std::optional<py::error_already_set> interrupted;
  std::future<RenderResult> rendering;
  {
    py::gil_scoped_release release;
    rendering = std::async(std::launch::async, [&] {
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
  if (image.beauty.size() != static_cast<size_t>(scene.width) * scene.height * 4)
    throw std::runtime_error("render: the renderer returned an image of the wrong size");
  if (out) {
    std::optional<Diagnostic> failed;
    {
      py::gil_scoped_release release;
      Expected<std::vector<std::string>> written = write_render(*out, image);
      if (!written) failed = written.error();
    }
    if (failed) throw_file_error(*failed);
  }
  py::array_t<float> pixels(
      {static_cast<py::ssize_t>(scene.height), static_cast<py::ssize_t>(scene.width), py::ssize_t{4}});
  std::memcpy(pixels.mutable_data(), image.beauty.data(), image.beauty.size() * sizeof(float));
  return pixels;
}

}  // namespace

void bind_render(py::module_& m) {
  m.def("render", &python_render, "plant"_a, py::kw_only(), "width"_a = py::none(), "height"_a = py::none(),
        "backend"_a = "auto", "spp"_a = kDefaultRenderSpp, "threads"_a = 0u, "skin"_a = py::none(),
        "eye"_a = py::none(), "target"_a = py::none(), "fov_y_deg"_a = py::none(), "sun"_a = py::none(),
        "output"_a = py::none(),
        R"doc(Renders a plant or a scene with the CPU ray caster and returns an (H, W, 4) float32 array.

plant: a Skeleton, which stands in its default scene (as `sylva render plant.skel.json`:
sun, sky, ground at its lowest point, a camera framing it, 640 x 480), or the path of a
.scene.json scene, read and grown (its image size, camera, sun, fog, materials).
Pixels are linear RGBA, row 0 at the top, alpha 1 (the sky is part of the picture);
convert to sRGB for display. Keyword-only:
  width, height  pixels (default: the scene's, or 640 x 480 for a Skeleton)
  backend        'auto' or 'cpu' (the OpenGL renderer is not available from Python)
  spp            stratified samples per pixel (default 8, as `sylva render`)
  threads        0: every core; the image is the same for every thread count
  skin           "smooth" or "paper" for every plant (default: the scene's; `--skin`)
  eye, target    the camera's eye and the point it looks at, (x, y, z) metres, Y up
  fov_y_deg      its full vertical field of view, degrees (`--eye`, `--target`, `--fov`)
  sun            the direction toward the sun, (x, y, z), need not be unit (`--sun`)
  output         also write the image there, atomically, as `sylva render -o` does (PNG,
                 EXR with AOV channels, any format OpenImageIO writes); never onto the
                 scene or a grammar it grew from
Bad values raise ValueError or TypeError naming the argument, files OSError; Ctrl-C
raises KeyboardInterrupt. The GIL is released while rendering.)doc");
}

}  // namespace sylva::python
