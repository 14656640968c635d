// batch.h — many seeds of one grammar in one command (docs/spec/cli.md, `--seed A..B`): an output
// pattern `-o out/elm_{seed}.glb`, one derivation per task on a pool of threads (one per
// core), progress on stderr, and a failure on one seed reported by its seed without
// stopping or damaging the others. Shared by `sylva grow` and `sylva export`,
// together with the grammar loading both do.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "app/front/args.h"
#include "core/util/diagnostic.h"
#include "core/util/progress.h"
#include "core/grow/grow.h"

namespace sylva::cli {

// An inclusive range of seeds, first <= last.
struct SeedRange {
  uint64_t first = 0;
  uint64_t last = 0;
  uint64_t count() const { return last - first + 1; }  // precondition: not the whole 2^64
};

// Most seeds one command may ask for.
inline constexpr uint64_t kMaxBatchSeeds = 1'000'000;

// Removes a `--seed A..B` or `--seed=A..B` from `args` and returns it; a single seed is
// left for parse_grammar_args. `value_flags` are the flags whose next argument is a
// value, not a flag (so `-o --seed` is not read as a seed). Throws UsageError for a
// malformed range ("5..1", "1..x") or one of more than kMaxBatchSeeds seeds.
std::optional<SeedRange> take_seed_range(std::vector<std::string>& args,
                                         const std::vector<std::string>& value_flags);

// True when `pattern` holds "{seed}".
bool has_seed_placeholder(const std::string& pattern);

// Throws UsageError when `placeholder` ("{seed}", "{frame}") in `pattern` does not give
// each value its own file: '..' undoes the folder it names (out/{seed}/../a.skel.json).
void check_pattern_separates(const std::string& pattern, std::string_view placeholder);

// `pattern` with every "{seed}" replaced by the seed in decimal.
std::string expand_seed_pattern(const std::string& pattern, uint64_t seed);

// Loads the grammar with its -D overrides; prints the diagnostic and sets *exit_code
// (a -D naming no #define is a usage error, anything else an input error) on failure.
std::optional<lsys::Grammar> load_grammar_for(const GrammarArgs& args, int* exit_code);

// The derivation options of the grammar flags (steps, seed, max modules).
lsys::DeriveOptions derive_options_for(const GrammarArgs& args);

// What one seed's task reports: an error (printed after the seed), or a line of summary
// for stdout.
struct SeedTaskResult {
  std::optional<Diagnostic> error;
  std::string summary;  // printed on stdout when not empty (one line, no newline)
  std::string warning;  // printed on stderr before the progress line when not empty
};

// Runs task(seed) for every seed of `range` on `threads` threads (0: min(cores, seeds)),
// without printing: on_done(seed, result, done, total) is called once per seed as it
// finishes, serialised, with done counting 1..total. An exception in a task becomes
// that seed's error ("out of memory", "internal error: ..."). `progress` is told
// done/total ("batch") and checked before each seed starts; once cancelled no new seed
// starts (those running finish). Returns the seeds that failed, in increasing order.
std::vector<uint64_t> run_seed_tasks(const SeedRange& range, unsigned threads,
                                     const std::function<SeedTaskResult(uint64_t seed)>& task,
                                     const std::function<void(uint64_t seed, const SeedTaskResult& result,
                                                              uint64_t done, uint64_t total)>& on_done,
                                     const Progress& progress = {});

// run_seed_tasks on every core, printing each finished seed as
// "sylva SUBCOMMAND: [k/N] seed S: ok|error: ..." on stderr (summaries on stdout) and at
// the end a tally naming the failed seeds. Returns kOk when every seed succeeded,
// kInputError otherwise.
int run_seed_batch(const std::string& subcommand, const SeedRange& range,
                   const std::function<SeedTaskResult(uint64_t seed)>& task);

// Frames (`sylva render --frames`, docs/animation.md): "{frame}" in an output pattern
// stands for the frame number, zero-padded to kFramePatternDigits digits (f_0007.png), so
// that the files sort in frame order; a longer number keeps all its digits.
inline constexpr size_t kFramePatternDigits = 4;
bool has_frame_placeholder(const std::string& pattern);
std::string expand_frame_pattern(const std::string& pattern, uint64_t frame);
// expand_frame_pattern with the file's folder created (the error names the folder).
Expected<std::string> frame_output_path(const std::string& pattern, uint64_t frame);

// Creates the folder that will hold `path` (for output patterns like out/{seed}.glb).
// The error names the folder.
Status create_parent_folder(const std::string& path);

// The output for `seed` of an -o `pattern` holding "{seed}", its folder created (each seed's
// own where the folder part holds {seed}: out/{seed}/plant.glb); the error names the folder.
Expected<std::string> seed_output_path(const std::string& pattern, uint64_t seed);

}  // namespace sylva::cli
