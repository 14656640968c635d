// progress_bar.h — the command line's progress bar on stderr, drawn from the Progress
// callback of the core libraries (core/util/progress.h), which never print themselves.
//
// Shown only when stderr is a terminal and the work has run for more than a second, then
// redrawn at most every 100 ms in place: "\rsylva render: [#####...] 42% 3.1 s". The work
// reaching 1, or finish() (after a cancelled or failed run), draws it once more and ends
// the line, so what follows starts on a line of its own.
#pragma once

#include <atomic>
#include <chrono>
#include <string>

#include "core/util/progress.h"

namespace sylva::cli {

class ProgressBar {
 public:
  // `label`: "sylva render". `enabled`: draw at all (isatty(STDERR_FILENO) for users).
  ProgressBar(std::string label, bool enabled);
  ~ProgressBar() { finish(); }
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  // A Progress that draws this bar and stops the work once *cancel is set (may be null).
  // The bar must outlive the work.
  Progress progress(const std::atomic<bool>* cancel);
  // Ends the bar's line if it is drawn and not ended yet.
  void finish();

 private:
  void on_progress(double fraction);  // serialised by Progress
  void draw(double fraction, double elapsed_s);

  std::string label_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_draw_{};
  double fraction_ = 0;
  bool drawn_ = false;
  bool ended_ = false;
};

}  // namespace sylva::cli
