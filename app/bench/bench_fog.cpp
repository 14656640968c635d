// bench_fog.cpp — `sylva bench fog SCENE`: the cost and quality of the fog's
// viewpoint-independent half (sun photons, shadow cones; core/cpu/photons.h) against the
// photon count, each setting with several seeds.
//
// Rows (CSV columns mode,steps,photons,seed,photon_s,cone_s,render_s,total_s,rmse,bias,cones,
// the columns every fog mode's row will have once the fog integrator renders them):
//   cones   photons traced (all threads) and clustered into cones, automatic parameters
//           (or --cone-params); render_s 0, rmse and bias empty.
// A second CSV (STEM.fog-cones.csv) has what the cones measure: the chosen parameters,
// the vectors, how much of the exact shadow they miss and how much lit space they cover
// (ConeCoverage, on random points of the plants' shadow region).
// The photon rate per core: --per-core-photons photons traced on one thread.
// The cone query: for each photon count (seed 1), the scene camera's pixel-centre rays
// (512×384) collect their cone intervals (ConeSet::intervals, the hierarchy), timed on one
// thread: microseconds per camera ray and merged intervals per ray.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <time.h>
#include <vector>

#include "app/bench/bench_metrics.h"
#include "app/cli/cli.h"
#include "app/cli/render_input.h"
#include "core/cpu/photons.h"
#include "core/cpu/render_cpu.h"
#include "core/render_common.h"
#include "core/util/file_io.h"

namespace sylva::cli {

namespace {

void print_help() {
  std::cout << "usage: sylva bench fog SCENE [--photons N,N,...] [--seeds N] [--threads N]\n"
               "                            [--cone-params auto|p1,p2,p3,p4[,threshold]]\n"
               "                            [--per-core-photons N] [--csv FILE] [--quick]\n\n"
               "Cost and quality of the fog's sun photons and shadow cones on SCENE (a scene,\n"
               "grammar or skeleton, as for `sylva render`): for each photon count and seed, the\n"
               "time to trace the photons and to cluster their shadow vectors into cones, the\n"
               "cones made, and how much of the exact shadow the cones miss and how much lit\n"
               "space they cover (random points of the plants' shadow region, exact shadow rays).\n\n"
               "  --photons LIST        photon counts (default 10000,100000,1000000,10000000)\n"
               "  --seeds N             seeds per photon count (default 5)\n"
               "  --threads N           threads (default: every core)\n"
               "  --cone-params P       auto (default: chosen by measurement) or p1,p2,p3,p4 with an\n"
               "                        optional variance threshold\n"
               "  --per-core-photons N  photons of the one-thread rate (default 1000000)\n"
               "  --csv FILE            rows as CSV (default SCENE-stem.fog.csv; the cones' coverage\n"
               "                        goes to the same name with .fog-cones.csv)\n"
               "  --quick               photons 10000,100000, 2 seeds (for tests)\n";
}

struct Args {
  GrammarArgs grammar;
  std::vector<uint64_t> photons = {10'000, 100'000, 1'000'000, 10'000'000};
  uint32_t seeds = 5;
  unsigned threads = 0;
  std::optional<ConeParams> params;
  uint64_t per_core_photons = 1'000'000;
  std::string csv, cones_csv;
  bool quick = false;
};

std::vector<std::string> split(const std::string& text, char by) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, by)) out.push_back(item);
  return out;
}

ConeParams parse_cone_params(const std::string& flag, const std::string& text) {
  const std::vector<std::string> items = split(text, ',');
  if (items.size() != 4 && items.size() != 5)
    throw UsageError{flag + " needs auto or p1,p2,p3,p4[,threshold], not '" + text + "'"};
  ConeParams p;
  uint32_t* fields[4] = {&p.p1, &p.p2, &p.p3, &p.p4};
  for (int i = 0; i < 4; ++i) *fields[i] = parse_count(flag, items[i], 1u << 20);
  if (items.size() == 5) {
    char* end = nullptr;
    p.variance_threshold = std::strtod(items[4].c_str(), &end);
    if (end == items[4].c_str() || *end != '\0') throw UsageError{flag + ": '" + items[4] + "' is not a number"};
  }
  if (const char* e = cone_params_error(p)) throw UsageError{flag + ": " + e};
  return p;
}

