// bench_geometry.cpp — `sylva bench geometry INPUT`: error against run time of every way
// the CPU engine can stand for the plants (docs/benchmarks.md, "Error against run time").
//
// Methods, each a full render_cpu of the same scene, camera and pixel samples (one per
// pixel, through its centre, so differences are geometry, not sampling noise):
//   RC           the analytic frusta, relief left out;
//   RC+R s×b     the analytic frusta relief-mapped with s uniform steps and b bisection
//                steps (v interpolated, as the paper), s ∈ {8,16,32,64}, b ∈ {0,4,8};
//   GS m         the frusta tessellated at the paper's GS level m = 0..4 (16·4^m
//                triangles per segment), traced by Embree;
//   GS+R m       the same meshes displaced by the height map.
// The reference is RC+R with --reference-steps uniform steps, --reference-bisection
// bisection steps and exact v (or RC itself when the scene has no height map: then the
// relief rows are not run, the scene does not ask for relief).
//
// Errors against the reference: depth (Z: Euclidean distance from the eye, metres) RMSE
// and maximum over pixels where both hit a plant, the fraction of pixels where exactly
// one of them hits a plant, and colour (linear RGB beauty) RMSE and maximum absolute
// difference over all pixels and channels. Time: the wall time of the trace + shade pass
// (on --threads threads); build: the passes before it (skin, tessellate, textures,
// acceleration structure). Memory: what the traced geometry holds.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "app/bench/bench_metrics.h"
#include "app/bench/bench.h"
#include "app/front/render_input.h"
#include "core/util/file_io.h"
#include "app/bench/plot.h"
#include "core/cpu/render_cpu.h"
#include "core/util/parallel.h"

