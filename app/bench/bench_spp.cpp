// bench_spp.cpp — `sylva bench spp [INPUT...]`: how many samples per pixel the default
// render needs so that thin needles and twigs do not break up (issue 15 §4), measured on
// both backends, with what each sample count costs (docs/benchmarks.md, "Samples per pixel").
//
// For every input (default: the pine and the elm, at 800×600) and every backend (the CPU
// ray caster; OpenGL where a context can be made), the same scene and camera are rendered
// at each sample count of --spp (default 1,2,4,8,16) and once at --reference-spp (default
// 64) on the same backend: a backend is measured against its own converged image, so the
// rows show the sampling error (aliasing of sub-pixel geometry, the sun disc's penumbrae)
// and not the backends' known differences (shadow map against shadow rays, docs/accuracy.md).
//
// The error is taken on the image a user sees: both images encoded to 8-bit sRGB (clamped,
// as the PNG `render` writes). Per row:
//   rmse_8bit     RMSE over all pixels and colour channels, in 8-bit steps;
//   speckle       the fraction of pixels where some channel is off by more than
//                 --speckle-step 8-bit steps (default 16): the pixels a viewer sees as
//                 broken up — a needle missing from a pixel, a twig flickering to sky;
//   time_s        the render's wall time (all passes, setup included) on --threads threads,
//                 and its ratio to the 1-spp row of the same input and backend.
// The recommended count, per input and backend, is the smallest measured count whose
// speckle is at most --max-speckle (default 0.01, one pixel in 100); the count for the
// defaults is the largest of those over the inputs (docs/benchmarks.md says what was
// chosen from it, and `render --help` states the default).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/bench/bench_metrics.h"
#include "app/bench/plot.h"
#include "app/bench/bench.h"
#include "app/front/render_input.h"
#include "core/cpu/render_cpu.h"
#include "core/gl/gl_context.h"
#include "app/front/render.h"
#include "core/gl/render_gl.h"
#include "core/util/color.h"
#include "core/util/file_io.h"
#include "core/util/parallel.h"

