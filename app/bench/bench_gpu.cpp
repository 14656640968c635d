// bench_gpu.cpp — `sylva bench gpu [INPUT...]`: error against GPU time of every way the
// GL backend can draw the plants (docs/benchmarks.md, "Error against GPU time"; Bhagvat et al. 2009 sec. 4, Table 1 and the
// dancing cacti of fig. 8).
//
// For each input and image size, each method builds one GlRenderer (render_gl.h), renders
// --warmup frames (shader variants are built at the first draw, drivers settle), then
// --frames frames, each drawn, waited for (GlRenderer::wait_for_frame) and read back. A
// frame's GPU time is GlFrameStats::gpu_s (GL_TIME_ELAPSED queries: shadow map, frusta or
// mesh, shade); the table gives its median and 10th/90th percentiles, fps from the median,
// and the frame's wall time (draw, wait and readback).
// Methods:
//   RC          the analytic frusta, relief left out;
//   RC-nocd     the same without the conservative depth layout (layout(depth_less) lets
//               the GPU keep early depth tests while the shader writes gl_FragDepth):
//               what that layout buys;
//   RC+R s×b    relief-mapped frusta, s uniform and b bisection steps, v interpolated;
//   GS m        the frusta tessellated at GS level m (16·4^m triangles a segment);
//   GS+R m      the same meshes displaced by the height map;
//   RC-anim     RC with every plant swaying (core/scene/animate.h; a scene's `animation` key's
//               motion where it has one: the dancing cacti dance) at 60 frames a second of
//               animation time: per frame the skeletons are swayed, re-skinned and their
//               segment records uploaded again (GlRenderer::update_plants); the CPU time
//               of the sway and of re-skin + upload and the bytes uploaded per frame are
//               reported beside the GPU time.
// Methods the GL backend refuses (gl_unsupported) are reported as skipped, with its reason.
//
// Errors (bench_metrics.h, as `sylva bench geometry`) of the last measured frame against
// the CPU's converged reference at the same size: RC+R with --reference-steps ×
// --reference-bisection steps and exact v (RC where no plant has a height map); RC-anim's
// against the CPU's RC of the same (last) pose. Every render here, GL and CPU, uses the
// sun as a point (angular radius 0): at one sample a pixel the GL backend draws a disc
// sun's centre while the CPU draws a random point of the disc, whose noise would
// otherwise swamp the colour errors.
//
// Memory: the bytes the renderer uploaded (GlRenderer::uploaded_bytes: segment records
// and ids, or the mesh) plus its render targets (GlFrameStats::target_bytes: G-buffer,
// depth, accumulation, shadow map, from their formats); bark textures are left out.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "app/bench/bench_gpu_fog.h"
#include "app/bench/bench_rows.h"
#include "app/bench/bench_metrics.h"
#include "app/bench/bench.h"
#include "app/front/render_input.h"
#include "core/scene/animate.h"
#include "core/util/file_io.h"
#include "core/gl/gl_context.h"
#include "app/bench/plot.h"
#include "core/scene/render_common.h"
#include "core/gl/render_gl.h"
#include "core/util/clock.h"
#include "core/util/parallel.h"

