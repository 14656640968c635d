// bench_metrics.cpp — see bench_metrics.h.
#include "app/bench/bench_metrics.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "app/front/args.h"
#include "app/front/render_input.h"

namespace sylva::cli {

bool scene_has_relief(const Scene& scene) {
  for (const ScenePlant& p : scene.plants)
    if (p.bark.height_texture) return true;
  return false;
}

std::string resolve_bench_input(const std::string& input) {
  if (is_render_input(input)) return input;
  const std::string presets = SYLVA_PRESETS_DIR;
  for (const std::string& candidate : {presets + "/scenes/" + input + ".scene.json", presets + "/" + input + ".lsys"})
    if (std::filesystem::exists(candidate)) return candidate;
  throw UsageError{"INPUT '" + input +
                   "' is neither a .lsys, .skel.json, .scene.json, .glb or .gltf file nor a preset name"};
}

GeometryOptions frusta_geometry() {
  GeometryOptions g;
  g.kind = GeometryKind::frusta;
  g.relief = false;
  return g;
}

GeometryOptions relief_geometry(int steps, int bisection) {
  GeometryOptions g;
  g.kind = GeometryKind::frusta;
  g.relief = true;
  g.relief_options.linear_steps = steps;
  g.relief_options.bisection_steps = bisection;
  g.relief_options.exact_v = false;
  return g;
}

GeometryOptions mesh_geometry(int level, bool displace) {
  GeometryOptions g;
  g.kind = GeometryKind::mesh;
  g.mesh_level = level;
  g.displace = displace;
  return g;
}

GeometryOptions reference_geometry(bool relief, int steps, int bisection) {
  if (!relief) return frusta_geometry();
  GeometryOptions reference = relief_geometry(steps, bisection);
  reference.relief_options.exact_v = true;
  return reference;
}

std::string describe_reference(bool relief, int steps, int bisection) {
  return relief ? "RC+R " + std::to_string(steps) + "x" + std::to_string(bisection) + " exact v"
                : std::string("RC (the scene has no height map)");
}

TimedRender render_cpu_timed(const Scene& scene, const GeometryOptions& geometry, unsigned threads) {
  RenderOptions options;
  options.aovs = kAovDepth;
  options.threads = threads;
  options.geometry = geometry;
  TimedRender t{render_cpu(scene, options)};
  bool traced = false;
  for (const RenderPass& p : t.result.passes) {
    if (p.name.rfind("trace + shade", 0) == 0) t.time_s = p.seconds, traced = true;
    else if (!traced) t.build_s += p.seconds;
  }
  return t;
}

ImageErrors compare_images(const RenderImage& reference, const RenderImage& image) {
  ImageErrors e;
  double depth_sq = 0, colour_sq = 0;
  size_t both = 0, mismatch = 0;
  const size_t pixels = static_cast<size_t>(reference.width) * reference.height;
  for (size_t i = 0; i < pixels; ++i) {
    const bool a = std::isfinite(reference.depth[i]), b = std::isfinite(image.depth[i]);
    if (a && b) {
      const double d = static_cast<double>(image.depth[i]) - reference.depth[i];
      depth_sq += d * d;
      e.depth_max_m = std::max(e.depth_max_m, std::abs(d));
      ++both;
    } else if (a != b) {
      ++mismatch;
    }
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(image.beauty[i * 4 + c]) - reference.beauty[i * 4 + c];
      colour_sq += d * d;
      e.colour_max = std::max(e.colour_max, std::abs(d));
    }
  }
  e.depth_rmse_m = both ? std::sqrt(depth_sq / both) : 0;
  e.hit_mismatch = pixels ? static_cast<double>(mismatch) / pixels : 0;
  e.colour_rmse = pixels ? std::sqrt(colour_sq / (3.0 * pixels)) : 0;
  return e;
}

std::string input_stem(const std::string& path) {
  std::string name = path.substr(path.find_last_of('/') + 1);
  for (const std::string e : {".scene.json", ".skel.json", ".lsys", ".glb", ".gltf"}) {
    if (name.size() > e.size() && name.ends_with(e))
      return name.substr(0, name.size() - e.size());
  }
  return name;
}

PlotSeries& series_named(std::vector<PlotSeries>& series, const std::string& name) {
  for (PlotSeries& s : series)
    if (s.name == name) return s;
  series.push_back({name, plot_colour(series.size()), {}, true});
  return series.back();
}

}  // namespace sylva::cli
