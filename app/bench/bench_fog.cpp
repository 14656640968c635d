// bench_fog.cpp — `sylva bench fog SCENE`: error against run time of the fog modes of
// docs/spec/fog.md (brute, medium, fast, refined) against the converged `reference`, with the
// cost and quality of the sun photons and shadow cones they use (core/cpu/photons.h), each
// setting with several seeds.
//
// What is measured: the fog AOV's in-scatter (fog.R fog.G fog.B, linear RGB) through each
// pixel's centre, as render_cpu computes it (FogIntegrator::integrate up to the first
// plant or the ground, the scene camera), at --width × --height. Plants are the exact
// frusta (no relief: the same for every mode and the reference). The surfaces' shading is
// not part of it: only the fog integral is timed (render_s: the fog of every pixel, wall,
// on --threads threads); photon_s and cone_s are the cones' (build_sun_cones), built once
// per (photon count, cone parameters, seed) and reused by every mode and step count, the
// paper's point (the photon tracer's accelerator and mask, built once per scene and sun,
// are reported apart).
//
// Rows (CSV mode,steps,photons,seed,photon_s,cone_s,render_s,total_s,rmse,bias,cones):
//   cones-auto, cones-fixed  the photons and cones alone (render_s 0, rmse and bias empty);
//   brute     --brute-steps, no cones;
//   medium, refined  --cone-steps × --photons × {auto, fixed} cone parameters ("auto"
//             or "fixed" follows the mode's name: medium-auto, refined-fixed, ...);
//   fast      --photons × {auto, fixed} (steps 0: no samples).
// rmse: over pixels and channels against the reference; bias: the same for the mean
// image of the setting's seeds (what more seeds cannot remove; fast mode's floor). With
// --reference-stride S the reference is computed, and both measured, on every S-th pixel
// each way only (a uniform grid of the image: the same RMSE in expectation); every mode
// still renders every pixel, so its times are the whole image's.
// Outputs: the CSV, STEM.fog-cones.csv (the cones' coverage of the exact shadow), a
// log-log plot of RMSE against total time (the plot module), and on stdout the time each
// family needs to reach given RMSEs (interpolated on its fastest settings, log-log) and
// fast mode's bias floor. On stderr, a progress line per row with an estimate of the time
// left, and a line every 30 s within a long row (the reference) (bench_rows.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>
#include <unistd.h>

#include "app/bench/bench_metrics.h"
#include "app/bench/bench_rows.h"
#include "app/bench/fog_view.h"
#include "app/bench/plot.h"
#include "app/bench/bench.h"
#include "app/front/render_input.h"
#include "core/cpu/photons.h"
#include "core/cpu/render_cpu.h"
#include "core/cpu/sun_maps.h"
#include "core/scene/fog_integrator.h"
#include "core/scene/render_common.h"
#include "core/light/shading.h"
#include "core/util/file_io.h"
#include "core/util/random.h"
#include "core/util/clock.h"
#include "core/util/parallel.h"

