// batch.cpp — seed ranges, output patterns and the seed tasks of batch.h on parallel_for.
#include "app/front/batch.h"

#include <algorithm>
#include <exception>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <new>

#include "core/util/parallel.h"

namespace sylva::cli {

namespace {

constexpr std::string_view kPlaceholder = "{seed}";

SeedRange parse_seed_range(const std::string& text) {
  const size_t dots = text.find("..");
  const auto first = parse_u64(text.substr(0, dots));
  const auto last = parse_u64(text.substr(dots + 2));
  if (!first || !last)
    throw UsageError{"--seed " + text + ": a seed range is A..B with integers from 0 to 18446744073709551615"};
  if (*first > *last) throw UsageError{"--seed " + text + ": the range is empty (the first seed is after the last)"};
  if (*last - *first >= kMaxBatchSeeds)
    throw UsageError{"--seed " + text + ": at most " + std::to_string(kMaxBatchSeeds) + " seeds in one command"};
  return {*first, *last};
}

}  // namespace

std::optional<SeedRange> take_seed_range(std::vector<std::string>& args, const std::vector<std::string>& value_flags) {
  std::optional<SeedRange> range;
  // --seed is this pass's only flag, and only with a range for its value; every other
  // argument, a single seed's --seed included, stays for parse_grammar_args.
  Flag seed_range = value_flag({"--seed"}, [&range](const std::string&, const std::string& value) {
    if (range) throw UsageError{"--seed given twice"};
    range = parse_seed_range(value);
  });
  seed_range.claims = [](const std::string& value) { return value.find("..") != std::string::npos; };
  FlagTable table;
  table.flags = {seed_range};
  table.inline_values = InlineValues::value_flags;
  table.leaves_others = true;
  table.later_value_flags = value_flags;
  args = parse_flags(args, table);
  // A single --seed besides the range is a contradiction parse_grammar_args cannot see.
  if (range)
    for (const std::string& a : args)
      if (a == "--seed" || a.starts_with("--seed=")) throw UsageError{"--seed given twice"};
  return range;
}

namespace {

// `pattern` with every `placeholder` replaced by `text`.
std::string expand_placeholder(const std::string& pattern, std::string_view placeholder, const std::string& text) {
  std::string out;
  size_t from = 0;
  for (size_t at; (at = pattern.find(placeholder, from)) != std::string::npos; from = at + placeholder.size())
    out.append(pattern, from, at - from).append(text);
  out.append(pattern, from);
  return out;
}

constexpr std::string_view kFramePlaceholder = "{frame}";

}  // namespace

bool has_seed_placeholder(const std::string& pattern) { return pattern.find(kPlaceholder) != std::string::npos; }

void check_pattern_separates(const std::string& pattern, std::string_view placeholder) {
  // Each value gives its own file only if the placeholder outlives '..' and '.': in
  // out/{seed}/../a.skel.json it names a folder that '..' leaves at once.
  const std::string normal = std::filesystem::path(pattern).lexically_normal().string();
  if (normal.find(placeholder) == std::string::npos)
    throw UsageError{"-o " + pattern + ": '..' undoes the folder " + std::string(placeholder) +
                     " names, so every one would write the same file " + normal};
}

std::string expand_seed_pattern(const std::string& pattern, uint64_t seed) {
  return expand_placeholder(pattern, kPlaceholder, std::to_string(seed));
}

bool has_frame_placeholder(const std::string& pattern) {
  return pattern.find(kFramePlaceholder) != std::string::npos;
}

std::string expand_frame_pattern(const std::string& pattern, uint64_t frame) {
  std::string digits = std::to_string(frame);
  if (digits.size() < kFramePatternDigits) digits.insert(0, kFramePatternDigits - digits.size(), '0');
  return expand_placeholder(pattern, kFramePlaceholder, digits);
}

std::optional<lsys::Grammar> load_grammar_for(const GrammarArgs& a, int* exit_code) {
  lsys::ParseOptions po;
  po.define_overrides = a.defines;
  auto g = lsys::load_grammar(a.grammar, po);
  if (!g) {
    const sylva::Diagnostic& d = g.error();
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

lsys::DeriveOptions derive_options_for(const GrammarArgs& a) {
  lsys::DeriveOptions o;
  o.steps = a.steps;
  o.seed = a.seed;
  o.max_modules = a.max_modules;
  return o;
}

Status create_parent_folder(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (parent.empty()) return {};
  std::error_code ec;
  std::filesystem::create_directories(parent, ec);
  if (ec) return file_diagnostic(parent.string(), "cannot create the output folder: " + ec.message(), ec.value());
  return {};
}

Expected<std::string> seed_output_path(const std::string& pattern, uint64_t seed) {
  std::string path = expand_seed_pattern(pattern, seed);
  if (Status folder = create_parent_folder(path); !folder) return std::move(folder.error());
  return path;
}

Expected<std::string> frame_output_path(const std::string& pattern, uint64_t frame) {
  std::string path = expand_frame_pattern(pattern, frame);
  if (Status folder = create_parent_folder(path); !folder) return std::move(folder.error());
  return path;
}

std::vector<uint64_t> run_seed_tasks(const SeedRange& range, unsigned threads,
                                     const std::function<SeedTaskResult(uint64_t seed)>& task,
                                     const std::function<void(uint64_t seed, const SeedTaskResult& result,
                                                              uint64_t done, uint64_t total)>& on_done,
                                     const Progress& progress) {
  const uint64_t total = range.count();
  std::mutex done_mutex;
  uint64_t done = 0;
  std::vector<uint64_t> failed;
  parallel_for(total, threads, progress.cancel_flag(), [&](size_t k, unsigned) {
    const uint64_t seed = range.first + k;
    SeedTaskResult r;
    try {
      r = task(seed);
    } catch (const std::bad_alloc&) {
      r.error = file_diagnostic("", "out of memory");
    } catch (const std::exception& e) {
      r.error = file_diagnostic("", std::string("internal error: ") + e.what());
    }
    std::lock_guard<std::mutex> lock(done_mutex);
    ++done;
    if (r.error) failed.push_back(seed);
    on_done(seed, r, done, total);
    progress.report(static_cast<double>(done) / static_cast<double>(total), "batch");
  });
  std::sort(failed.begin(), failed.end());
  return failed;
}

int run_seed_batch(const std::string& subcommand, const SeedRange& range,
                   const std::function<SeedTaskResult(uint64_t seed)>& task) {
  const uint64_t total = range.count();
  const std::vector<uint64_t> failed = run_seed_tasks(
      range, 0, task, [&](uint64_t seed, const SeedTaskResult& r, uint64_t done, uint64_t) {
        std::cerr << r.warning;
        std::string line = "sylva " + subcommand + ": [" + std::to_string(done) + "/" + std::to_string(total) +
                           "] seed " + std::to_string(seed) + ": ";
        if (r.error) {
          // The diagnostic as the single command prints it, after the seed (its place
          // prefix, if any, included; a message without place reads "error: MESSAGE").
          std::string message = r.error->format();
          while (!message.empty() && message.back() == '\n') message.pop_back();
          line += r.error->file.empty() && r.error->loc.line == 0 ? message : "error: " + message;
        } else {
          line += "ok";
          if (!r.summary.empty()) std::cout << r.summary << "\n" << std::flush;
        }
        std::cerr << line << "\n" << std::flush;
      });

  std::cerr << "sylva " << subcommand << ": " << total << (total == 1 ? " seed, " : " seeds, ")
            << (total - failed.size()) << " written, " << failed.size() << " failed";
  for (size_t i = 0; i < failed.size() && i < 100; ++i) std::cerr << (i ? ", " : ": seed ") << failed[i];
  if (failed.size() > 100) std::cerr << ", ...";
  std::cerr << "\n";
  return failed.empty() ? kOk : kInputError;
}

}  // namespace sylva::cli