namespace sylva::cli {

namespace {

void print_help() {
  std::cout
      << "usage: sylva bench geometry INPUT [-n STEPS] [--seed S] [-D NAME=VALUE]...\n"
         "                                [--width W --height H] [--threads N] [--quick]\n"
         "                                [--csv FILE] [--plot FILE.png]\n"
         "                                [--reference-steps N] [--reference-bisection N]\n\n"
         "Error against run time of the CPU engine's geometries on INPUT (a scene, grammar or\n"
         "skeleton, as for `sylva render`): analytic frusta (RC), relief-mapped frusta (RC+R,\n"
         "steps {8,16,32,64} x bisection {0,4,8}), tessellated meshes (GS, m = 0..4) and\n"
         "displaced meshes (GS+R), each against a converged reference (RC+R with many steps\n"
         "and exact v). Relief rows run only for scenes whose plants have a height map.\n\n"
         "  --width W, --height H   image size (default 512x384)\n"
         "  --threads N             render threads (default: every core)\n"
         "  --quick                 fewer methods and a 256x192 image (for tests)\n"
         "  --csv FILE              the table as CSV (default INPUT-stem.geometry.csv)\n"
         "  --plot FILE             log-log error-vs-time PNG (default INPUT-stem.geometry.png)\n"
         "  --reference-steps N     uniform relief steps of the reference (default 1024)\n"
         "  --reference-bisection N bisection steps of the reference (default 24)\n";
}

struct Args {
  GrammarArgs grammar;
  std::optional<uint32_t> width, height;
  unsigned threads = 0;
  bool quick = false;
  std::string csv, plot;
  int reference_steps = 1024;
  int reference_bisection = 24;
};

Args parse_args(const std::vector<std::string>& args) {
  Args out;
  FlagTable table;
  table.leaves_others = true;  // INPUT and the grammar flags: parse_grammar_args's
  table.flags = {
      count_flag({"--width"}, out.width, 16384),
      count_flag({"--height"}, out.height, 16384),
      count_flag({"--threads"}, out.threads, 4096),
      set_flag({"--quick"}, out.quick),
      text_flag({"--csv"}, out.csv),
      text_flag({"--plot"}, out.plot),
      count_flag({"--reference-steps"}, out.reference_steps, 1 << 20),
      count_flag({"--reference-bisection"}, out.reference_bisection, 60),
  };
  const std::vector<std::string> rest = parse_flags(std::span(args).subspan(1), table);  // args[0] is "geometry"
  out.grammar = parse_grammar_args(rest);
  if (out.grammar.help) return out;
  if (!is_render_input(out.grammar.grammar))
    throw UsageError{"INPUT '" + out.grammar.grammar + "' must end in .lsys, .skel.json, .scene.json, .glb or .gltf"};
  const std::string stem = input_stem(out.grammar.grammar);
  if (out.csv.empty()) out.csv = stem + ".geometry.csv";
  if (out.plot.empty()) out.plot = stem + ".geometry.png";
  return out;
}

struct Method {
  std::string family;  // RC, RC+R, GS, GS+R
  std::string name;    // e.g. "RC+R 32x4"
  GeometryOptions geometry;
  int steps = 0, bisection = 0, level = -1;
};

struct Row {
  Method method;
  double build_s = 0, time_s = 0;
  ImageErrors errors{};
  uint64_t memory = 0;
};

std::vector<Method> methods_for(bool relief, bool quick) {
  std::vector<Method> m;
  m.push_back({"RC", "RC", frusta_geometry()});
  if (relief) {
    const std::vector<int> steps = quick ? std::vector<int>{8, 32} : std::vector<int>{8, 16, 32, 64};
    const std::vector<int> bisections = quick ? std::vector<int>{0, 8} : std::vector<int>{0, 4, 8};
    for (int b : bisections)
      for (int s : steps)
        m.push_back({"RC+R", "RC+R " + std::to_string(s) + "x" + std::to_string(b), relief_geometry(s, b), s, b});
  }
  const int max_level = quick ? 2 : 4;
  for (int displaced = 0; displaced <= (relief ? 1 : 0); ++displaced)
    for (int level = 0; level <= max_level; ++level) {
      const std::string family = displaced ? "GS+R" : "GS";
      m.push_back({family, family + " m=" + std::to_string(level), mesh_geometry(level, displaced != 0), 0, 0, level});
    }
  return m;
}

std::string csv_text(const std::vector<Row>& rows, const std::string& input, const Scene& scene, unsigned threads) {
  std::ostringstream out;
  out << "# sylva bench geometry " << input << ", " << scene.width << "x" << scene.height << ", " << threads
      << " threads\n";
  out << "method,family,steps,bisection,mesh_level,build_s,time_s,depth_rmse_m,depth_max_m,hit_mismatch,"
         "colour_rmse,colour_max,memory_bytes\n";
  char line[512];
  for (const Row& r : rows) {
    std::snprintf(line, sizeof line, "%s,%s,%d,%d,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%llu\n", r.method.name.c_str(),
                  r.method.family.c_str(), r.method.steps, r.method.bisection, r.method.level, r.build_s, r.time_s,
                  r.errors.depth_rmse_m, r.errors.depth_max_m, r.errors.hit_mismatch, r.errors.colour_rmse,
                  r.errors.colour_max,
                  static_cast<unsigned long long>(r.memory));
    out << line;
  }
  return out.str();
}

std::vector<PlotPanel> plot_panels(const std::vector<Row>& rows, const std::string& title) {
  // One series per family (RC+R: one per bisection count), in the methods' order.
  std::vector<PlotSeries> series;
  std::vector<PlotSeries> depth, colour;
  for (int panel = 0; panel < 2; ++panel) {
    series.clear();
    for (const Row& r : rows) {
      std::string name = r.method.family;
      if (name == "RC+R") name += " b=" + std::to_string(r.method.bisection) + ", s=8..64";
      if (name == "GS" || name == "GS+R") name += ", m=0..4";
      series_named(series, name).points.push_back(
          {r.time_s, panel == 0 ? r.errors.depth_rmse_m : r.errors.colour_rmse});
    }
    (panel == 0 ? depth : colour) = series;
  }
  return {{title + ": depth", "trace + shade time (s)", "depth RMSE (m)", depth},
          {title + ": colour", "trace + shade time (s)", "colour RMSE (linear)", colour}};
}

}  // namespace

int run_bench_geometry(const std::vector<std::string>& args) {
  Args a = parse_args(args);
  if (a.grammar.help) {
    print_help();
    return kOk;
  }
  if (a.quick) {
    if (!a.width) a.width = 256;
    if (!a.height) a.height = 192;
    a.reference_steps = std::min(a.reference_steps, 256);
  }
  std::vector<RenderPass> passes;
  auto loaded = load_render_input(a.grammar, a.width.value_or(512), a.height.value_or(384), passes);
  if (auto* code = std::get_if<ExitCode>(&loaded)) return *code;
  const Scene scene = std::move(std::get<Scene>(loaded));
  const unsigned threads = worker_count(a.threads);
  const bool relief = scene_has_relief(scene);
  std::cerr << "sylva bench geometry: " << a.grammar.grammar << ", " << scene.width << "x" << scene.height << ", "
            << threads << " threads; reference " << describe_reference(relief, a.reference_steps, a.reference_bisection)
            << "\n";
  const TimedRender ref =
      render_cpu_timed(scene, reference_geometry(relief, a.reference_steps, a.reference_bisection), threads);

  std::vector<Row> rows;
  std::printf("%-16s %9s %9s %12s %12s %9s %12s %12s %10s\n", "method", "build_s", "time_s", "depth_rmse_m",
              "depth_max_m", "mismatch", "colour_rmse", "colour_max", "memory_KiB");
  for (const Method& m : methods_for(relief, a.quick)) {
    Row row{m};
    const TimedRender t = render_cpu_timed(scene, m.geometry, threads);
    row.build_s = t.build_s;
    row.time_s = t.time_s;
    row.memory = t.result.geometry_bytes;
    row.errors = compare_images(ref.result.image, t.result.image);
    const ImageErrors& e = row.errors;
    std::printf("%-16s %9.4f %9.4f %12.4g %12.4g %9.5f %12.4g %12.4g %10.0f\n", m.name.c_str(), row.build_s,
                row.time_s, e.depth_rmse_m, e.depth_max_m, e.hit_mismatch, e.colour_rmse, e.colour_max,
                row.memory / 1024.0);
    std::fflush(stdout);
    rows.push_back(row);
  }
  std::printf("%-16s %9.4f %9.4f %12s %12s %9s %12s %12s %10.0f\n", "reference", ref.build_s, ref.time_s, "-", "-", "-",
              "-", "-", ref.result.geometry_bytes / 1024.0);

  if (Status e = write_file_atomically(a.csv, csv_text(rows, a.grammar.grammar, scene, threads)); !e) {
    std::cerr << e.error().format();
    return kInputError;
  }
  if (Status e = write_loglog_plot(plot_panels(rows, input_stem(a.grammar.grammar)), a.plot); !e) {
    std::cerr << e.error().format();
    return kInputError;
  }
  std::cerr << "sylva bench geometry: wrote " << a.csv << " and " << a.plot << "\n";
  return kOk;
}

}  // namespace sylva::cli
