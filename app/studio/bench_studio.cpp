// bench_studio.cpp — `sylva bench studio [--quick]`: the studio's speed targets (issue
// "The studio", recorded in docs/benchmarks.md, never timed tests), measured on the app
// the window runs — StudioApp, its worker and the GL and CPU viewports — with an ImGui context
// and a window-less EGL context instead of a window (no display needed). What the
// window adds per frame (ImGui's own GL draw, the swap) is not in these figures.
//   latency  a define moved (as a slider release does) until the first frame whose
//            viewport shows the regrown plant: worker (parse, derive, interpret, turtle),
//            skin + upload, render, all on this machine (llvmpipe without a GPU); once
//            with the GL viewport, once with the CPU one (the studio's choice on llvmpipe)
//   frames   UI frame times while a ~15 M-module derivation runs on the worker
//   memory   resident memory over many regrows of the same grammar
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iostream>
#include <thread>

#include <imgui.h>

#include "app/front/args.h"
#include "app/studio/cpu_viewport.h"
#include "app/studio/gl_viewport.h"
#include "app/studio/studio.h"
#include "app/studio/studio_app.h"
#include "core/gl/gl_context.h"
#include "core/util/file_io.h"

namespace sylva::studio {

namespace {

using Clock = std::chrono::steady_clock;

double resident_mib() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return static_cast<double>(resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

class Ui {
 public:
  Ui() {
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;
    io.DisplaySize = ImVec2(1280, 800);
    unsigned char* px = nullptr;
    int w = 0, h = 0;
    io.Fonts->GetTexDataAsRGBA32(&px, &w, &h);
  }
  ~Ui() { ImGui::DestroyContext(); }
  // One frame; returns its wall time in ms. `pause_ms` stands for the swap's wait.
  double frame(StudioApp& app, double pause_ms = 1) {
    const auto t0 = Clock::now();
    ImGui::GetIO().DeltaTime = 1.0f / 60;
    ImGui::NewFrame();
    app.frame(std::chrono::duration<double>(Clock::now().time_since_epoch()).count());
    ImGui::Render();
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(pause_ms));
    return ms;
  }
  std::vector<double> frame_ms;  // the frames until() drew
  bool until(StudioApp& app, const std::function<bool()>& done, double timeout_s = 300, double pause_ms = 1) {
    const auto start = Clock::now();
    while (!done()) {
      if (Clock::now() - start > std::chrono::duration<double>(timeout_s)) return false;
      frame_ms.push_back(frame(app, pause_ms));
    }
    return true;
  }
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5))];
}

// Moves `define` between two values `runs` times; prints the latencies.
bool latency(Ui& ui, Viewport& viewport, const std::string& presets, const std::string& grammar,
             const std::string& define, double a, double b, int runs) {
  StudioOptions o;
  o.presets_dir = presets;
  StudioApp app(o, &viewport);
  if (auto err = app.open(presets + "/" + grammar)) {
    std::cerr << *err << "\n";
    return false;
  }
  if (!ui.until(app, [&] { return app.plant_drawn(); })) return false;
  std::vector<double> total, worker, upload, render, full;
  size_t previews = 0;
  ui.frame_ms.clear();
  for (int i = 0; i < runs; ++i) {
    const uint64_t before = app.plants_applied();
    const auto edited = std::chrono::steady_clock::now();
    app.set_define(define, i % 2 ? a : b);
    if (!ui.until(app, [&] { return app.plants_applied() > before && app.plant_drawn(); })) return false;
    total.push_back(app.latencies().back() * 1e3);
    worker.push_back(app.plant()->worker_seconds * 1e3);
    upload.push_back(viewport.stats().upload_ms);
    if (viewport.stats().preview) {
      ++previews;
      if (!ui.until(app, [&] { return !viewport.stats().preview; })) return false;
    }
    full.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - edited).count());
    render.push_back(viewport.stats().render_ms);
  }
  std::printf("latency %-10s %-4s %6llu segments %7.1f ms median, %7.1f ms p90, %7.1f ms max  (worker %.1f, skin+upload "
              "%.1f, render %.1f ms median; %dx%d viewport, %d runs)\n",
              grammar.c_str(), dynamic_cast<CpuViewport*>(&viewport) ? "cpu" : "gl", static_cast<unsigned long long>(app.plant()->segments), percentile(total, 0.5),
              percentile(total, 0.9), percentile(total, 1.0), percentile(worker, 0.5), percentile(upload, 0.5),
              percentile(render, 0.5), app.scene().width, app.scene().height, runs);
  std::printf("         %zu of %d first pictures were previews (GL: half size, small shadow map; CPU: the coarse "
              "steps); the finest picture %.1f ms median, %.1f ms p90 after the edit\n",
              previews, runs, percentile(full, 0.5), percentile(full, 0.9));
  std::printf("         UI frames meanwhile: %zu, %.2f ms median, %.2f ms max (the picture is made on the render "
              "thread)\n",
              ui.frame_ms.size(), percentile(ui.frame_ms, 0.5), percentile(ui.frame_ms, 1.0));
  return true;
}

