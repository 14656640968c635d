// cli_grow.cpp — `sylva derive` and `sylva grow` (cli.md).
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <iostream>
#include <limits>

#include "app/cli.h"
#include "core/file_io.h"
#include "core/turtle.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"

namespace sylva::cli {

namespace {

const char* const kGrammarFlags =
    "  -n, --steps N          derivation steps (overrides 'derivation length:')\n"
    "      --seed S           random seed, an integer from 0 to 2^64-1 (overrides 'seed:')\n"
    "  -D NAME=VALUE          override '#define NAME' (repeatable)\n"
    "      --max-modules N    stop with an error if a word would exceed N modules\n"
    "                         (default 50000000)\n"
    "  -h, --help             show this help\n";

void print_derive_help() {
  std::cout << "usage: sylva derive GRAMMAR [-n STEPS] [--seed S] [-D NAME=VALUE]... [--max-modules N]\n\n"
               "Derives the grammar's word and prints it to stdout (modules without spaces,\n"
               "arguments in shortest round-trip decimal form).\n\n"
            << kGrammarFlags;
}

void print_grow_help() {
  std::cout << "usage: sylva grow GRAMMAR [-n STEPS] [--seed S] [-D NAME=VALUE]... [--max-modules N]\n"
               "                  -o FILE.skel.json\n\n"
               "Derives the grammar, interprets the word with the turtle and writes the skeleton\n"
               "(sylva-skeleton JSON) atomically; prints one summary line: modules, chains,\n"
               "segments, bounding box, time.\n\n"
               "  -o, --output FILE      the skeleton file to write\n"
            << kGrammarFlags;
}

// Loads the grammar with its -D overrides; prints the diagnostic on failure.
std::optional<lsys::Grammar> load(const GrammarArgs& a, int* exit_code) {
  lsys::ParseOptions po;
  po.define_overrides = a.defines;
  auto g = lsys::load_grammar(a.grammar, po);
  if (!g) {
    const lsys::Diagnostic& d = g.error();
    // A -D naming no #define is a usage error, not a grammar error.
    if (d.loc.line == 0 && d.message.rfind("-D ", 0) == 0) {
      std::cerr << "sylva: error: " << d.message << "\n";
      *exit_code = kUsageError;
    } else {
      std::cerr << d.format();
      *exit_code = kInputError;
    }
    return std::nullopt;
  }
  return std::move(*g);
}

lsys::DeriveOptions derive_options(const GrammarArgs& a) {
  lsys::DeriveOptions o;
  o.steps = a.steps;
  o.seed = a.seed;
  o.max_modules = a.max_modules;
  return o;
}

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

}  // namespace

int run_derive(const std::vector<std::string>& args) {
  GrammarArgs a = parse_grammar_args(args, false);
  if (a.help) {
    print_derive_help();
    return kOk;
  }
  int code = kOk;
  auto g = load(a, &code);
  if (!g) return code;
  auto word = lsys::derive(*g, derive_options(a));
  if (!word) {
    std::cerr << word.error().format();
    return kInputError;
  }
  std::string text = lsys::print_word(*word, g->symbols);
  text += '\n';
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fflush(stdout);
  return kOk;
}

int run_grow(const std::vector<std::string>& args) {
  GrammarArgs a = parse_grammar_args(args, true);
  if (a.help) {
    print_grow_help();
    return kOk;
  }
  int code = kOk;
  auto g = load(a, &code);
  if (!g) return code;
  auto result = grow(*g, derive_options(a), a.grammar, a.defines);
  if (!result) {
    std::cerr << result.error().format();
    return kInputError;
  }
  const Skeleton& sk = result->skeleton;
  if (result->interpret.still_expandable)
    std::cerr << a.grammar << ": warning: the interpretation stopped at maximum depth " << g->max_depth
              << " with " << result->interpret.still_expandable << " modules still expandable\n";
  std::string json = write_skeleton_json(sk);
  if (auto err = write_file_atomically(a.output, json)) {
    std::cerr << err->format() << "\n";
    return kInputError;
  }
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  if (!sk.joints.empty()) {
    for (int k = 0; k < 3; ++k) lo[k] = std::numeric_limits<double>::infinity(), hi[k] = -lo[k];
    for (const Joint& j : sk.joints)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], j.position_m[k] - j.radius_m);
        hi[k] = std::max(hi[k], j.position_m[k] + j.radius_m);
      }
  }
  std::cout << a.grammar << ": " << result->modules << " modules, " << sk.chains.size() << " chains, "
            << sk.segment_count() << " segments, bbox [" << format_number(lo[0]) << "," << format_number(lo[1])
            << "," << format_number(lo[2]) << "]..[" << format_number(hi[0]) << "," << format_number(hi[1]) << ","
            << format_number(hi[2]) << "] m, " << format_number(result->seconds * 1e3) << " ms";
  if (result->turtle.zero_length_moves) std::cout << ", " << result->turtle.zero_length_moves << " zero-length moves";
  std::cout << "\n";
  return kOk;
}

}  // namespace sylva::cli