namespace sylva::cli {

namespace {

void print_help() {
  std::cout
      << "usage: sylva bench spp [INPUT...] [--width W --height H] [--spp LIST] [--reference-spp N]\n"
         "                       [--backends cpu,gl] [--threads N] [--speckle-step S] [--max-speckle F]\n"
         "                       [--quick] [--csv FILE] [--plot FILE.png]\n\n"
         "The sampling error of `sylva render` against the samples per pixel, on both backends: each\n"
         "INPUT (a scene, grammar or skeleton, or a preset name looked up in presets/scenes/NAME.scene.json,\n"
         "then presets/NAME.lsys; default: pine and elm) is rendered at every count of --spp and against the\n"
         "same backend's image at --reference-spp. Errors on the 8-bit sRGB image: RMSE in 8-bit steps, and\n"
         "the speckle, the fraction of pixels off by more than --speckle-step steps in some channel. Prints\n"
         "the smallest count whose speckle is at most --max-speckle, per input and backend.\n\n"
         "  --width W, --height H   image size (default 800x600)\n"
         "  --spp LIST              sample counts measured (default 1,2,4,8,16)\n"
         "  --reference-spp N       the converged image's samples per pixel (default 64)\n"
         "  --backends LIST         cpu, gl or both (default cpu,gl; gl is left out, saying why, where no\n"
         "                          OpenGL 4.5 context can be made)\n"
         "  --threads N             CPU render threads (default: every core)\n"
         "  --speckle-step S        8-bit steps past which a pixel counts as broken up (default 16)\n"
         "  --max-speckle F         the speckle a recommended count may leave (default 0.01)\n"
         "  --quick                 1,2,4 against 8 at 160x120 (for tests)\n"
         "  --csv FILE              the table as CSV (default bench_spp.csv)\n"
         "  --plot FILE             log-log error-vs-time PNG (default bench_spp.png)\n";
}

struct Args {
  bool help = false, quick = false;
  std::vector<std::string> inputs;
  std::optional<uint32_t> width, height;
  std::vector<uint32_t> spp;
  std::optional<uint32_t> reference_spp;
  bool cpu = true, gl = true;
  unsigned threads = 0;
  uint32_t speckle_step = 16;
  double max_speckle = 0.01;
  std::string csv = "bench_spp.csv", plot = "bench_spp.png";
};

std::vector<uint32_t> parse_spp_list(const std::string& flag, const std::string& text) {
  std::vector<uint32_t> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) out.push_back(parse_count(flag, item, 4096));
  if (out.empty()) throw UsageError{flag + " needs at least one sample count"};
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

double parse_fraction(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(v >= 0 && v <= 1))
    throw UsageError{flag + " needs a fraction from 0 to 1, got '" + text + "'"};
  return v;
}

Args parse_args(const std::vector<std::string>& args) {
  Args out;
  FlagTable table;
  table.flags = {
      help_flag(out.help),
      count_flag({"--width"}, out.width, 16384),
      count_flag({"--height"}, out.height, 16384),
      value_flag({"--spp"},
                 [&out](const std::string& spelled, const std::string& v) { out.spp = parse_spp_list(spelled, v); }),
      count_flag({"--reference-spp"}, out.reference_spp, 4096),
      count_flag({"--threads"}, out.threads, 4096),
      count_flag({"--speckle-step"}, out.speckle_step, 255),
      value_flag({"--max-speckle"},
                 [&out](const std::string& spelled, const std::string& v) {
                   out.max_speckle = parse_fraction(spelled, v);
                 }),
      set_flag({"--quick"}, out.quick),
      text_flag({"--csv"}, out.csv),
      text_flag({"--plot"}, out.plot),
      value_flag({"--backends"},
                 [&out](const std::string&, const std::string& names) {
                   out.cpu = out.gl = false;
                   std::stringstream in(names);
                   for (std::string item; std::getline(in, item, ',');) {
                     if (item == "cpu") out.cpu = true;
                     else if (item == "gl") out.gl = true;
                     else throw UsageError{"--backends: unknown backend '" + item + "' (available: cpu, gl)"};
                   }
                   if (!out.cpu && !out.gl) throw UsageError{"--backends needs cpu, gl or both"};
                 }),
  };
  table.positional = [&out](const std::string& input) { out.inputs.push_back(resolve_bench_input(input)); };
  table.unknown = [](const std::string& arg) {
    throw UsageError{"unknown option " + arg + " (see sylva bench spp --help)"};
  };
  parse_flags(std::span(args).subspan(1), table);  // args[0] is "spp"
  if (out.width.has_value() != out.height.has_value()) throw UsageError{"--width and --height go together"};
  if (out.help) return out;
  if (out.inputs.empty()) out.inputs = {std::string(SYLVA_PRESETS_DIR) + "/pine.lsys", std::string(SYLVA_PRESETS_DIR) + "/elm.lsys"};
  if (out.spp.empty()) out.spp = out.quick ? std::vector<uint32_t>{1, 2, 4} : std::vector<uint32_t>{1, 2, 4, 8, 16};
  if (!out.reference_spp) out.reference_spp = out.quick ? 8 : 64;
  if (*out.reference_spp <= out.spp.back())
    throw UsageError{"--reference-spp " + std::to_string(*out.reference_spp) +
                     " must exceed every measured count (the largest is " + std::to_string(out.spp.back()) + ")"};
  return out;
}

// Errors of `image` against `reference` on the 8-bit sRGB images a PNG holds.
struct DisplayErrors {
  double rmse_8bit = 0;
  double speckle = 0;  // fraction of pixels with a channel off by more than the step
};

DisplayErrors display_errors(const RenderImage& reference, const RenderImage& image, uint32_t speckle_step) {
  DisplayErrors e;
  const size_t pixels = static_cast<size_t>(reference.width) * reference.height;
  double sum_squares = 0;
  size_t speckled = 0;
  for (size_t p = 0; p < pixels; ++p) {
    int worst = 0;
    for (int c = 0; c < 3; ++c) {
      const auto encode = [&](const RenderImage& im) {
        return static_cast<int>(linear_to_srgb8(im.beauty[4 * p + c]));
      };
      const int d = std::abs(encode(image) - encode(reference));
      sum_squares += static_cast<double>(d) * d;
      worst = std::max(worst, d);
    }
    if (worst > static_cast<int>(speckle_step)) ++speckled;
  }
  e.rmse_8bit = pixels ? std::sqrt(sum_squares / (3.0 * pixels)) : 0;
  e.speckle = pixels ? static_cast<double>(speckled) / pixels : 0;
  return e;
}

struct Row {
  std::string input, backend;
  uint32_t spp = 0;
  double time_s = 0, time_ratio = 0;
  DisplayErrors errors;
};

// One render on `backend` and its wall time. The GL context must be current for "gl".
RenderResult render_timed(const Scene& scene, const std::string& backend, uint32_t spp, unsigned threads,
                          double* seconds) {
  RenderOptions options;
  options.spp = spp;
  options.threads = threads;
  const auto start = std::chrono::steady_clock::now();
  RenderResult result = backend == "gl" ? render_gl_scene(scene, options) : render_cpu(scene, options);
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::string csv_text(const std::vector<Row>& rows, const Args& a, const std::string& gl_device) {
  std::ostringstream out;
  out << "# sylva bench spp, reference " << *a.reference_spp << " spp on each backend, speckle step "
      << a.speckle_step << "/255" << (gl_device.empty() ? "" : ", gl: " + gl_device) << "\n";
  out << "input,backend,spp,time_s,time_ratio,rmse_8bit,speckle\n";
  char line[512];
  for (const Row& r : rows) {
    std::snprintf(line, sizeof line, "%s,%s,%u,%.6g,%.4g,%.6g,%.6g\n", input_stem(r.input).c_str(), r.backend.c_str(),
                  r.spp, r.time_s, r.time_ratio, r.errors.rmse_8bit, r.errors.speckle);
    out << line;
  }
  return out.str();
}

std::vector<PlotPanel> plot_panels(const std::vector<Row>& rows) {
  std::vector<PlotSeries> speckle, rmse;
  for (const Row& r : rows) {
    const std::string name = input_stem(r.input) + " " + r.backend;
    // A speckle of 0 has no place on a log axis: it is drawn at one pixel in a million.
    series_named(speckle, name).points.push_back({r.time_s, std::max(r.errors.speckle, 1e-6)});
    series_named(rmse, name).points.push_back({r.time_s, r.errors.rmse_8bit});
  }
  return {{"speckle against render time", "render time (s)", "fraction of pixels broken up", speckle},
          {"RMSE against render time", "render time (s)", "RMSE (8-bit sRGB steps)", rmse}};
}

}  // namespace

int run_bench_spp(const std::vector<std::string>& args) {
  Args a = parse_args(args);
  if (a.help) {
    print_help();
    return kOk;
  }
  const uint32_t width = a.width.value_or(a.quick ? 160 : 800), height = a.height.value_or(a.quick ? 120 : 600);
  const unsigned threads = worker_count(a.threads);

  std::vector<std::string> backends;
  if (a.cpu) backends.push_back("cpu");
  GlContextResult gl;
  std::string gl_device;
  if (a.gl) {
    gl = create_headless_gl_context();
    if (gl.context) {
      backends.push_back("gl");
      gl_device = gl.context->info().describe();
    } else {
      std::cerr << "sylva bench spp: the gl rows are left out: no OpenGL 4.5 context: " << gl.error << "\n";
      if (backends.empty()) return kInputError;
    }
  }
  std::cerr << "sylva bench spp: " << width << "x" << height << ", reference " << *a.reference_spp
            << " spp, CPU on " << threads << " threads" << (gl_device.empty() ? "" : "; gl: " + gl_device) << "\n";
  std::printf("%-14s %-7s %5s %9s %7s %10s %9s\n", "input", "backend", "spp", "time_s", "x1spp", "rmse_8bit",
              "speckle");

  std::vector<Row> rows;
  std::vector<std::string> recommendations;
  uint32_t overall = 0;
  bool all_met = true;
  for (const std::string& input : a.inputs) {
    std::vector<RenderPass> passes;
    GrammarArgs grammar;
    grammar.grammar = input;
    auto loaded = load_render_input(grammar, width, height, passes);
    if (auto* code = std::get_if<ExitCode>(&loaded)) return *code;
    const Scene scene = std::move(std::get<Scene>(loaded));
    for (const std::string& backend : backends) {
      if (backend == "gl")
        if (auto unsupported = gl_unsupported(scene, RenderOptions{})) {
          std::cerr << "sylva bench spp: " << input << ": no gl rows: " << *unsupported << "\n";
          continue;
        }
      double reference_s = 0;
      const RenderResult reference = render_timed(scene, backend, *a.reference_spp, threads, &reference_s);
      std::optional<uint32_t> recommended;
      double one_spp_s = 0;
      for (uint32_t spp : a.spp) {
        Row row{input, backend, spp, 0, 0, {}};
        const RenderResult r = render_timed(scene, backend, spp, threads, &row.time_s);
        if (spp == a.spp.front()) one_spp_s = row.time_s;
        row.time_ratio = one_spp_s > 0 ? row.time_s / one_spp_s : 0;
        row.errors = display_errors(reference.image, r.image, a.speckle_step);
        if (!recommended && row.errors.speckle <= a.max_speckle) recommended = spp;
        std::printf("%-14s %-7s %5u %9.3f %7.2f %10.3f %9.5f\n", input_stem(input).c_str(), backend.c_str(), spp,
                    row.time_s, row.time_ratio, row.errors.rmse_8bit, row.errors.speckle);
        std::fflush(stdout);
        rows.push_back(row);
      }
      std::printf("%-14s %-7s %5u %9.3f %7s %10s %9s\n", input_stem(input).c_str(), backend.c_str(),
                  *a.reference_spp, reference_s, "ref", "-", "-");
      const std::string who = input_stem(input) + " " + backend;
      if (recommended) {
        recommendations.push_back(who + ": " + std::to_string(*recommended));
        overall = std::max(overall, *recommended);
      } else {
        recommendations.push_back(who + ": none of the counts measured");
        all_met = false;
      }
    }
  }
  char threshold[64];
  std::snprintf(threshold, sizeof threshold, "%g", a.max_speckle);
  std::printf("smallest spp with speckle <= %s (%u/255 steps):", threshold, a.speckle_step);
  for (const std::string& r : recommendations) std::printf(" %s;", r.c_str());
  if (all_met) std::printf(" for every input and backend: %u\n", overall);
  else std::printf(" not met by every input and backend within --spp\n");

  if (Status e = write_file_atomically(a.csv, csv_text(rows, a, gl_device)); !e) {
    std::cerr << e.error().format();
    return kInputError;
  }
  if (Status e = write_loglog_plot(plot_panels(rows), a.plot); !e) {
    std::cerr << e.error().format();
    return kInputError;
  }
  std::cerr << "sylva bench spp: wrote " << a.csv << " and " << a.plot << "\n";
  return kOk;
}

}  // namespace sylva::cli