Args parse_args(const std::vector<std::string>& args) {
  Args out;
  std::vector<std::string> rest;
  bool photons_given = false, seeds_given = false;
  for (size_t i = 1; i < args.size(); ++i) {  // args[0] is "fog"
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw UsageError{a + " needs a value"};
      return args[++i];
    };
    if (a == "--photons") {
      out.photons.clear();
      for (const std::string& n : split(value(), ',')) {
        const std::optional<uint64_t> v = parse_u64(n);
        if (!v || *v == 0 || *v > 1'000'000'000) throw UsageError{"--photons: '" + n + "' is not a count from 1 to 1e9"};
        out.photons.push_back(*v);
      }
      photons_given = true;
    } else if (a == "--seeds") {
      out.seeds = parse_count(a, value(), 1000);
      seeds_given = true;
    } else if (a == "--threads") {
      out.threads = parse_count(a, value(), 4096);
    } else if (a == "--cone-params") {
      const std::string v = value();
      if (v != "auto") out.params = parse_cone_params(a, v);
    } else if (a == "--per-core-photons") {
      out.per_core_photons = parse_count(a, value(), 1'000'000'000);
    } else if (a == "--csv") {
      out.csv = value();
    } else if (a == "--quick") {
      out.quick = true;
    } else {
      rest.push_back(a);
    }
  }
  out.grammar = parse_grammar_args(rest, false);
  if (out.grammar.help) return out;
  if (!is_render_input(out.grammar.grammar))
    throw UsageError{"SCENE '" + out.grammar.grammar + "' must end in .lsys, .skel.json, .scene.json, .glb or .gltf"};
  if (out.quick) {
    if (!photons_given) out.photons = {10'000, 100'000};
    if (!seeds_given) out.seeds = 2;
    out.per_core_photons = std::min<uint64_t>(out.per_core_photons, 100'000);
  }
  const std::string stem = input_stem(out.grammar.grammar);
  if (out.csv.empty()) out.csv = stem + ".fog.csv";
  const std::string suffix = ".csv";
  out.cones_csv = out.csv.size() > suffix.size() && out.csv.ends_with(suffix)
                      ? out.csv.substr(0, out.csv.size() - suffix.size()) + "-cones.csv"
                      : out.csv + "-cones.csv";
  return out;
}

// CPU time of this process, all threads (seconds): photons and cones in core-seconds,
// which other jobs on a shared machine disturb less than wall time.
double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::string params_text(const ConeParams& p) {
  char line[96];
  std::snprintf(line, sizeof line, "%u;%u;%u;%u;%.3g", p.p1, p.p2, p.p3, p.p4, p.variance_threshold);
  return line;
}

}  // namespace

int run_bench_fog(const std::vector<std::string>& args) {
  const Args a = parse_args(args);
  if (a.grammar.help) {
    print_help();
    return kOk;
  }
  std::vector<RenderPass> passes;
  auto loaded = load_render_input(a.grammar, std::nullopt, std::nullopt, passes);
  if (auto* code = std::get_if<ExitCode>(&loaded)) return *code;
  const Scene scene = std::move(std::get<Scene>(loaded));
  const unsigned threads = a.threads ? a.threads : std::max(1u, std::thread::hardware_concurrency());
  GeometryOptions geometry;
  geometry.cull = false;     // a plant outside the view still casts shafts into it
  geometry.relief = false;   // photons trace the exact frusta
  const SceneGeometry g = build_scene_geometry(scene, {}, geometry);
  std::cerr << "sylva bench fog: " << a.grammar.grammar << ", " << g.frusta.size() << " frusta, " << threads
            << " threads\n";

  // The plants as the photons see them, built once for every photon count and seed.
  const SunPhotonTracer tracer(g.frusta, scene.sun, threads);
  std::printf("photon tracer: accelerator and occupancy mask built in %.3f s\n", tracer.build_seconds());
  // The photon rate of one core.
  {
    SunPhotonOptions o;
    o.photons = a.per_core_photons;
    o.threads = 1;
    const SunPhotons p = tracer.trace(o);
    std::printf("photons on 1 thread: %llu in %.3f s wall, %.3f s CPU = %.3g M photons/s per core (CPU time), "
                "%zu shadow vectors (%.1f%%)\n",
                static_cast<unsigned long long>(p.traced), p.seconds, p.cpu_seconds, p.traced / p.cpu_seconds * 1e-6,
                p.vectors.vectors.size(), 100.0 * p.vectors.vectors.size() / std::max<uint64_t>(1, p.traced));
  }

  std::ostringstream csv, cones_csv;
  csv << "# sylva bench fog " << a.grammar.grammar << ", " << threads << " threads\n";
  csv << "mode,steps,photons,seed,photon_s,cone_s,render_s,total_s,rmse,bias,cones\n";
  cones_csv << "# sylva bench fog " << a.grammar.grammar << ", " << threads << " threads\n";
  cones_csv << "photons,seed,photon_s,cone_s,params_s,cpu_s,params,vectors,covered,cones,missed_shadow,covered_lit,"
               "coverage_points,shadowed_points\n";
  std::printf("%10s %5s %9s %9s %9s %9s %8s %9s %9s %8s %8s  %s\n", "photons", "seed", "photon_s", "cone_s",
              "params_s", "cpu_s", "vectors", "covered", "cones", "missed", "lit_cov", "params");
  for (uint64_t photons : a.photons)
    for (uint32_t seed = 1; seed <= a.seeds; ++seed) {
      SunConeOptions o;
      o.photons.photons = photons;
      o.photons.seed = seed;
      o.photons.threads = threads;
      o.params = a.params;
      const double cpu_start = process_cpu_seconds();
      const auto c = build_sun_cones(g, scene, o, &tracer);
      const double cpu_s = process_cpu_seconds() - cpu_start;
      double params_s = 0;
      for (const RenderPass& p : c->passes)
        if (p.name == "cone params") params_s = p.seconds;
      const ConeCoverage cov = c->coverage.value_or(ConeCoverage{});
      char line[512];
      std::snprintf(line, sizeof line, "cones,0,%llu,%u,%.6g,%.6g,0,%.6g,,,%zu\n", static_cast<unsigned long long>(photons),
                    seed, c->photon_seconds, c->cone_seconds, c->photon_seconds + c->cone_seconds, c->cones.size());
      csv << line;
      std::snprintf(line, sizeof line, "%llu,%u,%.6g,%.6g,%.6g,%.6g,%s,%llu,%llu,%zu,%.6g,%.6g,%llu,%llu\n",
                    static_cast<unsigned long long>(photons), seed, c->photon_seconds, c->cone_seconds, params_s, cpu_s,
                    params_text(c->params).c_str(), static_cast<unsigned long long>(c->cluster.vectors),
                    static_cast<unsigned long long>(c->cluster.covered), c->cones.size(), cov.missed_shadow,
                    cov.covered_lit, static_cast<unsigned long long>(cov.points),
                    static_cast<unsigned long long>(cov.shadowed));
      cones_csv << line;
      std::printf("%10llu %5u %9.4f %9.4f %9.4f %9.4f %8llu %9llu %9zu %8.4f %8.4f  %s\n",
                  static_cast<unsigned long long>(photons), seed, c->photon_seconds, c->cone_seconds, params_s, cpu_s,
                  static_cast<unsigned long long>(c->cluster.vectors),
                  static_cast<unsigned long long>(c->cluster.covered), c->cones.size(), cov.missed_shadow,
                  cov.covered_lit, params_text(c->params).c_str());
      std::fflush(stdout);
      if (seed == 1 && c->automatic) std::cerr << c->automatic->describe();
      if (seed == 1) {
        // The camera's rays against the cones, one thread.
        Scene view = scene;
        view.width = 512;
        view.height = 384;
        std::vector<ConeInterval> intervals;
        uint64_t total = 0;
        const auto start = render_common::Clock::now();
        for (uint32_t y = 0; y < view.height; ++y)
          for (uint32_t x = 0; x < view.width; ++x) {
            c->cones.intervals(camera_ray(view, x + 0.5, y + 0.5), 0, 1e30, &intervals);
            total += intervals.size();
          }
        const double seconds = render_common::seconds_since(start);
        const double rays = double(view.width) * view.height;
        std::printf("%10s cone query: %.3g us per camera ray (512x384, 1 thread), %.3g intervals per ray, "
                    "%zu cones, hierarchy depth %u\n",
                    "", seconds / rays * 1e6, total / rays, c->cones.size(), c->cones.depth());
      }
    }
  for (const auto& [path, text] : {std::pair{a.csv, csv.str()}, std::pair{a.cones_csv, cones_csv.str()}}) {
    if (Status e = write_file_atomically(path, text); !e) {
      std::cerr << e.error().format();
      return kInputError;
    }
  }
  std::cerr << "sylva bench fog: wrote " << a.csv << " and " << a.cones_csv << "\n";
  return kOk;
}

}  // namespace sylva::cli
