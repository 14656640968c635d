// bench_geometry.cpp — `sylva bench geometry INPUT`: error against run time of every way
// the CPU engine can stand for the plants (issue 3 §5).
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
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/cli.h"
#include "app/render_input.h"
#include "core/file_io.h"
#include "core/plot.h"
#include "core/render_cpu.h"

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

uint32_t parse_count(const std::string& flag, const std::string& v, uint64_t max) {
  auto n = parse_u64(v);
  if (!n || *n == 0 || *n > max) throw UsageError{flag + " " + v + ": expected an integer from 1 to " + std::to_string(max)};
  return static_cast<uint32_t>(*n);
}

std::string stem_of(const std::string& path) {
  std::string name = path.substr(path.find_last_of('/') + 1);
  for (const char* ext : {".scene.json", ".skel.json", ".lsys", ".glb", ".gltf"}) {
    const std::string e = ext;
    if (name.size() > e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0)
      return name.substr(0, name.size() - e.size());
  }
  return name;
}

Args parse_args(const std::vector<std::string>& args) {
  Args out;
  std::vector<std::string> rest;
  for (size_t i = 1; i < args.size(); ++i) {  // args[0] is "geometry"
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw UsageError{a + " needs a value"};
      return args[++i];
    };
    if (a == "--width") out.width = parse_count(a, value(), 16384);
    else if (a == "--height") out.height = parse_count(a, value(), 16384);
    else if (a == "--threads") out.threads = parse_count(a, value(), 4096);
    else if (a == "--quick") out.quick = true;
    else if (a == "--csv") out.csv = value();
    else if (a == "--plot") out.plot = value();
    else if (a == "--reference-steps") out.reference_steps = static_cast<int>(parse_count(a, value(), 1 << 20));
    else if (a == "--reference-bisection") out.reference_bisection = static_cast<int>(parse_count(a, value(), 60));
    else rest.push_back(a);
  }
  out.grammar = parse_grammar_args(rest, false);
  if (out.grammar.help) return out;
  if (!is_render_input(out.grammar.grammar))
    throw UsageError{"INPUT '" + out.grammar.grammar + "' must end in .lsys, .skel.json, .scene.json, .glb or .gltf"};
  const std::string stem = stem_of(out.grammar.grammar);
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
  double depth_rmse = 0, depth_max = 0, mismatch = 0;
  double colour_rmse = 0, colour_max = 0;
  uint64_t memory = 0;
};

// Renders the scene with `geometry`; time of the trace + shade pass and the rest.
struct Timed {
  RenderResult result;
  double build_s = 0, time_s = 0;
};

Timed render_with(const Scene& scene, const GeometryOptions& geometry, unsigned threads) {
  RenderOptions options;
  options.aovs = kAovDepth;
  options.threads = threads;
  options.geometry = geometry;
  Timed t{render_cpu(scene, options)};
  bool traced = false;
  for (const RenderPass& p : t.result.passes) {
    if (p.name.rfind("trace + shade", 0) == 0) t.time_s = p.seconds, traced = true;
    else if (!traced) t.build_s += p.seconds;
  }
  return t;
}

void compare(const RenderImage& ref, const RenderImage& img, Row& row) {
  double depth_sq = 0, colour_sq = 0;
  size_t both = 0, mismatch = 0;
  const size_t pixels = static_cast<size_t>(ref.width) * ref.height;
  for (size_t i = 0; i < pixels; ++i) {
    const bool a = std::isfinite(ref.depth[i]), b = std::isfinite(img.depth[i]);
    if (a && b) {
      const double d = static_cast<double>(img.depth[i]) - ref.depth[i];
      depth_sq += d * d;
      row.depth_max = std::max(row.depth_max, std::abs(d));
      ++both;
    } else if (a != b) {
      ++mismatch;
    }
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(img.beauty[i * 4 + c]) - ref.beauty[i * 4 + c];
      colour_sq += d * d;
      row.colour_max = std::max(row.colour_max, std::abs(d));
    }
  }
  row.depth_rmse = both ? std::sqrt(depth_sq / both) : 0;
  row.mismatch = pixels ? static_cast<double>(mismatch) / pixels : 0;
  row.colour_rmse = pixels ? std::sqrt(colour_sq / (3.0 * pixels)) : 0;
}

