// args.h — what every front end's command line shares (docs/spec/cli.md): exit
// statuses, the usage error, the one flag parser every subcommand reads its arguments
// with, and the grammar flags of derive, grow, render and export.
//
// Exit status: 0 success, 1 a failure of the input (bad grammar, unreadable file),
// 2 a usage error, 3 an internal error. Messages go to stderr as
// "file:line:column: error: ..." where a place is known.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/geometry/skin.h"

namespace sylva::cli {

// kInterrupted: 128 + SIGINT, the shell's convention for work stopped by Ctrl-C.
enum ExitCode : int { kOk = 0, kInputError = 1, kUsageError = 2, kInternalError = 3, kInterrupted = 130 };

// Thrown for usage errors; main() prints "sylva SUBCOMMAND: error: message" and exits 2.
struct UsageError {
  std::string message;
};

// Parses an unsigned 64-bit integer exactly (no doubles); nullopt if not one.
std::optional<uint64_t> parse_u64(const std::string& text);

// Parses a count flag's value: an integer from 1 to `max`, else UsageError naming `flag`
// ("--width abc: expected an integer from 1 to 16384").
uint32_t parse_count(const std::string& flag, const std::string& value, uint64_t max);

// ---- The flag parser -------------------------------------------------------------
// A subcommand declares its flags in a FlagTable and parse_flags reads the arguments in
// order: a flag's value is the argument after it (whatever it looks like) or, where the
// table allows, the text after '=' ("--width=5") or after a one-letter name ("-n5").
// Each subcommand keeps the spellings, messages and help it always had; the table only
// says what differs between them.

// Whether a long flag may carry its value in the same argument, "--width=5".
enum class InlineValues {
  none,         // never: "--width=5" is not --width but an unknown option
  value_flags,  // a flag that takes a value may; "--mesh=1" is not the switch --mesh
  all_flags,    // as value_flags, and a switch ignores one: "--verbose=1" is --verbose
};

// One flag: its spellings, whether it takes a value, and what it does.
struct Flag {
  std::vector<std::string> names;  // e.g. {"-n", "--steps"}; "-n" taking a value also reads "-n5"
  bool takes_value = false;        // the next argument (or the inline value) is its value
  // Called with the name as given, for messages ("-n abc: ..." or "--steps abc: ..."), and
  // the value ("" for a switch). May throw UsageError.
  std::function<void(const std::string& spelled, const std::string& value)> apply;
  // Where set, the flag takes only a value this accepts: an occurrence it refuses, or one
  // without a value, is treated as an unknown option (kept, with its value, for a later
  // parser; see FlagTable::later_value_flags).
  std::function<bool(const std::string& value)> claims;
  bool ends_parsing = false;  // the arguments after it are not read (a help printed at once)
};

// A switch: `action` runs where it is given.
Flag switch_flag(std::vector<std::string> names, std::function<void()> action);
// A switch that sets `on`.
Flag set_flag(std::vector<std::string> names, bool& on);
// -h / --help, setting `help`; the arguments after it are still read (their errors win).
Flag help_flag(bool& help);
// -h / --help, setting `help` and reading no further: the help whatever follows it.
Flag help_at_once(bool& help);
// A flag taking a value; `apply` is called as Flag::apply.
Flag value_flag(std::vector<std::string> names,
                std::function<void(const std::string& spelled, const std::string& value)> apply);
// A flag whose value is stored as given in `text`.
Flag text_flag(std::vector<std::string> names, std::string& text);
// A flag whose value is a count from 1 to `max` (parse_count), stored in `count` (an
// integer, or an optional one).
template <typename Count>
Flag count_flag(std::vector<std::string> names, Count& count, uint64_t max) {
  return value_flag(std::move(names), [&count, max](const std::string& spelled, const std::string& value) {
    count = parse_count(spelled, value, max);
  });
}
// --skin smooth|paper (render, export, studio; docs/spec/scene.md "Skin"), into `style`.
Flag skin_flag(std::optional<SkinStyle>& style);
// `flag`, which also sets `given` where it is given (a default that depends on it, a
// check that it applies).
Flag noting_given(Flag flag, bool& given);

// A subcommand's flags, and what becomes of the other arguments.
struct FlagTable {
  std::vector<Flag> flags;
  InlineValues inline_values = InlineValues::none;
  // Called with each positional argument (one not starting with '-'; "" is one). Unset:
  // positional arguments are unknown.
  std::function<void(const std::string& arg)> positional;
  bool dash_is_positional = false;  // a lone "-" is a positional argument, not an option
  // Called with an unknown option as given ("--bogus=1"). Unset: UsageError
  // "unknown option 'ARG'".
  std::function<void(const std::string& arg)> unknown;
  // Unknown options and positional arguments are not handled here but returned by
  // parse_flags, in order, for a later parser (`positional` and `unknown` unused).
  bool leaves_others = false;
  // With leaves_others: the later parser's flags that take a value; the argument after
  // one of them goes with it, whatever it looks like ("-o --mesh" writes "--mesh").
  std::vector<std::string> later_value_flags;
};

// Reads `args` by `table`, calling the flags' actions in order; a flag that takes a
// value given last is a UsageError "FLAG needs a value". Returns the arguments left for a
// later parser (table.leaves_others), else nothing.
std::vector<std::string> parse_flags(std::span<const std::string> args, const FlagTable& table);

// ---- The grammar flags of derive, grow, render, export and the benchmarks -------

// The grammar-related flags shared by derive, grow, render, export and bench fog/geometry.
struct GrammarArgs {
  std::string grammar;                    // positional GRAMMAR
  std::optional<int64_t> steps;           // -n / --steps
  std::optional<uint64_t> seed;           // --seed
  std::map<std::string, double> defines;  // -D NAME=VALUE
  uint64_t max_modules = 50'000'000;      // --max-modules
  std::string output;                     // -o / --output
  bool help = false;
};

// What a subcommand calls its input and output in the grammar parser's messages.
struct GrammarArgsOptions {
  bool wants_output = false;  // -o / --output is a flag, and required
  std::string missing_input = "missing GRAMMAR (a .lsys file)";  // no positional given
  std::string missing_output = "missing -o FILE.skel.json";     // wants_output, no -o given
  std::string input_name = "GRAMMAR";  // in "unexpected argument 'X' (one GRAMMAR only)"
};

// The flags of parse_grammar_args that take a value (-o / --output included).
const std::vector<std::string>& grammar_value_flags();

// Parses argv (after the subcommand name). Throws UsageError.
GrammarArgs parse_grammar_args(std::span<const std::string> args, const GrammarArgsOptions& options = {});

}  // namespace sylva::cli
