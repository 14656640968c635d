// bench_metrics.h — what the error-against-time benchmarks (`sylva bench geometry`, CPU;
// `sylva bench gpu`, OpenGL) share, so that their errors are measured the same way: the
// converged reference, the image metrics, and a few argument and plot helpers.
//
// The reference (docs/benchmarks.md, "Error against run time"): the CPU engine's
// analytic frusta, relief-mapped with many uniform steps and bisection steps and exact v
// (RC+R 1024×24 by default), or RC itself when no plant of the scene has a height map
// (the scene asks for no relief then).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "app/bench/plot.h"
#include "core/cpu/render_cpu.h"

namespace sylva::cli {

// Whether any plant of `scene` has a relief height map.
bool scene_has_relief(const Scene& scene);

// The geometries the benchmarks' methods draw:
GeometryOptions frusta_geometry();                          // RC: the frusta, relief left out
GeometryOptions relief_geometry(int steps, int bisection);  // RC+R: uniform and bisection
                                                            // steps, v interpolated (paper)
GeometryOptions mesh_geometry(int level, bool displace);    // GS m, or GS+R m if displaced

// The reference geometry: RC+R with `steps` uniform and `bisection` bisection steps and
// exact v when `relief`, else RC.
GeometryOptions reference_geometry(bool relief, int steps, int bisection);

// "RC+R 1024x24 exact v" or "RC (the scene has no height map)".
std::string describe_reference(bool relief, int steps, int bisection);

// A CPU render with one sample per pixel through its centre and the depth AOV, and what
// it cost: time_s is the trace + shade pass (wall), build_s every pass before it (skin,
// tessellate, textures, acceleration structure).
struct TimedRender {
  RenderResult result;
  double build_s = 0, time_s = 0;
};
TimedRender render_cpu_timed(const Scene& scene, const GeometryOptions& geometry, unsigned threads);

// Errors of `image` against `reference` (same size, both with depth): depth (Z, metres)
// RMSE and maximum over pixels where both hit a plant, the fraction of pixels where
// exactly one hits, colour (linear RGB beauty) RMSE and maximum absolute difference over
// all pixels and channels.
struct ImageErrors {
  double depth_rmse_m = 0, depth_max_m = 0, hit_mismatch = 0;
  double colour_rmse = 0, colour_max = 0;
};
ImageErrors compare_images(const RenderImage& reference, const RenderImage& image);

// INPUT as given when it is a render input (is_render_input), else a preset's scene or
// grammar by name: presets/scenes/NAME.scene.json, then presets/NAME.lsys. UsageError when
// it is neither.
std::string resolve_bench_input(const std::string& input);

// The file name of `path` without its folder and input extension (.scene.json,
// .skel.json, .lsys, .glb, .gltf): "presets/scenes/pine.scene.json" -> "pine".
std::string input_stem(const std::string& path);

// The series of `series` named `name`, appended (with the next plot colour) if new.
PlotSeries& series_named(std::vector<PlotSeries>& series, const std::string& name);

}  // namespace sylva::cli