namespace sylva::cli {

namespace {

void print_help() {
  std::cout << "usage: sylva bench fog SCENE [--modes LIST] [--brute-steps LIST] [--cone-steps LIST]\n"
               "                            [--photons LIST] [--seeds N] [--width W --height H]\n"
               "                            [--reference-steps N] [--reference-stride S]\n"
               "                            [--fixed-params p1,p2,p3,p4[,t]]\n"
               "                            [--threads N] [--per-core-photons N] [--cones-only]\n"
               "                            [--clock wall|cpu] [--merge FILE.csv]...\n"
               "                            [--csv FILE] [--plot FILE.png] [--quick]\n\n"
               "Error against run time of the fog modes on SCENE (a scene with a `fog` key): the fog\n"
               "AOV's in-scatter through every pixel centre by brute, medium, fast and refined,\n"
               "against the reference mode; each setting with --seeds seeds; the shadow cones built\n"
               "once per photon count, cone parameters (automatic and fixed) and seed, and reused by\n"
               "every mode. Prints the time each mode needs to reach given RMSEs and fast mode's bias\n"
               "floor; writes the rows as CSV, the cones' coverage as CSV, and a log-log plot.\n\n"
               "  --modes LIST          of brute,medium,fast,refined,map (default all five)\n"
               "  --brute-steps LIST    brute's samples per ray (default 8,16,32,64,128,256,512,1024)\n"
               "  --cone-steps LIST     medium's and refined's (default 16,64,256)\n"
               "  --photons LIST        photon counts (default 10000,100000,1000000,10000000)\n"
               "  --seeds N             seeds per setting (default 5)\n"
               "  --width W, --height H pixels (default 512x384)\n"
               "  --reference-steps N   the reference's steps (default 64: 512 probes per disc point)\n"
               "  --reference-stride S  the reference, and the errors, on every S-th pixel each way\n"
               "                        (default 1: every pixel); the modes still render them all\n"
               "  --fixed-params P      the fixed cone parameters (default 96,8,24,16,2.5)\n"
               "  --threads N           threads (default: every core)\n"
               "  --per-core-photons N  photons of the one-thread photon rate (default 1000000)\n"
               "  --cones-only          photons and cones only, no fog rows\n"
               "  --map-resolutions L   map mode's texels a side (default 1024,2048,4096); its rows\n"
               "                        are mapK (K maps over the sun's disc, as the renderer runs\n"
               "                        it: the photons find the tiles, no cones), steps = the\n"
               "                        resolution, cone_s = the maps' build\n"
               "  --map-directions L    map mode's disc directions (default 1,4)\n"
               "  --map-memory-mib N    the maps' memory limit (default 1024)\n"
               "  --map-dilate N        tiles of margin around each shadow vector's tile (default 1)\n"
               "  --map-variants        also the variants docs/fog-map.md measured: maprayK (one map\n"
               "                        per camera ray) and mapconesK-auto/-fixed (only the cone\n"
               "                        intervals walked; cone_s = cones + maps)\n"
               "  --csv FILE            rows (default SCENE-stem.fog.csv; the cones' coverage in\n"
               "                        the same name with -cones.csv)\n"
               "  --plot FILE           log-log RMSE against time (default SCENE-stem.fog.png)\n"
               "  --clock wall|cpu      times as wall seconds (default), or as the process's CPU\n"
               "                        seconds divided by the threads: what two idle cores would\n"
               "                        take, for a machine shared with other jobs\n"
               "  --merge FILE.csv      rows of an earlier run (the same scene, size, threads, clock\n"
               "                        and reference) join this run's tables, plot and CSV; a\n"
               "                        setting this run measures replaces that file's rows of it\n"
               "  --quick               a smoke test: 64x48, brute 8,32, cone steps 16, photons\n"
               "                        10000,100000, 2 seeds, reference steps 8\n";
}

struct Args {
  GrammarArgs grammar;
  std::vector<std::string> modes = {"brute", "medium", "fast", "refined", "map"};
  std::vector<uint32_t> brute_steps = {8, 16, 32, 64, 128, 256, 512, 1024};
  std::vector<uint32_t> cone_steps = {16, 64, 256};
  std::vector<uint64_t> photons = {10'000, 100'000, 1'000'000, 10'000'000};
  uint32_t seeds = 5;
  uint32_t width = 512, height = 384;
  uint32_t reference_steps = 64;
  uint32_t reference_stride = 1;
  ConeParams fixed_params;
  unsigned threads = 0;
  uint64_t per_core_photons = 1'000'000;
  bool cones_only = false;
  std::vector<uint32_t> map_resolutions = {1024, 2048, 4096};
  std::vector<uint32_t> map_directions = {1, 4};
  uint64_t map_memory_mib = 1024;
  uint32_t map_dilate = SunMapOptions{}.dilate_tiles;
  bool map_variants = false;
  std::string csv, cones_csv, plot;
  bool quick = false;
  bool cpu_clock = false;           // --clock cpu
  std::vector<std::string> merge;  // --merge FILE, in order
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
    throw UsageError{flag + " needs p1,p2,p3,p4[,threshold], not '" + text + "'"};
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

std::vector<uint32_t> parse_counts(const std::string& flag, const std::string& text, uint64_t max) {
  std::vector<uint32_t> out;
  for (const std::string& n : split(text, ',')) out.push_back(parse_count(flag, n, max));
  if (out.empty()) throw UsageError{flag + " needs at least one value"};
  return out;
}

Args parse_args(const std::vector<std::string>& args) {
  Args out;
  bool photons_given = false, seeds_given = false, brute_given = false, cone_given = false, size_given = false,
       reference_given = false, map_given = false;
  FlagTable table;
  table.leaves_others = true;  // SCENE and the grammar flags: parse_grammar_args's
  table.flags = {
      noting_given(value_flag({"--photons"},
                              [&out](const std::string&, const std::string& list) {
                                out.photons.clear();
                                for (const std::string& n : split(list, ',')) {
                                  const std::optional<uint64_t> v = parse_u64(n);
                                  if (!v || *v == 0 || *v > 1'000'000'000)
                                    throw UsageError{"--photons: '" + n + "' is not a count from 1 to 1e9"};
                                  out.photons.push_back(*v);
                                }
                              }),
                   photons_given),
      value_flag({"--modes"},
                 [&out](const std::string&, const std::string& list) {
                   out.modes = split(list, ',');
                   for (const std::string& m : out.modes)
                     if (m != "brute" && m != "medium" && m != "fast" && m != "refined" && m != "map")
                       throw UsageError{"--modes: '" + m + "' is not one of brute, medium, fast, refined, map"};
                 }),
      noting_given(value_flag({"--brute-steps"},
                              [&out](const std::string& spelled, const std::string& v) {
                                out.brute_steps = parse_counts(spelled, v, 65536);
                              }),
                   brute_given),
      noting_given(value_flag({"--cone-steps"},
                              [&out](const std::string& spelled, const std::string& v) {
                                out.cone_steps = parse_counts(spelled, v, 65536);
                              }),
                   cone_given),
      noting_given(count_flag({"--seeds"}, out.seeds, 1000), seeds_given),
      noting_given(count_flag({"--width"}, out.width, 16384), size_given),
      noting_given(count_flag({"--height"}, out.height, 16384), size_given),
      noting_given(count_flag({"--reference-steps"}, out.reference_steps, 65536), reference_given),
      count_flag({"--reference-stride"}, out.reference_stride, 1024),
      value_flag({"--fixed-params", "--cone-params"},
                 [&out](const std::string& spelled, const std::string& v) {
                   out.fixed_params = parse_cone_params(spelled, v);
                 }),
      count_flag({"--threads"}, out.threads, 4096),
      count_flag({"--per-core-photons"}, out.per_core_photons, 1'000'000'000),
      set_flag({"--cones-only"}, out.cones_only),
      noting_given(value_flag({"--map-resolutions"},
                 [&out](const std::string& spelled, const std::string& v) {
                   out.map_resolutions = parse_counts(spelled, v, kFogMaxMapResolution);
                   for (uint32_t n : out.map_resolutions)
                     if (n < kFogMinMapResolution || n % 32 != 0)
                       throw UsageError{spelled + ": " + std::to_string(n) + " is not a multiple of 32 from " +
                                        std::to_string(kFogMinMapResolution) + " to " +
                                        std::to_string(kFogMaxMapResolution)};
                 }), map_given),
      value_flag({"--map-directions"},
                 [&out](const std::string& spelled, const std::string& v) {
                   out.map_directions = parse_counts(spelled, v, kFogMaxMapDirections);
                 }),
      count_flag({"--map-memory-mib"}, out.map_memory_mib, 1 << 20),
      value_flag({"--map-dilate"},
                 [&out](const std::string& spelled, const std::string& v) {
                   const std::optional<uint64_t> n = parse_u64(v);
                   if (!n || *n > 8) throw UsageError{spelled + " " + v + ": expected an integer from 0 to 8"};
                   out.map_dilate = static_cast<uint32_t>(*n);
                 }),
      set_flag({"--map-variants"}, out.map_variants),
      text_flag({"--csv"}, out.csv),
      text_flag({"--plot"}, out.plot),
      set_flag({"--quick"}, out.quick),
      value_flag({"--clock"},
                 [&out](const std::string&, const std::string& v) {
                   if (v != "wall" && v != "cpu") throw UsageError{"--clock: '" + v + "' is not wall or cpu"};
                   out.cpu_clock = v == "cpu";
                 }),
      value_flag({"--merge"}, [&out](const std::string&, const std::string& v) { out.merge.push_back(v); }),
  };
  const std::vector<std::string> rest = parse_flags(std::span(args).subspan(1), table);  // args[0] is "fog"
  out.grammar = parse_grammar_args(rest);
  if (out.grammar.help) return out;
  if (!is_render_input(out.grammar.grammar))
    throw UsageError{"SCENE '" + out.grammar.grammar + "' must end in .lsys, .skel.json, .scene.json, .glb or .gltf"};
  if (out.quick) {
    if (!photons_given) out.photons = {10'000, 100'000};
    if (!seeds_given) out.seeds = 2;
    if (!brute_given) out.brute_steps = {8, 32};
    if (!cone_given) out.cone_steps = {16};
    if (!map_given) out.map_resolutions = {256};
    if (!size_given) out.width = 64, out.height = 48;
    if (!reference_given) out.reference_steps = 8;
    out.per_core_photons = std::min<uint64_t>(out.per_core_photons, 100'000);
  }
  const std::string stem = input_stem(out.grammar.grammar);
  if (out.csv.empty()) out.csv = stem + ".fog.csv";
  if (out.plot.empty()) out.plot = stem + ".fog.png";
  const std::string suffix = ".csv";
  out.cones_csv = out.csv.size() > suffix.size() && out.csv.ends_with(suffix)
                      ? out.csv.substr(0, out.csv.size() - suffix.size()) + "-cones.csv"
                      : out.csv + "-cones.csv";
  return out;
}

std::string params_text(const ConeParams& p) {
  char line[96];
  std::snprintf(line, sizeof line, "%u;%u;%u;%u;%.3g", p.p1, p.p2, p.p3, p.p4, p.variance_threshold);
  return line;
}

// Over `pixels` (of `a`, RGB) against `reference` (RGB, one per pixel in that order).
template <typename T>
double rmse(const std::vector<T>& a, const std::vector<double>& reference, const std::vector<size_t>& pixels) {
  return rmse_at(a, 3, reference, pixels);
}

// One row of the CSV, and the setting it belongs to.
struct Row {
  std::string mode;  // brute, medium-auto, ...
  uint32_t steps = 0;
  uint64_t photons = 0;
  uint32_t seed = 0;
  double photon_s = 0, cone_s = 0, render_s = 0, total_s = 0, rmse = -1, bias = -1;
  size_t cones = 0;
  bool merged = false;  // from a --merge file: its bias is that run's
  std::string setting() const { return mode + "/" + std::to_string(steps) + "/" + std::to_string(photons); }
};

// A setting's mean over its seeds.
struct Point {
  double time = 0, rmse = 0;
};

// The time a family's settings need to reach `target` RMSE: on the fastest settings (the
// frontier of mean time against mean RMSE), interpolated log-log between the last point
// above the target and the first at or below it; negative where none reaches it.
double time_to_reach(std::vector<Point> points, double target) {
  std::sort(points.begin(), points.end(), [](const Point& a, const Point& b) { return a.time < b.time; });
  std::vector<Point> frontier;
  for (const Point& p : points)
    if (frontier.empty() || p.rmse < frontier.back().rmse) frontier.push_back(p);
  for (size_t i = 0; i < frontier.size(); ++i) {
    if (frontier[i].rmse > target) continue;
    if (i == 0) return frontier[0].time;
    const Point &a = frontier[i - 1], &b = frontier[i];
    const double f = (std::log(target) - std::log(a.rmse)) / (std::log(b.rmse) - std::log(a.rmse));
    return std::exp(std::log(a.time) + f * (std::log(b.time) - std::log(a.time)));
  }
  return -1;
}

// The rows of an earlier run's CSV (`path`), which must have been written with `header`
// (scene, size, threads, clock and reference) as its first line.
Expected<std::vector<Row>> read_rows(const std::string& path, const std::string& header) {
  auto text = read_text_file(path);
  if (!text) return text.error();
  std::istringstream in(*text);
  std::string line;
  std::vector<Row> rows;
  uint32_t number = 0;
  auto at = [&](uint32_t column, const std::string& why) { return diagnostic_at(path, {number, column}, why); };
  while (std::getline(in, line)) {
    ++number;
    if (number == 1) {
      if (line + "\n" != header)
        return at(1, "was written by another run setting ('" + line + "'; this run's: '" +
                         header.substr(0, header.size() - 1) + "'): scene, size, threads, clock and reference must agree");
      continue;
    }
    if (number == 2 || line.empty()) continue;  // the column names
    const std::vector<std::string> f = split(line, ',');
    if (f.size() < 9 || f.size() > 11) return at(1, "expected 11 columns, found " + std::to_string(f.size()));
    std::vector<double> v(11, -1);
    uint32_t column = 1;
    for (size_t k = 0; k < f.size(); column += static_cast<uint32_t>(f[k].size()) + 1, ++k) {
      if (k == 0 || f[k].empty()) continue;
      char* end = nullptr;
      v[k] = std::strtod(f[k].c_str(), &end);
      if (end == f[k].c_str() || *end != '\0' || !std::isfinite(v[k]) || v[k] < 0)
        return at(column, "'" + f[k] + "' is not a number of zero or more");
    }
    Row r;
    r.mode = f[0];
    r.steps = static_cast<uint32_t>(std::max(0.0, v[1]));
    r.photons = static_cast<uint64_t>(std::max(0.0, v[2]));
    r.seed = static_cast<uint32_t>(std::max(0.0, v[3]));
    r.photon_s = std::max(0.0, v[4]), r.cone_s = std::max(0.0, v[5]), r.render_s = std::max(0.0, v[6]);
    r.total_s = std::max(0.0, v[7]);
    r.rmse = v[8], r.bias = v[9];
    r.cones = static_cast<size_t>(std::max(0.0, v[10]));
    r.merged = true;
    rows.push_back(r);
  }
  if (number < 2) return diagnostic_at(path, {number, 0}, "has no rows");
  return rows;
}

// The first line of both CSVs' run setting: what a --merge file must agree with.
std::string run_header(const Args& a, const Scene& scene, unsigned threads) {
  return "# sylva bench fog " + a.grammar.grammar + ", " + std::to_string(scene.width) + "x" +
         std::to_string(scene.height) + ", " + std::to_string(threads) + " threads, reference " +
         std::to_string(a.reference_steps) + " steps on every " + std::to_string(a.reference_stride) +
         "-th pixel each way" + (a.cpu_clock ? ", CPU clock" : "") + "\n";
}

// The rows of every --merge file, in order; a diagnostic for the first that cannot be read.
Expected<std::vector<Row>> read_merge_files(const std::vector<std::string>& paths, const std::string& header) {
  std::vector<Row> merged;
  for (const std::string& path : paths) {
    auto more = read_rows(path, header);
    if (!more) return std::move(more.error());
    merged.insert(merged.end(), more->begin(), more->end());
  }
  return merged;
}

// The photon rate of one core, printed.
void print_per_core_photon_rate(const SunPhotonTracer& tracer, uint64_t photons) {
  SunPhotonOptions o;
  o.photons = photons;
  o.threads = 1;
  const SunPhotons p = tracer.trace(o);
  std::printf("photons on 1 thread: %llu in %.3f s wall, %.3f s CPU = %.3g M photons/s per core (CPU time), "
              "%zu shadow vectors (%.1f%%)\n",
              static_cast<unsigned long long>(p.traced), p.seconds, p.cpu_seconds, p.traced / p.cpu_seconds * 1e-6,
              p.vectors.vectors.size(), 100.0 * p.vectors.vectors.size() / std::max<uint64_t>(1, p.traced));
}

// One run's measurements: the scene and the plants as the photons see them, the
// reference, and the rows measured so far with each setting's images summed over its
// seeds (for the bias).
class FogBench {
 public:
  FogBench(const Args& a, const Scene& scene, const SceneGeometry& g, const SunPhotonTracer& tracer, unsigned threads,
           bool fog_rows)
      : a_(a), scene_(scene), g_(g), tracer_(tracer), threads_(threads),
        progress_("sylva bench fog", planned_rows(fog_rows), isatty(STDERR_FILENO) != 0) {}

  // The rows this run will measure: the reference, the brute rows, and per photon count,
  // parameter kind and seed the cones row and the rows of the modes reading them.
  size_t planned_rows(bool fog_rows) const {
    const size_t seeds = a_.seeds;
    size_t n = fog_rows ? 1 : 0;
    if (fog_rows && wants("brute")) n += a_.brute_steps.size() * seeds;
    size_t automatic = 1, fixed = 1;  // the cones rows
    if (fog_rows) {
      for (const char* m : {"medium", "refined"})
        if (wants(m)) automatic += a_.cone_steps.size(), fixed += a_.cone_steps.size();
      if (wants("fast")) ++automatic, ++fixed;
      if (wants("map"))
        for (uint32_t directions : a_.map_directions)
          for (const bool a : {true, false}) (a ? automatic : fixed) += a_.map_resolutions.size() * map_rows(directions, a);
    }
    return n + a_.photons.size() * seeds * (automatic + fixed);
  }

  // The rows run_map_rows measures for one resolution and disc directions, over cones of
  // automatic or fixed parameters.
  size_t map_rows(uint32_t directions, bool automatic) const {
    const bool several = scene_.sun.angular_radius_deg > 0 && directions > 1;  // sun_map_directions' rule
    if (!automatic) return a_.map_variants ? 1 : 0;
    return 1 + (a_.map_variants ? (several ? 2 : 1) : 0);
  }

  bool wants(const std::string& m) const { return std::find(a_.modes.begin(), a_.modes.end(), m) != a_.modes.end(); }

  // The converged reference mode on every --reference-stride-th pixel each way.
  void render_reference() {
    view_ = pixel_rays(scene_, *g_.tracer);
    medium_ = fog_medium_of(scene_);
    FogIntegratorOptions ro;
    ro.mode = FogMode::reference;
    ro.steps = a_.reference_steps;
    const FogIntegrator ref(*medium_, fog_sun_of(scene_.sun), scene_.sky, *g_.tracer, nullptr, ro);
    double seconds = 0;
    const View sparse = strided(view_, a_.reference_stride, &reference_pixels_);
    const std::string what = "reference, " + std::to_string(a_.reference_steps) + " steps";
    const Progress within([&](double f, std::string_view) { progress_.within(f, what); });
    const std::vector<float> image = fog_image(sparse, ref, 0, threads_, &seconds, nullptr, within);
    reference_.assign(image.begin(), image.end());
    double mean = 0;
    for (double v : reference_) mean += v;
    mean /= std::max<size_t>(1, reference_.size());
    std::printf("reference: %u steps (%u probes per disc point), %zu pixels (stride %u), %.2f s, mean in-scatter "
                "%.4g\n",
                a_.reference_steps, a_.reference_steps * kReferenceProbesPerStep, reference_pixels_.size(),
                a_.reference_stride, seconds, mean);
    std::fflush(stdout);
    progress_.done(what);
  }

  // brute at each --brute-steps, each seed.
  void run_brute_rows() {
    for (uint32_t steps : a_.brute_steps)
      for (uint32_t seed = 1; seed <= a_.seeds; ++seed) {
        Row row;
        row.mode = "brute", row.steps = steps, row.seed = seed;
        render_row(row, FogMode::brute, nullptr);
      }
  }

  // The photons and cones of each photon count, cone parameters and seed (a cones row
  // and a line of the cones' CSV each), and with `fog_rows` the modes that use them.
  void run_cone_rows(bool fog_rows) {
    cones_csv_ << "# sylva bench fog " << a_.grammar.grammar << ", " << threads_ << " threads\n";
    cones_csv_ << "photons,seed,params_kind,photon_s,cone_s,params_s,cpu_s,params,vectors,covered,cones,missed_shadow,"
                  "covered_lit,coverage_points,shadowed_points,query_us\n";
    const bool cone_modes = wants("medium") || wants("fast") || wants("refined") || wants("map");
    for (uint64_t photons : a_.photons)
      for (const bool automatic : {true, false})
        for (uint32_t seed = 1; seed <= a_.seeds; ++seed) {
          SunConeOptions o;
          o.photons.photons = photons;
          o.photons.seed = seed;
          o.photons.threads = threads_;
          if (!automatic) o.params = a_.fixed_params;
          const double cpu_start = process_cpu_seconds();
          const auto c = build_sun_cones(g_, scene_, o, &tracer_);
          const double cpu_s = process_cpu_seconds() - cpu_start;
          const Row base = cones_row(*c, photons, seed, automatic, cpu_s);
          if (!fog_rows || !cone_modes) continue;
          const ConeSetFogSource source(c->cones);
          const std::string suffix = automatic ? "-auto" : "-fixed";
          for (const char* mode_name : {"medium", "refined"}) {
            if (!wants(mode_name)) continue;
            for (uint32_t steps : a_.cone_steps) {
              Row row = base;
              row.mode = mode_name + suffix, row.steps = steps;
              render_row(row, std::string(mode_name) == "medium" ? FogMode::medium : FogMode::refined, &source);
            }
          }
          if (wants("fast")) {
            Row row = base;
            row.mode = "fast" + suffix;
            render_row(row, FogMode::fast, &source);
          }
          if (wants("map")) run_map_rows(*c, source, base, suffix);
        }
  }

  // Mode map over the cones `c` (and, with --map-whole, over every ray's whole shadow range):
  // a row per map resolution and disc directions, the maps' build counted in cone_s.
  void run_map_rows(const SunCones& c, const ConeSetFogSource& source, const Row& base, const std::string& suffix) {
    for (uint32_t resolution : a_.map_resolutions)
      for (uint32_t directions : a_.map_directions) {
        SunMapOptions mo;
        mo.resolution = resolution;
        mo.disc_maps = directions;
        mo.threads = threads_;
        mo.memory_limit_bytes = a_.map_memory_mib << 20;
        mo.dilate_tiles = a_.map_dilate;
        const double cpu_start = process_cpu_seconds();
        const Expected<SunMaps> maps = build_sun_maps(tracer_, c.vectors, mo);
        const double cpu_s = process_cpu_seconds() - cpu_start;
        if (!maps) {
          std::printf("map %u² x %u: skipped: %s\n", resolution, directions, maps.error().message.c_str());
          std::fflush(stdout);
          for (size_t k = map_rows(directions, suffix == "-auto"); k > 0; --k) progress_.done("map, skipped");
          continue;
        }
        std::printf("map %u² x %u: %s, %.3f s wall, %.3f s CPU\n", resolution, directions, maps->describe().c_str(),
                    maps->seconds, cpu_s);
        const double map_s = a_.cpu_clock ? cpu_s / threads_ : maps->seconds;
        const std::string k = std::to_string(maps->maps.size());
        Row row = base;
        row.steps = resolution;
        // As the renderer runs it: the photons find the tiles, no cones (the automatic
        // and fixed rows are then the same setting on their own seeds' photons).
        if (suffix == "-auto") {
          row.cone_s = map_s, row.cones = 0;
          row.mode = "map" + k;
          render_row(row, FogMode::map, nullptr, maps->maps);
        }
        if (!a_.map_variants) continue;
        if (maps->maps.size() > 1 && suffix == "-auto") {
          row.mode = "mapray" + k;  // one map per camera ray, drawn at random
          render_row(row, FogMode::map, nullptr, maps->maps, true);
        }
        row = base;
        row.steps = resolution;
        row.cone_s += map_s;
        row.mode = "mapcones" + k + suffix;  // only the cone intervals walked
        render_row(row, FogMode::map, &source, maps->maps);
      }
  }

  // Each setting's bias: the mean image of its seeds against the reference.
  std::map<std::string, double> bias() const {
    std::map<std::string, double> out;
    for (const auto& [setting, sum] : sums_) {
      std::vector<double> mean(sum.size());
      for (size_t i = 0; i < sum.size(); ++i) mean[i] = sum[i] / counts_.at(setting);
      out[setting] = rmse(mean, reference_, reference_pixels_);
    }
    return out;
  }

  std::vector<Row>& rows() { return rows_; }
  std::string cones_csv() const { return cones_csv_.str(); }

 private:
  // The fog of every pixel by `mode` for `row`'s setting and seed: its time and RMSE, printed
  // and kept.
  void render_row(Row row, FogMode mode, const FogConeSource* cones, std::span<const SunDepthMap> maps = {},
                  bool map_per_ray = false) {
    FogIntegratorOptions o;
    o.mode = mode;
    o.steps = std::max(1u, row.steps);
    o.maps = maps;
    o.map_per_ray = map_per_ray;
    const FogIntegrator integrator(*medium_, fog_sun_of(scene_.sun), scene_.sky, *g_.tracer, cones, o);
    double cpu = 0;
    const std::string what = row.mode + ", " + std::to_string(row.steps) + " steps, " +
                             (row.photons ? std::to_string(row.photons) + " photons, " : "") + "seed " +
                             std::to_string(row.seed);
    const Progress within([&](double f, std::string_view) { progress_.within(f, what); });
    const std::vector<float> image = fog_image(view_, integrator, mix_pair(row.seed, 0x666f67), threads_,
                                               &row.render_s, &cpu, within);
    if (a_.cpu_clock) row.render_s = cpu / threads_;
    row.total_s = row.photon_s + row.cone_s + row.render_s;
    row.rmse = rmse(image, reference_, reference_pixels_);
    std::vector<double>& sum = sums_[row.setting()];
    if (sum.empty()) sum.assign(image.size(), 0.0);
    for (size_t i = 0; i < image.size(); ++i) sum[i] += image[i];
    ++counts_[row.setting()];
    std::printf("%-14s %5u %9llu %4u %9.3f %9.3f %9.3f %9.3f %11.4g %6zu\n", row.mode.c_str(), row.steps,
                static_cast<unsigned long long>(row.photons), row.seed, row.photon_s, row.cone_s, row.render_s,
                row.total_s, row.rmse, row.cones);
    std::fflush(stdout);
    rows_.push_back(row);
    progress_.done(what);
  }

  // The cones `c` built from `photons` photons of `seed`: the line of the cones' CSV, the
  // cones row (printed and kept), and the row the modes using them start from.
  Row cones_row(const SunCones& c, uint64_t photons, uint32_t seed, bool automatic, double cpu_s) {
    double params_s = 0;
    for (const RenderPass& p : c.passes)
      if (p.name == "cone params") params_s = p.seconds;
    if (seed == 1 && c.automatic) std::cerr << c.automatic->describe();
    const double query_us = cone_query_us(c);
    const ConeCoverage cov = c.coverage.value_or(ConeCoverage{});
    char line[512];
    std::snprintf(line, sizeof line, "%llu,%u,%s,%.6g,%.6g,%.6g,%.6g,%s,%llu,%llu,%zu,%.6g,%.6g,%llu,%llu,%.4g\n",
                  static_cast<unsigned long long>(photons), seed, automatic ? "auto" : "fixed", c.photon_seconds,
                  c.cone_seconds, params_s, cpu_s, params_text(c.params).c_str(),
                  static_cast<unsigned long long>(c.cluster.vectors), static_cast<unsigned long long>(c.cluster.covered),
                  c.cones.size(), cov.missed_shadow, cov.covered_lit, static_cast<unsigned long long>(cov.points),
                  static_cast<unsigned long long>(cov.shadowed), query_us);
    cones_csv_ << line;
    Row base;
    // The final coverage is a report (the cones' CSV), not a cost of rendering.
    base.photons = photons, base.seed = seed;
    base.photon_s = a_.cpu_clock ? c.photon_cpu_seconds / threads_ : c.photon_seconds;
    base.cone_s = a_.cpu_clock ? (c.cone_cpu_seconds - c.coverage_cpu_seconds) / threads_
                               : c.cone_seconds - c.coverage_seconds;
    base.cones = c.cones.size();
    Row row = base;
    row.mode = automatic ? "cones-auto" : "cones-fixed";
    row.total_s = row.photon_s + row.cone_s;
    std::printf("%-14s %5s %9llu %4u %9.3f %9.3f %9s %9.3f %11s %6zu  missed %.3f, covered lit %.3f, %s, "
                "query %.3g us/ray, cpu %.3f s\n",
                row.mode.c_str(), "-", static_cast<unsigned long long>(photons), seed, row.photon_s, row.cone_s, "-",
                row.total_s, "-", row.cones, cov.missed_shadow, cov.covered_lit, params_text(c.params).c_str(),
                query_us, cpu_s);
    std::fflush(stdout);
    rows_.push_back(row);
    progress_.done(row.mode + ", " + std::to_string(photons) + " photons, seed " + std::to_string(seed));
    return base;
  }

  // The camera's rays against the cones, one thread: microseconds a ray.
  double cone_query_us(const SunCones& c) const {
    std::vector<ConeInterval> intervals;
    Scene probe = scene_;
    probe.width = 256, probe.height = 192;
    const auto start = Clock::now();
    for (uint32_t y = 0; y < probe.height; ++y)
      for (uint32_t x = 0; x < probe.width; ++x)
        c.cones.intervals(camera_ray(probe, x + 0.5, y + 0.5), 0, 1e30, &intervals);
    return seconds_since(start) / (double(probe.width) * probe.height) * 1e6;
  }

  const Args& a_;
  const Scene& scene_;
  const SceneGeometry& g_;
  const SunPhotonTracer& tracer_;
  const unsigned threads_;
  BenchProgress progress_;  // after a_ and scene_, which planned_rows() reads
  View view_;
  std::vector<double> reference_;
  std::vector<size_t> reference_pixels_;  // of the view, in the reference's order
  std::optional<FogMedium> medium_;
  std::vector<Row> rows_;
  std::map<std::string, std::vector<double>> sums_;  // setting → sum of its seeds' images
  std::map<std::string, uint32_t> counts_;
  std::ostringstream cones_csv_;
};

// Appends the merged runs' rows to `rows`, less the settings this run measured again.
void merge_rows(std::vector<Row>& rows, const std::vector<Row>& merged, size_t files) {
  std::set<std::string> measured;
  for (const Row& r : rows) measured.insert(r.setting());
  size_t replaced = 0;
  for (const Row& r : merged)
    if (measured.count(r.setting())) ++replaced;
    else rows.push_back(r);
  if (!merged.empty())
    std::printf("merged %zu rows of %zu file(s)%s\n", merged.size() - replaced, files,
                replaced ? (", " + std::to_string(replaced) + " replaced by this run's").c_str() : "");
}

// The rows' CSV under `header`; a rendered row of this run gets its setting's `bias`.
std::string rows_csv(const std::string& header, std::vector<Row>& rows, std::map<std::string, double>& bias) {
  std::ostringstream csv;
  csv << header;
  csv << "mode,steps,photons,seed,photon_s,cone_s,render_s,total_s,rmse,bias,cones\n";
  for (Row& r : rows) {
    char line[512];
    const bool rendered = r.rmse >= 0;
    if (rendered && !r.merged) r.bias = bias[r.setting()];
    char rm[32] = "", bi[32] = "";
    if (rendered) std::snprintf(rm, sizeof rm, "%.6g", r.rmse), std::snprintf(bi, sizeof bi, "%.6g", r.bias);
    std::snprintf(line, sizeof line, "%s,%u,%llu,%u,%.6g,%.6g,%.6g,%.6g,%s,%s,%zu\n", r.mode.c_str(), r.steps,
                  static_cast<unsigned long long>(r.photons), r.seed, r.photon_s, r.cone_s, r.render_s, r.total_s, rm,
                  bi, r.cones);
    csv << line;
  }
  return csv.str();
}

// Each setting's mean time and RMSE over its seeds; families: the mode (with its cone
// parameters).
struct Families {
  std::map<std::string, std::map<std::string, Point>> totals;  // family → setting → sums over seeds
  std::map<std::string, std::map<std::string, uint32_t>> n;  // the same → seeds
  std::map<std::string, std::vector<Point>> curves;         // family → means, total time
  std::map<std::string, std::vector<Point>> render_curves;  // the same, render_s only
};

Families families_of(const std::vector<Row>& rows) {
  Families f;
  std::map<std::string, std::map<std::string, double>> render_time;  // family → setting → sum of render_s
  for (const Row& r : rows) {
    if (r.rmse < 0) continue;
    Point& p = f.totals[r.mode][r.setting()];
    p.time += r.total_s, p.rmse += r.rmse;
    render_time[r.mode][r.setting()] += r.render_s;
    ++f.n[r.mode][r.setting()];
  }
  for (auto& [family, settings] : f.totals)
    for (auto& [setting, p] : settings) {
      const uint32_t k = f.n[family][setting];
      f.curves[family].push_back({p.time / k, p.rmse / k});
      f.render_curves[family].push_back({render_time[family][setting] / k, p.rmse / k});
    }
  return f;
}

// The time each family needs to reach brute's mean RMSE at its settings' step counts
// (1024 the issue's), photons and cones included (one image), and the render alone (the
// cones amortised over every frame and camera that reuses them).
void print_times_to_reach(const std::vector<Row>& rows, Families& f) {
  std::vector<std::pair<std::string, double>> targets;
  std::set<uint32_t> brute_steps;  // this run's and the merged files'
  for (const Row& r : rows)
    if (r.mode == "brute" && r.rmse >= 0) brute_steps.insert(r.steps);
  if (f.curves.count("brute"))
    for (uint32_t steps : brute_steps) {
      const std::string key = "brute/" + std::to_string(steps) + "/0";
      if (f.totals["brute"].count(key))
        targets.push_back({"brute " + std::to_string(steps), f.totals["brute"][key].rmse / f.n["brute"][key]});
    }
  for (const bool with_cones : {true, false}) {
    std::printf(with_cones ? "\ntime (s, mean over seeds, photons and cones included) to reach the RMSE of:\n%-16s"
                           : "\nrender time alone (s, mean over seeds; the cones reused) to reach the RMSE of:\n%-16s",
                "family");
    for (const auto& t : targets) std::printf(" %12s", t.first.c_str());
    std::printf("\n%-16s", "");
    for (const auto& t : targets) std::printf(" %12.4g", t.second);
    std::printf("\n");
    for (const auto& [family, points] : with_cones ? f.curves : f.render_curves) {
      std::printf("%-16s", family.c_str());
      for (const auto& t : targets) {
        const double s = time_to_reach(points, t.second);
        if (s < 0) std::printf(" %12s", "-");
        else std::printf(" %12.4g", s);
      }
      std::printf("\n");
    }
  }
  // The same as ratios: what each family gains over brute force at brute's own RMSEs.
  if (!f.curves.count("brute")) return;
  std::printf("\nspeed-up over brute at equal RMSE (brute's time / the family's, photons, cones and maps "
              "included):\n%-16s",
              "family");
  for (const auto& t : targets) std::printf(" %12s", t.first.c_str());
  std::printf("\n");
  for (const auto& [family, points] : f.curves) {
    if (family == "brute") continue;
    std::printf("%-16s", family.c_str());
    for (const auto& t : targets) {
      const double mine = time_to_reach(points, t.second), brute = time_to_reach(f.curves.at("brute"), t.second);
      if (mine <= 0 || brute <= 0) std::printf(" %12s", "-");
      else std::printf(" %11.3gx", brute / mine);
    }
    std::printf("\n");
  }
}

// Fast mode's bias floor: the smallest bias of its settings, and when brute gets there.
void print_bias_floors(const std::vector<Row>& rows, Families& f) {
  for (const char* kind : {"fast-auto", "fast-fixed"}) {
    double floor = -1;
    std::string at;
    double time = 0;
    for (const Row& r : rows)
      if (r.mode == kind && r.bias >= 0 && (floor < 0 || r.bias < floor)) floor = r.bias, at = r.setting();
    if (floor < 0) continue;
    for (const auto& [setting, p] : f.totals[kind])
      if (setting == at) time = p.time / f.n[kind][setting];
    const double brute_time = f.curves.count("brute") ? time_to_reach(f.curves["brute"], floor) : -1;
    std::printf("%s bias floor: %.4g at %s (%.3g s); brute reaches that RMSE in %s\n", kind, floor, at.c_str(), time,
                brute_time < 0 ? "- (not within its settings)" : (std::to_string(brute_time) + " s").c_str());
  }
}

// The log-log plot of each family's RMSE against total time, to --plot.
Status write_plot(const Families& f, const Args& a) {
  std::vector<PlotSeries> series;
  for (const auto& [family, points] : f.curves) {
    PlotSeries& s = series_named(series, family);
    std::vector<Point> sorted = points;
    std::sort(sorted.begin(), sorted.end(), [](const Point& x, const Point& y) { return x.time < y.time; });
    for (const Point& p : sorted) s.points.push_back({p.time, p.rmse});
    s.connect = false;
  }
  return write_loglog_plot({{input_stem(a.grammar.grammar) + ": fog in-scatter against the reference",
                             "total time: photons + cones + fog (s)", "RMSE (linear RGB)", series}},
                           a.plot);
}

}  // namespace

int run_bench_fog(const std::vector<std::string>& args) {
  const Args a = parse_args(args);
  if (a.grammar.help) {
    print_help();
    return kOk;
  }
  std::vector<RenderPass> passes;
  auto loaded = load_render_input(a.grammar, a.width, a.height, passes);
  if (auto* code = std::get_if<ExitCode>(&loaded)) return *code;
  const Scene scene = std::move(std::get<Scene>(loaded));
  if (!a.cones_only && !scene.fog) {
    std::cerr << "sylva bench fog: " << a.grammar.grammar << " has no fog key (docs/spec/fog.md); --cones-only measures "
                 "its photons and cones alone\n";
    return kInputError;
  }
  const unsigned threads = worker_count(a.threads);
  const std::string header = run_header(a, scene, threads);
  // Read before the run: a bad file fails in a second, not after an hour.
  Expected<std::vector<Row>> merged = read_merge_files(a.merge, header);
  if (!merged) {
    std::cerr << merged.error().format();
    return kInputError;
  }
  GeometryOptions geometry;
  geometry.cull = false;     // a plant outside the view still casts shafts into it
  geometry.relief = false;   // the exact frusta for photons, shadow rays and the reference alike
  const SceneGeometry g = build_scene_geometry(scene, {}, geometry);
  std::cerr << "sylva bench fog: " << a.grammar.grammar << ", " << g.frusta.size() << " frusta, " << scene.width
            << "x" << scene.height << ", " << threads << " threads\n";

  // The plants as the photons see them, built once for every photon count and seed.
  const SunPhotonTracer tracer(g.frusta, scene.sun, threads);
  std::printf("photon tracer: accelerator and occupancy mask built in %.3f s\n", tracer.build_seconds());
  print_per_core_photon_rate(tracer, a.per_core_photons);

  const bool fog_rows = !a.cones_only;
  FogBench bench(a, scene, g, tracer, threads, fog_rows);
  if (fog_rows) bench.render_reference();
  std::printf("%-14s %5s %9s %4s %9s %9s %9s %9s %11s %6s\n", "mode", "steps", "photons", "seed", "photon_s", "cone_s",
              "render_s", "total_s", "rmse", "cones");
  if (fog_rows && bench.wants("brute")) bench.run_brute_rows();
  bench.run_cone_rows(fog_rows);

  std::map<std::string, double> bias = bench.bias();
  std::vector<Row>& rows = bench.rows();
  merge_rows(rows, *merged, a.merge.size());
  const std::string csv = rows_csv(header, rows, bias);
  if (fog_rows) {
    Families families = families_of(rows);
    print_times_to_reach(rows, families);
    print_bias_floors(rows, families);
    if (Status e = write_plot(families, a); !e) {
      std::cerr << e.error().format();
      return kInputError;
    }
  }
  for (const auto& [path, text] : {std::pair{a.csv, csv}, std::pair{a.cones_csv, bench.cones_csv()}}) {
    if (Status e = write_file_atomically(path, text); !e) {
      std::cerr << e.error().format();
      return kInputError;
    }
  }
  std::cerr << "sylva bench fog: wrote " << a.csv << ", " << a.cones_csv << (fog_rows ? " and " + a.plot : "") << "\n";
  return kOk;
}

}  // namespace sylva::cli