namespace sylva::cli {

namespace {


const char* const kFamilies[] = {"RC", "RC-nocd", "RC+R", "GS", "GS+R", "RC-anim"};

void print_help() {
  std::cout
      << "usage: sylva bench gpu [INPUT...] [--width W --height H] [--frames N] [--warmup K]\n"
         "                       [--methods LIST] [--csv FILE] [--plot FILE.png] [--full | --quick]\n"
         "                       [--reference-steps N] [--reference-bisection N]\n"
         "       sylva bench gpu --fog [SCENE...] [--width W --height H] [--frames N] [--quick] ...\n\n"
         "Error against GPU time per frame of the GL backend's ways to draw INPUT (scenes,\n"
         "grammars, skeletons or glTF exports, as for `sylva render`; a bare name is looked\n"
         "up in presets/scenes/NAME.scene.json, then presets/NAME.lsys; default: the pine and\n"
         "saguaro scenes): ray-cast frusta (RC; RC-nocd without the conservative depth\n"
         "layout), relief-mapped frusta (RC+R), meshes (GS, m = 0..4), displaced meshes\n"
         "(GS+R) and swaying skeletons re-uploaded every frame (RC-anim). GPU time is the\n"
         "sum of the GL_TIME_ELAPSED passes; errors are against the CPU's converged\n"
         "reference. Methods the GL backend cannot draw yet are listed as skipped.\n\n"
         "The default run: 1024x768, 10 frames after 2, RC, RC-nocd, RC+R 8x0 and 32x4, GS and GS+R\n"
         "m = 0..2, RC-anim (22 rows for the pine and saguaro: 4 min 39 s on dev-2c's llvmpipe).\n"
         "--full: the whole sweep, 1024x768 and 1920x1080, 100 frames after 5, RC+R 8x0, 16x4,\n"
         "32x4, 64x8, GS and GS+R m = 0..4 (60 rows; about 5 h on dev-2c's llvmpipe, estimated\n"
         "in docs/benchmarks.md).\n"
         "Each row is printed as it finishes and the CSV rewritten (atomically) with the rows done;\n"
         "stderr gets one progress line a row with the time elapsed and an estimate of the time\n"
         "left. A stopped run (Ctrl-C, SIGTERM) leaves a valid CSV of its finished rows whose last\n"
         "line is '# partial run: K of N rows ...'; the plot is drawn at the end only.\n\n"
         "  --width W, --height H   one image size (default 1024x768; --full: and 1920x1080)\n"
         "  --frames N              measured frames per method (default 10; --full: 100)\n"
         "  --warmup K              frames rendered before measuring (default 2; --full: 5)\n"
         "  --methods LIST          comma-separated families: RC,RC-nocd,RC+R,GS,GS+R,RC-anim\n"
         "  --csv FILE              the table as CSV (default bench_gpu.csv)\n"
         "  --plot FILE             log-log depth error vs GPU time PNG (default bench_gpu.png)\n"
         "  --full                  the whole sweep (above)\n"
         "  --quick                 a 160x120 image, 3 frames after 1, fewer settings (tests)\n"
         "  --reference-steps N     uniform relief steps of the reference (default 1024)\n"
         "  --reference-bisection N bisection steps of the reference (default 24)\n"
         "  --fog                   the fog pass instead: brute at 16..256 steps, fast, medium and map on\n"
         "                          foggy scenes (default elm_grove_low_sun), fog GPU ms and the fog\n"
         "                          AOV's RMSE against the CPU reference (default bench_gpu_fog.csv,\n"
         "                          .png; --quick: 96x72, brute 16 and 64, 2 frames after 1)\n"
         "  --reference-stride S    with --fog: the CPU reference, and the error, on every S-th pixel\n"
         "                          each way only (default 1: every pixel; a uniform grid gives the\n"
         "                          same RMSE in expectation, S² times sooner)\n";
}

struct ImageSize {
  uint32_t width = 0, height = 0;
};

struct Args {
  std::vector<std::string> inputs;
  std::optional<uint32_t> width, height, frames, warmup;
  std::vector<std::string> families;  // empty: every family
  bool quick = false;
  bool full = false;                  // --full: the whole sweep (docs/benchmarks.md)
  bool help = false;
  bool fog = false;                   // --fog: the fog pass's rows (bench_gpu_fog.h)
  bool csv_given = false, plot_given = false;
  std::string csv = "bench_gpu.csv", plot = "bench_gpu.png";
  int reference_steps = 1024;
  int reference_bisection = 24;
  uint32_t reference_stride = 1;  // --reference-stride, --fog only
};

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// A family name as kFamilies spells it, from any case; UsageError when unknown.
std::string family_named(const std::string& name) {
  for (const char* f : kFamilies)
    if (lower(name) == lower(f)) return f;
  throw UsageError{"--methods: unknown method family '" + name + "' (available: RC, RC-nocd, RC+R, GS, GS+R, RC-anim)"};
}

Args parse_args(const std::vector<std::string>& args) {
  Args out;
  FlagTable table;
  table.flags = {
      help_flag(out.help),
      count_flag({"--width"}, out.width, 16384),
      count_flag({"--height"}, out.height, 16384),
      count_flag({"--frames"}, out.frames, 1'000'000),
      count_flag({"--warmup"}, out.warmup, 1'000'000),
      set_flag({"--quick"}, out.quick),
      set_flag({"--full"}, out.full),
      set_flag({"--fog"}, out.fog),
      noting_given(text_flag({"--csv"}, out.csv), out.csv_given),
      noting_given(text_flag({"--plot"}, out.plot), out.plot_given),
      count_flag({"--reference-steps"}, out.reference_steps, 1 << 20),
      count_flag({"--reference-stride"}, out.reference_stride, 1024),
      count_flag({"--reference-bisection"}, out.reference_bisection, 60),
      value_flag({"--methods"},
                 [&out](const std::string&, const std::string& names) {
                   std::stringstream list(names);
                   for (std::string name; std::getline(list, name, ',');)
                     if (!name.empty()) out.families.push_back(family_named(name));
                   if (out.families.empty()) throw UsageError{"--methods needs at least one method family"};
                 }),
  };
  table.positional = [&out](const std::string& input) { out.inputs.push_back(input); };
  parse_flags(std::span(args).subspan(1), table);  // args[0] is "gpu"
  if (out.help) return out;
  if (out.width.has_value() != out.height.has_value()) throw UsageError{"give --width and --height together"};
  if (out.full && out.quick) throw UsageError{"--full and --quick exclude each other"};
  for (std::string& input : out.inputs) input = resolve_bench_input(input);
  if (out.inputs.empty())
    out.inputs = out.fog ? std::vector<std::string>{resolve_bench_input("elm_grove_low_sun")}
                         : std::vector<std::string>{resolve_bench_input("pine"), resolve_bench_input("saguaro")};
  if (out.fog && !out.csv_given) out.csv = "bench_gpu_fog.csv";
  if (out.fog && !out.plot_given) out.plot = "bench_gpu_fog.png";
  return out;
}

struct Method {
  std::string family;  // one of kFamilies
  std::string name;    // e.g. "RC+R 32x4", "GS m=2"
  GeometryOptions geometry;
  int steps = 0, bisection = 0, level = -1;
  bool conservative_depth = true;
  bool animated = false;
};

// The settings of each family: --quick's (tests), the default run's, or --full's sweep.
enum class Sweep { quick, standard, full };

std::vector<Method> methods_for(bool relief, Sweep sweep, const std::vector<std::string>& families) {
  auto wanted = [&](const std::string& family) {
    return families.empty() || std::find(families.begin(), families.end(), family) != families.end();
  };
  std::vector<Method> m;
  const GeometryOptions rc = frusta_geometry();
  if (wanted("RC")) m.push_back({"RC", "RC", rc});
  if (wanted("RC-nocd")) {
    Method no_layout{"RC-nocd", "RC no cons. depth", rc};
    no_layout.conservative_depth = false;
    m.push_back(no_layout);
  }
  if (relief && wanted("RC+R")) {
    using Setting = std::pair<int, int>;  // uniform steps, bisection steps
    const std::vector<Setting> settings = sweep == Sweep::quick      ? std::vector<Setting>{{16, 4}}
                                          : sweep == Sweep::standard ? std::vector<Setting>{{8, 0}, {32, 4}}
                                                                     : std::vector<Setting>{{8, 0}, {16, 4}, {32, 4}, {64, 8}};
    for (const auto& [steps, bisection] : settings)
      m.push_back({"RC+R", "RC+R " + std::to_string(steps) + "x" + std::to_string(bisection),
                   relief_geometry(steps, bisection), steps, bisection});
  }
  const int max_level = sweep == Sweep::full ? 4 : sweep == Sweep::standard ? 2 : 1;
  for (int displaced = 0; displaced <= (relief ? 1 : 0); ++displaced) {
    const std::string family = displaced ? "GS+R" : "GS";
    if (!wanted(family)) continue;
    for (int level = 0; level <= max_level; ++level)
      m.push_back({family, family + " m=" + std::to_string(level), mesh_geometry(level, displaced != 0), 0, 0, level});
  }
  if (wanted("RC-anim")) {
    Method anim{"RC-anim", "RC anim", rc};
    anim.animated = true;
    m.push_back(anim);
  }
  return m;
}

// p-th quantile (0..1) of `values`, linear between order statistics; NaN when empty.
double quantile(std::vector<double> values, double p) {
  if (values.empty()) return std::nan("");
  std::sort(values.begin(), values.end());
  const double at = p * static_cast<double>(values.size() - 1);
  const size_t below = static_cast<size_t>(std::floor(at));
  const size_t above = std::min(below + 1, values.size() - 1);
  return values[below] + (at - static_cast<double>(below)) * (values[above] - values[below]);
}

struct Row {
  std::string input;
  ImageSize size;
  Method method;
  std::string status = "ok";  // ok, skipped (the GL backend refuses), failed (it threw)
  std::string reason{};
  std::vector<double> gpu_s{}, wall_s{}, sway_s{}, update_s{}, upload_bytes{};  // per measured frame
  uint64_t frusta = 0, setup_upload_bytes = 0, memory_bytes = 0;
  std::string reference{};
  std::optional<ImageErrors> errors{};
};

// What a method is measured against: the converged reference of the input at this size,
// rendered on the CPU the first time a method needs it.
class LazyReference {
 public:
  LazyReference(const Scene& scene, const Args& args) : scene_(scene), args_(args) {}
  const RenderImage& image() {
    if (!image_) {
      const bool relief = scene_has_relief(scene_);
      const unsigned threads = worker_count(0);
      std::cerr << "sylva bench gpu: CPU reference " << describe() << ", " << scene_.width << "x" << scene_.height
                << ", " << threads << " threads\n";
      image_ = render_cpu_timed(scene_, reference_geometry(relief, args_.reference_steps, args_.reference_bisection),
                                threads)
                   .result.image;
    }
    return *image_;
  }
  std::string describe() const {
    return describe_reference(scene_has_relief(scene_), args_.reference_steps, args_.reference_bisection) + " (CPU)";
  }