void print_help() {
  std::cout << "usage: sylva bench studio [--quick]\n\n"
               "The studio's speed on this machine, without a window (EGL; llvmpipe without a GPU):\n"
               "edit-to-picture latency for elm and pine (a define moved until the viewport shows the\n"
               "regrown plant), UI frame times while a ~15 M-module derivation runs, and resident\n"
               "memory over 1,000 regrows (--quick: fewer runs, 100 regrows).\n";
}

}  // namespace

int run_bench_studio(const std::vector<std::string>& args) {
  bool quick = false, help = false;
  cli::FlagTable table;
  table.flags = {cli::set_flag({"--quick"}, quick), cli::help_at_once(help)};
  table.unknown = [](const std::string& arg) { throw cli::UsageError{"unknown argument '" + arg + "'"}; };
  cli::parse_flags(std::span(args).subspan(1), table);  // args[0] is "studio"
  if (help) {
    print_help();
    return cli::kOk;
  }
  GlContextResult gl = create_headless_gl_context();
  if (!gl.context) {
    std::cerr << "sylva bench studio: error: no OpenGL 4.5 context: " << gl.error << "\n";
    return cli::kInputError;
  }
  std::printf("renderer: %s\n", gl.context->info().describe().c_str());
  const char* env = std::getenv("SYLVA_PRESETS");
  const std::string presets = env ? env : SYLVA_PRESETS_DIR;
  Ui ui;
  GlViewport viewport;  // its pictures on its own thread; the texture in `gl`

  // 1. Edit-to-picture latency, with the GL viewport and with the CPU one (the studio's
  // choice where GL is a software rasteriser: --backend auto).
  {
    CpuViewport cpu;
    for (Viewport* v : std::initializer_list<Viewport*>{&viewport, &cpu}) {
      if (!latency(ui, *v, presets, "elm.lsys", "TRUNK_H", 3.2, 3.3, quick ? 4 : 20)) return cli::kInternalError;
      if (!latency(ui, *v, presets, "pine.lsys", "BR_LEN", 4.2, 4.3, quick ? 2 : 10)) return cli::kInternalError;
    }
  }

  // 2. Frames while a long derivation runs (Fibonacci words: F(36) = 14,930,352 modules).
  {
    char dir[] = "/tmp/sylva-bench-studio-XXXXXX";
    if (!::mkdtemp(dir)) return cli::kInternalError;
    const std::string path = std::string(dir) + "/fibonacci.lsys";
    if (!write_file_atomically(path, "derivation length: 34\naxiom: A\nproductions:\nA -> AB\nB -> A\n").ok())
      return cli::kInternalError;
    StudioOptions o;
    o.presets_dir = presets;
    StudioApp app(o, &viewport);
    if (app.open(path)) return cli::kInternalError;
    std::vector<double> frames;
    const auto start = Clock::now();
    ui.frame(app);  // the submit
    while (app.worker().busy() || app.worker().result_waiting()) frames.push_back(ui.frame(app));
    const double derive_s = std::chrono::duration<double>(Clock::now() - start).count();
    ui.frame(app);
    std::printf("frames   %llu modules grown in %.2f s behind %zu UI frames: %.2f ms median, %.2f ms p99, %.2f ms max "
                "(target: every frame <= 33 ms)\n",
                static_cast<unsigned long long>(app.plant() ? app.plant()->modules : 0), derive_s, frames.size(),
                percentile(frames, 0.5), percentile(frames, 0.99), percentile(frames, 1.0));
    ::unlink(path.c_str());
    ::rmdir(dir);
  }

  // 3. Memory over many regrows.
  {
    StudioOptions o;
    o.presets_dir = presets;
    o.autosave_s = 1e9;
    StudioApp app(o, &viewport);
    if (app.open(presets + "/elm.lsys")) return cli::kInternalError;
    if (!ui.until(app, [&] { return app.plant_drawn(); })) return cli::kInternalError;
    const int n = quick ? 100 : 1000;
    std::vector<std::pair<int, double>> samples;
    for (int i = 1; i <= n; ++i) {
      const uint64_t before = app.plants_applied();
      app.set_define("TRUNK_H", i % 2 ? 3.3 : 3.2);
      if (!ui.until(app, [&] { return app.plants_applied() > before && app.plant_drawn(); }, 120, 0))
        return cli::kInternalError;
      if (i == 1 || i == n / 10 || i == n / 2 || i == n) samples.emplace_back(i, resident_mib());
    }
    std::printf("memory   elm regrown %d times: resident", n);
    for (const auto& [i, mib] : samples) std::printf("  %.1f MiB after %d", mib, i);
    std::printf("  (growth from the 10%% mark: %+.1f MiB)\n", samples.back().second - samples[1].second);
  }
  return cli::kOk;
}

}  // namespace sylva::studio
