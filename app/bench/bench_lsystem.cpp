// bench_lsystem.cpp — `sylva bench lsystem`: derivation and turtle throughput.
//
// Measures, with Google Benchmark on one thread: (a) ABOP 1.24a to >= 10 M modules
// (context-free, no parameters), (b) Honda's tree (ABOP 2.6, parametric) to >= 1 M
// modules, (c) ABOP 1.31a (context-sensitive), turtle interpretation (segments/s), peak
// bytes per module, and memcpy bandwidth in the same run, so each throughput can be read
// as a fraction of what the memory system can move. Throughput counts every module
// produced by every step (the work done), not only the final word.
#include <benchmark/benchmark.h>
#include <unistd.h>


#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "app/bench/bench_lsystem_scaling.h"
#include "app/bench/bench.h"
#include "core/grow/turtle.h"
#include "core/grow/grow.h"

namespace sylva::cli {

namespace {

struct Case {
  std::string name;
  std::string preset;
  int64_t steps;
  lsys::Grammar grammar;
  uint64_t produced = 0;  // modules produced over all steps
  uint64_t final_modules = 0;
  uint64_t peak_bytes = 0;
};

// Sums the sizes of the words after each step (the modules the engine wrote).
uint64_t modules_produced(const lsys::Grammar& g, int64_t steps) {
  uint64_t total = 0;
  for (int64_t s = 1; s <= steps; ++s) {
    lsys::DeriveOptions o;
    o.steps = s;
    auto w = lsys::derive(g, o);
    if (!w) return 0;
    total += w->size();
  }
  return total;
}

// Smallest step count at which the grammar's word reaches `target` modules.
int64_t steps_to_reach(const lsys::Grammar& g, uint64_t target, int64_t max_steps) {
  lsys::DeriveOptions o;
  for (int64_t s = 1; s <= max_steps; ++s) {
    o.steps = s;
    auto w = lsys::derive(g, o);
    if (!w || w->size() >= target) return s;
  }
  return max_steps;
}

// Colour codes only on a terminal: a benchmark's output piped to a file or a CI log must
// be plain text (Google Benchmark's own --benchmark_color does not reach a reporter made
// here, whose default is colour always).
class CapturingReporter : public benchmark::ConsoleReporter {
 public:
  CapturingReporter() : ConsoleReporter(isatty(STDOUT_FILENO) ? OO_ColorTabular : OO_Tabular) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.run_type == Run::RT_Iteration || r.aggregate_name == "median")
        seconds_[r.benchmark_name()] = r.GetAdjustedRealTime() / benchmark::GetTimeUnitMultiplier(r.time_unit);
    }
    ConsoleReporter::ReportRuns(runs);
  }
  double seconds(const std::string& name) const {
    auto it = seconds_.find(name);
    return it == seconds_.end() ? 0 : it->second;
  }

 private:
  std::map<std::string, double> seconds_;
};

void print_lsystem_help() {
  std::cout << "usage: sylva bench lsystem [--quick] [--presets DIR] [Google Benchmark flags]\n\n"
               "Derivation throughput (modules produced per second, one thread) for ABOP 1.24a,\n"
               "Honda's tree (ABOP 2.6) and ABOP 1.31a from DIR (default: the presets); turtle\n"
               "segments per second; peak bytes per module; memcpy bandwidth in the same run;\n"
               "scaling/* rows: the work bounds of docs/limits.md at doubling sizes (time per\n"
               "item, complexity fit). --quick uses small sizes (a smoke test, not a measurement). --benchmark_* flags\n"
               "(e.g. --benchmark_filter=REGEX) go to Google Benchmark.\n";
}

}  // namespace