 private:
  const Scene& scene_;
  const Args& args_;
  std::optional<RenderImage> image_;
};

void run_method(const Scene& scene, uint32_t frames, uint32_t warmup, LazyReference& reference,
                Row& row) {
  const Method& m = row.method;
  RenderOptions options;
  options.aovs = kAovDepth;
  options.geometry = m.geometry;
  if (auto why = gl_unsupported(scene, options)) {
    row.status = "skipped";
    row.reason = *why;
    return;
  }
  try {
    Scene posed = scene;  // RC-anim's plants at the frame's pose
    std::vector<Skeleton> rest;
    if (m.animated)
      for (const ScenePlant& p : scene.plants) rest.push_back(*p.skeleton);
    // The scene's own motion where it has an `animation` key (the dancing cacti dance).
    const SwayParameters sway = scene.animation ? sway_parameters_of(*scene.animation) : SwayParameters{};
    GlRenderer renderer(scene, options);
    renderer.set_conservative_depth(m.conservative_depth);
    row.frusta = renderer.frusta();
    row.setup_upload_bytes = renderer.uploaded_bytes();
    RenderImage image;
    GlFrameStats stats;
    for (uint32_t f = 0; f < warmup + frames; ++f) {
      double sway_s = 0, update_s = 0, uploaded = 0;
      if (m.animated) {
        Clock::time_point start = Clock::now();
        sway_scene_plants(posed, rest, f / 60.0, sway);
        sway_s = seconds_since(start);
        start = Clock::now();
        uploaded = static_cast<double>(renderer.update_plants(posed));
        update_s = seconds_since(start);
      }
      const Clock::time_point start = Clock::now();
      renderer.draw(posed);
      stats = renderer.wait_for_frame();
      image = renderer.read_back();
      const double wall_s = seconds_since(start);
      if (f < warmup) continue;
      row.gpu_s.push_back(stats.gpu_s());
      row.wall_s.push_back(wall_s);
      if (m.animated) {
        row.sway_s.push_back(sway_s);
        row.update_s.push_back(update_s);
        row.upload_bytes.push_back(uploaded);
      }
    }
    row.frusta = stats.frusta;
    row.memory_bytes = renderer.uploaded_bytes() + stats.target_bytes;
    if (m.animated) {
      // The moving plants have no converged reference: the CPU draws the last pose the
      // same way, which checks that update_plants uploaded it.
      row.reference = "RC at the same pose (CPU)";
      const unsigned threads = worker_count(0);
      row.errors = compare_images(render_cpu_timed(posed, m.geometry, threads).result.image, image);
    } else {
      row.reference = reference.describe();
      row.errors = compare_images(reference.image(), image);
    }
  } catch (const std::exception& e) {
    row.status = "failed";
    row.reason = e.what();
  }
}

// A CSV field, quoted when it holds a comma, a quote or a line break (RFC 4180).
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

// A number for the CSV: empty when not measured (NaN).
std::string csv_number(double v) {
  if (std::isnan(v)) return "";
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

const char* const kCsvColumns =
    "device,gl_renderer,input,width,height,method,family,steps,bisection,mesh_level,status,reason,frames,"
    "gpu_ms_median,gpu_ms_p10,gpu_ms_p90,fps,wall_ms_median,frusta,setup_upload_bytes,gpu_memory_bytes,"
    "upload_bytes_per_frame,sway_ms_median,update_ms_median,reference,depth_rmse_m,depth_max_m,hit_mismatch,"
    "colour_rmse,colour_max\n";

// The CSV's comment and column lines.
std::string csv_head(const std::string& device, const GlContextInfo& gl, uint32_t frames, uint32_t warmup,
                     const std::string& run) {
  std::ostringstream out;
  out << "# sylva bench gpu on " << device << " (" << gl.describe() << "), " << frames << " frames after " << warmup
      << " warm-up frames, sun as a point, " << run << "\n";
  out << kCsvColumns;
  return out.str();
}

// One row of the CSV, ending in '\n'.
std::string csv_row(const Row& r, const std::string& device, const GlContextInfo& gl) {
  std::ostringstream out;
  {
    const Method& m = r.method;
    const double median_ms = quantile(r.gpu_s, 0.5) * 1e3;
    const ImageErrors e = r.errors.value_or(ImageErrors{});
    auto error = [&](double v) { return csv_number(r.errors ? v : std::nan("")); };
    out << csv_field(device) << ',' << csv_field(gl.renderer) << ',' << csv_field(r.input) << ',' << r.size.width
        << ',' << r.size.height << ',' << csv_field(m.name) << ',' << csv_field(m.family) << ',' << m.steps << ','
        << m.bisection << ',' << m.level << ',' << r.status << ',' << csv_field(r.reason) << ',' << r.gpu_s.size()
        << ',' << csv_number(median_ms) << ',' << csv_number(quantile(r.gpu_s, 0.1) * 1e3) << ','
        << csv_number(quantile(r.gpu_s, 0.9) * 1e3) << ',' << csv_number(1e3 / median_ms) << ','
        << csv_number(quantile(r.wall_s, 0.5) * 1e3) << ',' << r.frusta << ',' << r.setup_upload_bytes << ','
        << r.memory_bytes << ',' << csv_number(quantile(r.upload_bytes, 0.5)) << ','
        << csv_number(quantile(r.sway_s, 0.5) * 1e3) << ',' << csv_number(quantile(r.update_s, 0.5) * 1e3) << ','
        << csv_field(r.reference) << ',' << error(e.depth_rmse_m) << ',' << error(e.depth_max_m) << ','
        << error(e.hit_mismatch) << ',' << error(e.colour_rmse) << ',' << error(e.colour_max) << '\n';
  }
  return out.str();
}

// "saguaro.scene.json 1920x1080": the input's file name and the image size.
std::string where(const Row& r) {
  return r.input.substr(r.input.find_last_of('/') + 1) + " " + std::to_string(r.size.width) + "x" +
         std::to_string(r.size.height);
}

void print_row(const Row& r) {
  if (r.status != "ok") {
    std::printf("%-28s %-18s %s: %s\n", where(r).c_str(), r.method.name.c_str(), r.status.c_str(), r.reason.c_str());
  } else {
    const double median_ms = quantile(r.gpu_s, 0.5) * 1e3;
    const ImageErrors& e = *r.errors;
    std::printf("%-28s %-18s %9.3f %9.3f %9.3f %9.1f %9.2f %10.2f %10.1f %10.1f %9.3f %11.4g %9.5f %11.4g\n",
                where(r).c_str(), r.method.name.c_str(), median_ms, quantile(r.gpu_s, 0.1) * 1e3,
                quantile(r.gpu_s, 0.9) * 1e3, 1e3 / median_ms, quantile(r.wall_s, 0.5) * 1e3,
                r.memory_bytes / 1048576.0, r.setup_upload_bytes / 1024.0,
                r.upload_bytes.empty() ? 0.0 : quantile(r.upload_bytes, 0.5) / 1024.0,
                r.update_s.empty() ? 0.0 : quantile(r.update_s, 0.5) * 1e3, e.depth_rmse_m, e.hit_mismatch,
                e.colour_rmse);
  }
  std::fflush(stdout);
}

// One panel per input and size: depth RMSE against GPU time, a series per family (RC+R
// and the meshes as curves over their settings, named in the legend); RC-anim has no
// converged error.
std::vector<PlotPanel> plot_panels(const std::vector<Row>& rows, const std::string& device) {
  std::vector<PlotPanel> panels;
  std::vector<std::map<std::string, std::string>> settings;  // per panel: family -> settings drawn
  const Row* first_of_panel = nullptr;
  for (const Row& r : rows) {
    if (!first_of_panel || r.input != first_of_panel->input || r.size.width != first_of_panel->size.width ||
        r.size.height != first_of_panel->size.height) {
      panels.push_back({where(r) + ", " + device, "GPU time per frame (ms)", "depth RMSE (m)", {}});
      settings.emplace_back();
      first_of_panel = &r;
    }
    if (r.status != "ok" || r.method.animated) continue;
    series_named(panels.back().series, r.method.family)
        .points.push_back({quantile(r.gpu_s, 0.5) * 1e3, r.errors->depth_rmse_m});
    // The legend lists the settings drawn: "GS m=0,1,2", "RC+R 8x0,16x4".
    if (r.method.name.rfind(r.method.family + " ", 0) == 0) {
      const std::string setting = r.method.name.substr(r.method.family.size() + 1);  // "m=2", "16x4"
      std::string& text = settings.back()[r.method.family];
      text += text.empty() ? setting : "," + setting.substr(setting.find('=') + 1);
    }
  }
  for (size_t p = 0; p < panels.size(); ++p)
    for (PlotSeries& series : panels[p].series)
      if (auto found = settings[p].find(series.name); found != settings[p].end()) series.name += " " + found->second;
  return panels;
}

// "software (llvmpipe)" for a software rasteriser (its first word), else GL_RENDERER.
std::string device_label(const GlContextInfo& info) {
  if (!info.software) return info.renderer;
  return "software (" + info.renderer.substr(0, info.renderer.find(' ')) + ")";
}

}  // namespace

int run_bench_gpu(const std::vector<std::string>& args) {
  Args a = parse_args(args);
  if (a.help) {
    print_help();
    return kOk;
  }
  const Sweep sweep = a.full ? Sweep::full : a.quick ? Sweep::quick : Sweep::standard;
  const uint32_t frames = a.frames.value_or(a.quick ? 3 : a.full ? 100 : 10);
  const uint32_t warmup = a.warmup.value_or(a.quick ? 1 : a.full ? 5 : 2);
  std::vector<ImageSize> sizes;
  if (a.width) sizes.push_back({*a.width, *a.height});
  else if (a.quick) sizes.push_back({160, 120});
  else if (a.full) sizes = {{1024, 768}, {1920, 1080}};
  else sizes = {{1024, 768}};

  GlContextResult gl = create_headless_gl_context();
  if (!gl.context) {
    std::cerr << "sylva bench gpu: no OpenGL 4.5 context: " << gl.error << "\n";
    return kInputError;
  }
  const std::string device = device_label(gl.context->info());
  std::cerr << "sylva bench gpu: " << gl.context->info().describe() << "\n";
  std::printf("device: %s\n", device.c_str());
  if (a.fog) {
    GpuFogArgs fog;
    fog.inputs = a.inputs;
    for (const ImageSize& s : sizes) fog.sizes.push_back({s.width, s.height});
    if (a.quick && !a.width) fog.sizes = {{96, 72}};
    fog.frames = a.frames.value_or(a.quick ? 2 : 10);
    fog.warmup = a.warmup.value_or(1);
    fog.quick = a.quick;
    fog.reference_stride = a.reference_stride;
    fog.csv = a.csv;
    fog.plot = a.plot;
    return run_gpu_fog_rows(fog, device, gl.context->info());
  }
  std::printf("%-28s %-18s %9s %9s %9s %9s %9s %10s %10s %10s %9s %11s %9s %11s\n", "input", "method", "gpu_ms", "p10",
              "p90", "fps", "wall_ms", "mem_MiB", "setup_KiB", "KiB/frame", "upd_ms", "depth_rmse", "mismatch",
              "colour_rmse");

  // Every input at every size first, so that the rows planned are known (the progress
  // line's estimate, the CSV's partial-run line).
  struct Job {
    std::string input;
    ImageSize size;
    Scene scene;
    std::vector<Method> methods;
  };
  std::vector<Job> jobs;
  size_t planned = 0;
  for (const std::string& input : a.inputs) {
    for (const ImageSize& size : sizes) {
      std::vector<RenderPass> passes;
      GrammarArgs grammar;
      grammar.grammar = input;
      auto loaded = load_render_input(grammar, size.width, size.height, passes);
      if (auto* code = std::get_if<ExitCode>(&loaded)) return *code;
      Job job{input, size, std::move(std::get<Scene>(loaded)), {}};
      job.scene.sun.angular_radius_deg = 0;
      job.methods = methods_for(scene_has_relief(job.scene), sweep, a.families);
      planned += job.methods.size();
      jobs.push_back(std::move(job));
    }
  }
  const std::string run = a.full ? "full sweep" : a.quick ? "quick run" : "default run (--full: the whole sweep)";
  BenchRows csv("sylva bench gpu", a.csv, csv_head(device, gl.context->info(), frames, warmup, run), planned,
                isatty(STDERR_FILENO) != 0);
  if (Status e = csv.start(); !e) {
    std::cerr << e.error().format();
    return kInputError;
  }
  std::vector<Row> rows;
  for (const Job& job : jobs) {
    LazyReference reference(job.scene, a);
    for (const Method& m : job.methods) {
      Row row{job.input, job.size, m};
      run_method(job.scene, frames, warmup, reference, row);
      print_row(row);
      if (Status e = csv.add(csv_row(row, device, gl.context->info()), where(row) + " " + m.name); !e) {
        std::cerr << e.error().format();
        return kInputError;
      }
      rows.push_back(std::move(row));
    }
  }
  if (Status e = csv.finish(); !e) {
    std::cerr << e.error().format();
    return kInputError;
  }
  if (Status e = write_loglog_plot(plot_panels(rows, device), a.plot); !e) {
    std::cerr << e.error().format();
    return kInputError;
  }
  std::cerr << "sylva bench gpu: wrote " << a.csv << " and " << a.plot << "\n";
  const auto failed = std::count_if(rows.begin(), rows.end(), [](const Row& r) { return r.status == "failed"; });
  if (failed > 0) {
    std::cerr << "sylva bench gpu: " << failed << " method(s) failed (see the table)\n";
    return kInputError;
  }
  return kOk;
}

}  // namespace sylva::cli
