// bench_rows.h — the rows of a long benchmark as they finish (`sylva bench gpu` and its
// --fog rows; docs/benchmarks.md "Long runs"): a progress line per row on stderr with the
// time elapsed and an estimate of the time left, and a CSV rewritten after every row, so
// that a run stopped at any point (Ctrl-C, SIGTERM, SIGHUP, a crash) leaves a valid CSV of
// the rows it finished.
//
// The CSV on disk is always one complete version: `head` (its '#' comment lines and the
// column line), the rows done, in order, and — until finish() — a last comment line
//   # partial run: K of N rows (the run was stopped, or is still running)
// which the finished run's file leaves out. Every version is written by
// write_file_atomically: a signal during a write removes the temporary
// (remove_temporaries_on_signals) and leaves the previous version, never a cut row.
//
// The progress line, one per row (a plain line when stderr is not a terminal; on a
// terminal the count and the bar are drawn in bold):
//   LABEL: row K/N done in 4.2 s (WHAT); 1 min 3 s elapsed, about 2 min 10 s left
// The estimate is the mean time of the rows done times the rows left.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

#include "core/util/diagnostic.h"

namespace sylva::cli {

// "0.8 s", "42 s", "3 min 5 s", "1 h 2 min": a duration for the progress line.
std::string describe_duration(double seconds);

// The progress line after row `done` of `planned` (no line break). `decorated`: ANSI bold
// count and a [####....] bar, for a terminal.
std::string bench_progress_line(const std::string& label, size_t done, size_t planned, const std::string& what,
                                double row_s, double elapsed_s, bool decorated);

// A line within a long row, at most every few seconds (bench_progress_line's form):
//   LABEL: row K/N (WHAT) 37 % in 4 min 10 s, about 7 min 5 s left in it; 5 min 2 s elapsed
std::string bench_within_row_line(const std::string& label, size_t row, size_t planned, const std::string& what,
                                  double fraction, double row_s, double elapsed_s);

// The progress of a benchmark's rows on stderr: a line per row done (bench_progress_line)
// and, for a row that reports its own fraction, a line within it at most every
// `within_every_s` seconds, so that no run is silent for long (`sylva bench gpu`, `bench
// fog`). Not thread-safe: one thread calls it (within() from a Progress callback, which
// serialises its calls).
class BenchProgress {
 public:
  BenchProgress(std::string label, size_t planned, bool decorated, double within_every_s = 30);
  void start();  // the clock starts (also at construction)
  // Row done: prints its line.
  void done(const std::string& what);
  // `fraction` of the row now running (row done()+1), named `what`.
  void within(double fraction, const std::string& what);
  size_t rows_done() const { return done_; }
  size_t planned() const { return planned_; }

 private:
  std::string label_;
  size_t planned_ = 0, done_ = 0;
  bool decorated_ = false;
  double within_every_s_ = 30;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now(), last_ = start_, said_ = start_;
};

class BenchRows {
 public:
  // `label`: "sylva bench gpu"; `head`: the CSV's comment and column lines, each ending
  // in '\n'; `planned`: the rows the run will write; `decorated`: see bench_progress_line
  // (isatty(STDERR_FILENO) for users).
  BenchRows(std::string label, std::string csv_path, std::string head, size_t planned, bool decorated);

  // Writes the head and the "0 of N" line. An error names the file (nothing else is run).
  Status start();
  // Row done: `csv_line` (ending in '\n') is added and the file rewritten; the progress
  // line names it by `what` ("pine.scene.json 1024x768 RC+R 8x0").
  Status add(const std::string& csv_line, const std::string& what);
  // The complete CSV, without the partial-run line.
  Status finish();

 private:
  std::string text(bool finished) const;

  std::string path_, head_, rows_;
  BenchProgress progress_;
};

}  // namespace sylva::cli