int run_bench(const std::vector<std::string>& args) {
  if (args.empty() || args[0] == "-h" || args[0] == "--help") {
    std::cout << "usage: sylva bench lsystem [--quick] [--presets DIR] [Google Benchmark flags]\n"
                 "       sylva bench raycast [PRESET] [--width W --height H] [--csv FILE] [--quick]\n"
                 "       sylva bench geometry INPUT [--width W --height H] [--csv FILE] [--plot FILE] [--quick]\n"
                 "       sylva bench gpu [INPUT...] [--width W --height H] [--frames N] [--methods LIST]\n"
                 "                       [--csv FILE] [--plot FILE] [--quick]\n"
                 "       sylva bench fog SCENE [--photons LIST] [--seeds N] [--csv FILE] [--quick]\n"
                 "       sylva bench spp [INPUT...] [--spp LIST] [--backends cpu,gl] [--csv FILE] [--quick]\n"
                 "       sylva bench light [--threads N] [--csv FILE] [--plot FILE] [--quick]\n"
                 "       sylva bench export [INPUT...] [--scatter N] [--csv FILE] [--quick]\n\n"
                 "Derivation throughput (modules produced per second, one thread) for ABOP 1.24a,\n"
                 "Honda's tree (ABOP 2.6) and ABOP 1.31a; turtle segments per second; peak bytes\n"
                 "per module; memcpy bandwidth in the same run. --quick uses small sizes (a smoke\n"
                 "test, not a measurement).\n"
                 "raycast: primary rays per second on a preset (default pine, 1024x768), sylva's BVH\n"
                 "and analytic frusta against Embree user geometry, round curves and tessellated\n"
                 "meshes, on one thread and all threads, with depth error and bytes per segment.\n"
                 "geometry: error against run time of analytic frusta, relief mapping and meshes\n"
                 "(CSV and a log-log plot); `sylva bench geometry --help` for details.\n"
                 "gpu: GPU time per frame (timer queries) and error of the GL backend's ray casting,\n"
                 "relief mapping, meshes and animated skeletons, at 1024x768 and 1920x1080 (CSV and\n"
                 "a log-log plot); `sylva bench gpu --help` for details.\n"
                 "fog: sun photons and shadow cones (time, cones, the shadow they miss and the lit\n"
                 "space they cover) against the photon count; `sylva bench fog --help` for details.\n"
                 "spp: the sampling error (speckle, RMSE) of both backends against the samples per\n"
                 "pixel, at 800x600 on the pine and the elm; `sylva bench spp --help` for details.\n"
                 "light: the ?E light's error against closed forms and time against photons, and one\n"
                 "answer on the pine and a 10-pine stand; `sylva bench light --help` for details.\n"
                 "export: CPU time and bytes of the glTF variants for engines (rig, wind clip, wind\n"
                 "data, levels of detail) and an instanced scatter; `sylva bench export --help`.\n";
    return args.empty() ? kUsageError : kOk;
  }
  if (args[0] == "raycast") return run_bench_raycast(args);
  if (args[0] == "geometry") return run_bench_geometry(args);
  if (args[0] == "gpu") return run_bench_gpu(args);
  if (args[0] == "fog") return run_bench_fog(args);
  if (args[0] == "spp") return run_bench_spp(args);
  if (args[0] == "light") return run_bench_light(args);
  if (args[0] == "export") return run_bench_export(args);
  if (args[0] != "lsystem")
    throw UsageError{"unknown benchmark '" + args[0] + "' (available: lsystem, raycast, geometry, gpu, fog, spp, light, export)"};
  bool quick = false;
  std::string presets = SYLVA_PRESETS_DIR;
  std::vector<std::string> gb_args = {"sylva-bench"};
  bool help = false;
  FlagTable table;
  Flag presets_dir = text_flag({"--presets"}, presets);
  presets_dir.claims = [](const std::string&) { return true; };  // given last: an unknown option
  table.flags = {help_at_once(help), set_flag({"--quick"}, quick), presets_dir};
  table.unknown = [&gb_args](const std::string& arg) {
    if (!arg.starts_with("--benchmark_")) throw UsageError{"unknown option '" + arg + "'"};
    gb_args.push_back(arg);
  };
  parse_flags(std::span(args).subspan(1), table);  // args[0] is "lsystem"
  if (help) {
    print_lsystem_help();
    return kOk;
  }
  auto load = [&](const std::string& file) -> std::optional<lsys::Grammar> {
    auto g = lsys::load_grammar(presets + "/" + file);
    if (!g) {
      std::cerr << g.error().format();
      return std::nullopt;
    }
    return std::move(*g);
  };
  const uint64_t target_a = quick ? 100'000 : 10'000'000;
  const uint64_t target_b = quick ? 10'000 : 1'000'000;
  std::vector<Case> cases;
  {
    auto g = load("abop_1_24a.lsys");
    if (!g) return kInputError;
    int64_t n = steps_to_reach(*g, target_a, 40);
    cases.push_back({"derive/a_abop_1_24a", "abop_1_24a.lsys", n, std::move(*g)});
  }
  {
    auto g = load("abop_2_6_honda.lsys");
    if (!g) return kInputError;
    int64_t n = steps_to_reach(*g, target_b, 60);
    cases.push_back({"derive/b_honda_2_6", "abop_2_6_honda.lsys", n, std::move(*g)});
  }
  {
    auto g = load("abop_1_31a_context.lsys");
    if (!g) return kInputError;
    int64_t n = steps_to_reach(*g, target_b, 400);
    cases.push_back({"derive/c_abop_1_31a", "abop_1_31a_context.lsys", n, std::move(*g)});
  }
  {
    // Honda's tree written as a cpfg model file, its productions with statements (docs/cpfg.md):
    // beside derive/b_honda_2_6, what the statements and the globals cost.
    auto g = load("cpfg/abop_2_6_honda.l");
    if (!g) return kInputError;
    int64_t n = steps_to_reach(*g, target_b, 60);
    cases.push_back({"derive/d_honda_cpfg_statements", "cpfg/abop_2_6_honda.l", n, std::move(*g)});
  }
  for (Case& c : cases) {
    c.produced = modules_produced(c.grammar, c.steps);
    lsys::DeriveOptions o;
    o.steps = c.steps;
    lsys::DeriveStats st;
    auto w = lsys::derive(c.grammar, o, &st);
    if (!w) {
      std::cerr << w.error().format();
      return kInputError;
    }
    c.final_modules = w->size();
    c.peak_bytes = st.peak_bytes;
  }

  // memcpy bandwidth: large buffers, well past the caches.
  const size_t copy_bytes = quick ? (8u << 20) : (256u << 20);
  std::unique_ptr<char[]> src(new char[copy_bytes]), dst(new char[copy_bytes]);
  std::memset(src.get(), 1, copy_bytes);
  std::memset(dst.get(), 2, copy_bytes);
  benchmark::RegisterBenchmark("memcpy", [&](benchmark::State& state) {
    for (auto _ : state) {
      std::memcpy(dst.get(), src.get(), copy_bytes);
      benchmark::ClobberMemory();
    }
    state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * copy_bytes));
  })->Unit(benchmark::kMillisecond)->UseRealTime();

  for (Case& c : cases) {
    benchmark::RegisterBenchmark(c.name.c_str(), [&c](benchmark::State& state) {
      lsys::DeriveOptions o;
      o.steps = c.steps;
      for (auto _ : state) {
        auto w = lsys::derive(c.grammar, o);
        benchmark::DoNotOptimize(w->size());
      }
      state.counters["modules/s"] = benchmark::Counter(static_cast<double>(c.produced),
                                                       benchmark::Counter::kIsIterationInvariantRate);
    })->Unit(benchmark::kMillisecond)->UseRealTime();
  }

  // Turtle: interpret Honda's tree and ABOP 1.24a (one step below the derivation size).
  struct TurtleCase {
    std::string name;
    lsys::Word word;
    const lsys::Grammar* grammar;
    uint64_t segments = 0;
  };
  std::vector<TurtleCase> turtles;
  for (int k : {0, 1}) {
    lsys::DeriveOptions o;
    o.steps = cases[k].steps - (k == 0 ? 1 : 0);
    auto w = lsys::derive(cases[k].grammar, o);
    auto sk = build_skeleton(*w, cases[k].grammar);
    if (!sk) {
      std::cerr << sk.error().format();
      return kInputError;
    }
    turtles.push_back({"turtle/" + cases[k].name.substr(7), std::move(*w), &cases[k].grammar, sk->segment_count()});
  }
  for (TurtleCase& t : turtles) {
    benchmark::RegisterBenchmark(t.name.c_str(), [&t](benchmark::State& state) {
      for (auto _ : state) {
        auto sk = build_skeleton(t.word, *t.grammar);
        benchmark::DoNotOptimize(sk->joints.data());
      }
      state.counters["segments/s"] = benchmark::Counter(static_cast<double>(t.segments),
                                                        benchmark::Counter::kIsIterationInvariantRate);
    })->Unit(benchmark::kMillisecond)->UseRealTime();
  }

  register_lsystem_scaling_benchmarks(quick);

  int gb_argc = static_cast<int>(gb_args.size());
  std::vector<char*> gb_argv;
  for (std::string& s : gb_args) gb_argv.push_back(s.data());
  benchmark::Initialize(&gb_argc, gb_argv.data());
  if (gb_argc > 1) throw UsageError{"unknown option '" + std::string(gb_argv[1]) + "'"};
  CapturingReporter reporter;
  const size_t ran = benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  if (ran == 0) throw UsageError{"no benchmark matches the --benchmark_filter given"};

  const double memcpy_s = reporter.seconds("memcpy/real_time");
  const double bandwidth = memcpy_s > 0 ? static_cast<double>(copy_bytes) / memcpy_s : 0;
  std::printf("\nsummary (one thread%s)\n", quick ? ", --quick sizes: not a measurement" : "");
  std::printf("memcpy bandwidth: %.2f GB/s\n", bandwidth / 1e9);
  std::printf("%-22s %6s %12s %14s %12s %10s %13s\n", "case", "steps", "final", "produced", "Mmodules/s",
              "B/module", "of memcpy");
  for (const Case& c : cases) {
    double s = reporter.seconds(c.name + "/real_time");
    double rate = s > 0 ? static_cast<double>(c.produced) / s : 0;
    // Bytes the engine writes per produced module: the 8-byte record plus its parameters.
    double bytes_per_module = static_cast<double>(c.peak_bytes) / static_cast<double>(c.final_modules);
    double written = rate * 8.0;
    std::printf("%-22s %6" PRId64 " %12" PRIu64 " %14" PRIu64 " %12.1f %10.1f %12.1f%%\n", c.name.c_str(), c.steps,
                c.final_modules, c.produced, rate / 1e6, bytes_per_module,
                bandwidth > 0 ? 100.0 * written / bandwidth : 0.0);
  }
  for (const TurtleCase& t : turtles) {
    double s = reporter.seconds(t.name + "/real_time");
    std::printf("%-22s %6s %12" PRIu64 " segments %20.1f Msegments/s\n", t.name.c_str(), "", t.segments,
                s > 0 ? static_cast<double>(t.segments) / s / 1e6 : 0.0);
  }
  std::printf("(B/module: peak bytes of the word buffers over the final word's modules; 'of memcpy':\n"
              " module records written per second x 8 bytes, over memcpy bandwidth)\n");
  return kOk;
}

}  // namespace sylva::cli