std::vector<Method> methods_for(bool relief, bool quick) {
  std::vector<Method> m;
  GeometryOptions rc;
  rc.kind = GeometryKind::frusta;
  rc.relief = false;
  m.push_back({"RC", "RC", rc});
  if (relief) {
    const std::vector<int> steps = quick ? std::vector<int>{8, 32} : std::vector<int>{8, 16, 32, 64};
    const std::vector<int> bisections = quick ? std::vector<int>{0, 8} : std::vector<int>{0, 4, 8};
    for (int b : bisections)
      for (int s : steps) {
        GeometryOptions g = rc;
        g.relief = true;
        g.relief_options.linear_steps = s;
        g.relief_options.bisection_steps = b;
        g.relief_options.exact_v = false;
        m.push_back({"RC+R", "RC+R " + std::to_string(s) + "x" + std::to_string(b), g, s, b});
      }
  }
  const int max_level = quick ? 2 : 4;
  for (int displaced = 0; displaced <= (relief ? 1 : 0); ++displaced)
    for (int level = 0; level <= max_level; ++level) {
      GeometryOptions g;
      g.kind = GeometryKind::mesh;
      g.mesh_level = level;
      g.displace = displaced != 0;
      const std::string family = displaced ? "GS+R" : "GS";
      m.push_back({family, family + " m=" + std::to_string(level), g, 0, 0, level});
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
                  r.depth_rmse, r.depth_max, r.mismatch, r.colour_rmse, r.colour_max,
                  static_cast<unsigned long long>(r.memory));
    out << line;
  }
  return out.str();
}

std::vector<PlotPanel> plot_panels(const std::vector<Row>& rows, const std::string& title) {
  // One series per family (RC+R: one per bisection count), in the methods' order.
  std::vector<PlotSeries> series;
  auto series_for = [&](const std::string& name) -> PlotSeries& {
    for (PlotSeries& s : series)
      if (s.name == name) return s;
    series.push_back({name, plot_colour(series.size()), {}, true});
    return series.back();
  };
  std::vector<PlotSeries> depth, colour;
  for (int panel = 0; panel < 2; ++panel) {
    series.clear();
    for (const Row& r : rows) {
      std::string name = r.method.family;
      if (name == "RC+R") name += " b=" + std::to_string(r.method.bisection) + ", s=8..64";
      if (name == "GS" || name == "GS+R") name += ", m=0..4";
      series_for(name).points.push_back({r.time_s, panel == 0 ? r.depth_rmse : r.colour_rmse});
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
  const unsigned threads = a.threads ? a.threads : std::max(1u, std::thread::hardware_concurrency());
  bool relief = false;
  for (const ScenePlant& p : scene.plants) relief = relief || p.bark.height_texture.has_value();

  GeometryOptions reference;
  reference.kind = GeometryKind::frusta;
  reference.relief = relief;
  reference.relief_options.linear_steps = a.reference_steps;
  reference.relief_options.bisection_steps = a.reference_bisection;
  reference.relief_options.exact_v = true;
  std::cerr << "sylva bench geometry: " << a.grammar.grammar << ", " << scene.width << "x" << scene.height << ", "
            << threads << " threads; reference "
            << (relief ? "RC+R " + std::to_string(a.reference_steps) + "x" + std::to_string(a.reference_bisection) +
                             " exact v"
                       : std::string("RC (the scene has no height map)"))
            << "\n";
  const Timed ref = render_with(scene, reference, threads);

  std::vector<Row> rows;
  std::printf("%-16s %9s %9s %12s %12s %9s %12s %12s %10s\n", "method", "build_s", "time_s", "depth_rmse_m",
              "depth_max_m", "mismatch", "colour_rmse", "colour_max", "memory_KiB");
  for (const Method& m : methods_for(relief, a.quick)) {
    Row row{m};
    const Timed t = render_with(scene, m.geometry, threads);
    row.build_s = t.build_s;
    row.time_s = t.time_s;
    row.memory = t.result.geometry_bytes;
    compare(ref.result.image, t.result.image, row);
    std::printf("%-16s %9.4f %9.4f %12.4g %12.4g %9.5f %12.4g %12.4g %10.0f\n", m.name.c_str(), row.build_s,
                row.time_s, row.depth_rmse, row.depth_max, row.mismatch, row.colour_rmse, row.colour_max,
                row.memory / 1024.0);
    std::fflush(stdout);
    rows.push_back(row);
  }
  std::printf("%-16s %9.4f %9.4f %12s %12s %9s %12s %12s %10.0f\n", "reference", ref.build_s, ref.time_s, "-", "-", "-",
              "-", "-", ref.result.geometry_bytes / 1024.0);

  if (auto e = write_file_atomically(a.csv, csv_text(rows, a.grammar.grammar, scene, threads))) {
    std::cerr << e->format() << "\n";
    return kInputError;
  }
  if (auto e = write_loglog_plot(plot_panels(rows, stem_of(a.grammar.grammar)), a.plot)) {
    std::cerr << e->format() << "\n";
    return kInputError;
  }
  std::cerr << "sylva bench geometry: wrote " << a.csv << " and " << a.plot << "\n";
  return kOk;
}

}  // namespace sylva::cli
