// cli_grow.cpp — `sylva derive` and `sylva grow` (docs/spec/cli.md).
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <iostream>
#include <limits>
#include <sstream>

#include "app/front/batch.h"
#include "app/cli/cli.h"
#include "core/scene/scene.h"  // skeleton_bounds
#include "core/scene/scene_json.h"
#include "core/util/file_io.h"
#include "core/grow/turtle.h"
#include "core/grow/grow.h"
#include "app/front/light.h"

namespace sylva::cli {

namespace {

const char* const kGrammarFlags =
    "      --scene FILE       grow in that scene's light beside its plants, at its origin\n"
    "                         (a grammar with ?E light queries: docs/spec/light.md)\n"
    "      --verbose          print what answering ?E cost (photons, time, noise)\n"
    "  -n, --steps N          derivation steps (overrides 'derivation length:')\n"
    "      --seed S           random seed, an integer from 0 to 2^64-1 (overrides 'seed:')\n"
    "  -D NAME=VALUE          override '#define NAME' (repeatable)\n"
    "      --max-modules N    stop with an error if a word would exceed N modules\n"
    "                         (each parameter counts as a module; default 50000000)\n"
    "  -h, --help             show this help\n";

void print_derive_help() {
  std::cout << "usage: sylva derive GRAMMAR [-n STEPS] [--seed S] [-D NAME=VALUE]... [--max-modules N]\n"
               "                    [--scene FILE] [--verbose]\n\n"
               "Derives the grammar's word and prints it to stdout (modules without spaces,\n"
               "arguments in shortest round-trip decimal form).\n\n"
            << kGrammarFlags;
}

void print_grow_help() {
  std::cout << "usage: sylva grow GRAMMAR [-n STEPS] [--seed S] [-D NAME=VALUE]... [--max-modules N]\n"
               "                  [--scene FILE] [--verbose]\n"
               "                  -o FILE.skel.json\n\n"
               "Derives the grammar, interprets the word with the turtle and writes the skeleton\n"
               "(sylva-skeleton JSON) atomically; prints one summary line: modules, chains,\n"
               "segments, bounding box, time.\n\n"
               "  -o, --output FILE      the skeleton file to write\n"
               "      --seed A..B        a batch: every seed from A to B, in parallel on all cores;\n"
               "                         -o must then hold {seed} (out/elm_{seed}.skel.json), its\n"
               "                         folder is created; a failed seed is named on stderr,\n"
               "                         the others are still written, and the exit status is 1\n"
            << kGrammarFlags;
}

// --scene and --verbose, taken out before the grammar flags are parsed.
struct LightArgs {
  std::string scene_path;
  bool verbose = false;
  std::optional<Scene> scene;
};

LightArgs take_light_args(std::vector<std::string>& args) {
  LightArgs out;
  FlagTable table;
  table.leaves_others = true;
  table.later_value_flags = grammar_value_flags();
  table.flags = {text_flag({"--scene"}, out.scene_path), set_flag({"--verbose"}, out.verbose)};
  args = parse_flags(args, table);
  return out;
}

// Reads --scene; false (after printing the error) when it cannot be read.
bool read_light_scene(LightArgs& l) {
  if (l.scene_path.empty()) return true;
  auto scene = read_scene_file(l.scene_path);
  if (!scene) {
    std::cerr << scene.error().format();
    return false;
  }
  l.scene = std::move(*scene);
  return true;
}

std::string light_summary(const LightGrowthStats& s) {
  char line[256];
  std::snprintf(line, sizeof line,
                "light: %llu answers, %llu queries, %llu photons, %.3f s (%.3f s CPU tracing), mean relative "
                "standard error %.3g\n",
                static_cast<unsigned long long>(s.answers), static_cast<unsigned long long>(s.queries),
                static_cast<unsigned long long>(s.photons), s.seconds, s.cpu_seconds, s.mean_relative_error);
  return line;
}

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

}  // namespace

int run_derive(const std::vector<std::string>& raw_args) {
  std::vector<std::string> args = raw_args;
  LightArgs light = take_light_args(args);
  GrammarArgs a = parse_grammar_args(args);
  if (a.help) {
    print_derive_help();
    return kOk;
  }
  int code = kOk;
  auto g = load_grammar_for(a, &code);
  if (!g) return code;
  if (!read_light_scene(light)) return kInputError;
  LightGrowthStats stats;
  auto word = derive_word(*g, derive_options_for(a), {&cpu_light_oracle(), light.scene ? &*light.scene : nullptr},
                          &stats);
  if (!word) {
    std::cerr << word.error().format();
    return kInputError;
  }
  if (light.verbose) std::cerr << light_summary(stats);
  std::string text = lsys::print_word(*word, g->symbols);
  text += '\n';
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fflush(stdout);
  return kOk;
}

namespace {

// Grows one plant and writes it to `output`: the text grow prints on failure (a
// diagnostic) or, on success, its summary line and any warning.
struct GrowOutcome {
  std::optional<Diagnostic> error;   // printed on stderr (format())
  std::string warning;               // stderr text, may be empty
  std::string summary;               // the stdout summary line, without newline
  std::string light;                 // --verbose: what the light cost (stderr, after the summary)
};

GrowOutcome grow_to_file(const lsys::Grammar& g, const GrammarArgs& a, const std::string& output,
                         const LightArgs& light) {
  GrowOutcome out;
  auto result = grow(g, derive_options_for(a), a.grammar, a.defines,
                     {&cpu_light_oracle(), light.scene ? &*light.scene : nullptr});
  if (!result) {
    out.error = std::move(result.error());
    return out;
  }
  const Skeleton& sk = result->skeleton;
  if (result->interpret.still_expandable)
    out.warning = a.grammar + ": warning: the interpretation stopped at maximum depth " + std::to_string(g.max_depth) +
                  " with " + std::to_string(result->interpret.still_expandable) + " modules still expandable\n";
  std::string json = write_skeleton_json(sk);
  if (Status written = write_file_atomically(output, json); !written) {
    out.error = std::move(written.error());
    return out;
  }
  // The joints grown by their radii and the leaves' vertices; [0,0,0]..[0,0,0] for nothing.
  const SkeletonBounds box = skeleton_bounds(sk);
  std::ostringstream line;
  line << a.grammar << ": " << result->modules << " modules, " << sk.chains.size() << " chains, "
       << sk.segment_count() << " segments, bbox [" << format_number(box.lo.x) << "," << format_number(box.lo.y)
       << "," << format_number(box.lo.z) << "]..[" << format_number(box.hi.x) << "," << format_number(box.hi.y) << ","
       << format_number(box.hi.z) << "] m, " << format_number(result->seconds * 1e3) << " ms";
  if (!sk.leaves.empty()) line << ", " << sk.leaves.size() << (sk.leaves.size() == 1 ? " leaf" : " leaves");
  if (result->turtle.zero_length_moves) line << ", " << result->turtle.zero_length_moves << " zero-length moves";
  out.summary = line.str();
  if (light.verbose) out.light = light_summary(result->light);
  return out;
}

}  // namespace

int run_grow(const std::vector<std::string>& raw_args) {
  std::vector<std::string> args = raw_args;
  LightArgs light = take_light_args(args);
  const std::optional<SeedRange> range = take_seed_range(args, grammar_value_flags());
  GrammarArgs a = parse_grammar_args(args, {.wants_output = true});
  if (a.help) {
    print_grow_help();
    return kOk;
  }
  if (range && !has_seed_placeholder(a.output))
    throw UsageError{"--seed " + std::to_string(range->first) + ".." + std::to_string(range->last) +
                     " writes one file per seed: -o must hold {seed}, e.g. -o out/plant_{seed}.skel.json"};
  if (range) check_pattern_separates(a.output, "{seed}");
  int code = kOk;
  auto g = load_grammar_for(a, &code);
  if (!g) return code;
  if (!read_light_scene(light)) return kInputError;
  if (range) {
    if (Status folder = create_parent_folder(expand_seed_pattern(a.output, range->first)); !folder) {
      std::cerr << folder.error().format();
      return kInputError;
    }
    return run_seed_batch("grow", *range, [&](uint64_t seed) {
      GrammarArgs one = a;
      one.seed = seed;
      SeedTaskResult r;
      Expected<std::string> output = seed_output_path(a.output, seed);
      if (!output) {
        r.error = std::move(output.error());
        return r;
      }
      GrowOutcome o = grow_to_file(*g, one, *output, light);
      r.error = o.error;
      r.summary = o.summary;
      r.warning = o.warning + o.light;
      return r;
    });
  }
  Expected<std::string> output = has_seed_placeholder(a.output) && a.seed ? seed_output_path(a.output, *a.seed)
                                                                          : Expected<std::string>(a.output);
  if (!output) {
    std::cerr << output.error().format();
    return kInputError;
  }
  GrowOutcome o = grow_to_file(*g, a, *output, light);
  std::cerr << o.warning;
  if (o.error) {
    std::cerr << o.error->format();
    return kInputError;
  }
  std::cout << o.summary << "\n" << std::flush;
  std::cerr << o.light;
  return kOk;
}

}  // namespace sylva::cli
