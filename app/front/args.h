// args.h — what every front end's command line shares (docs/spec/cli.md): exit
// statuses, the usage error, and the grammar flags of derive, grow, render and export.
//
// Exit status: 0 success, 1 a failure of the input (bad grammar, unreadable file),
// 2 a usage error, 3 an internal error. Messages go to stderr as
// "file:line:column: error: ..." where a place is known.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace sylva::cli {

enum ExitCode : int { kOk = 0, kInputError = 1, kUsageError = 2, kInternalError = 3 };

// Thrown for usage errors; main() prints "sylva SUBCOMMAND: error: message" and exits 2.
struct UsageError {
  std::string message;
};

// The grammar-related flags shared by derive, grow (and later render/export).
struct GrammarArgs {
  std::string grammar;                    // positional GRAMMAR
  std::optional<int64_t> steps;           // -n / --steps
  std::optional<uint64_t> seed;           // --seed
  std::map<std::string, double> defines;  // -D NAME=VALUE
  uint64_t max_modules = 50'000'000;      // --max-modules
  std::string output;                     // -o / --output
  bool help = false;
};

// Parses argv (after the subcommand name). `wants_output`: accept -o. Throws UsageError.
GrammarArgs parse_grammar_args(const std::vector<std::string>& args, bool wants_output);

// Parses an unsigned 64-bit integer exactly (no doubles); nullopt if not one.
std::optional<uint64_t> parse_u64(const std::string& text);

}  // namespace sylva::cli
