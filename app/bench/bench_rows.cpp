// bench_rows.cpp — progress and incremental CSV of a benchmark's rows (bench_rows.h).
#include "app/bench/bench_rows.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "core/util/file_io.h"

namespace sylva::cli {

std::string describe_duration(double seconds) {
  char text[48];
  if (!(seconds >= 0) || !std::isfinite(seconds)) return "?";
  if (seconds < 10) {
    std::snprintf(text, sizeof text, "%.1f s", seconds);
  } else if (seconds < 60) {
    std::snprintf(text, sizeof text, "%.0f s", seconds);
  } else if (seconds < 3600) {
    const long s = std::lround(seconds);
    std::snprintf(text, sizeof text, "%ld min %ld s", s / 60, s % 60);
  } else {
    const long m = std::lround(seconds / 60);
    std::snprintf(text, sizeof text, "%ld h %ld min", m / 60, m % 60);
  }
  return text;
}

std::string bench_progress_line(const std::string& label, size_t done, size_t planned, const std::string& what,
                                double row_s, double elapsed_s, bool decorated) {
  const std::string count = std::to_string(done) + "/" + std::to_string(planned);
  std::string line = label + ": ";
  if (decorated) {
    constexpr size_t kWidth = 20;
    const size_t filled = planned ? std::min(kWidth, done * kWidth / planned) : kWidth;
    line += "\x1b[1mrow " + count + "\x1b[0m [" + std::string(filled, '#') + std::string(kWidth - filled, '.') + "]";
  } else {
    line += "row " + count;
  }
  line += " done in " + describe_duration(row_s) + " (" + what + "); " + describe_duration(elapsed_s) + " elapsed";
  if (done < planned && done > 0)
    line += ", about " + describe_duration(elapsed_s / static_cast<double>(done) * static_cast<double>(planned - done)) +
            " left";
  return line;
}

std::string bench_within_row_line(const std::string& label, size_t row, size_t planned, const std::string& what,
                                  double fraction, double row_s, double elapsed_s) {
  char percent[16];
  std::snprintf(percent, sizeof percent, "%.0f %%", 100 * std::clamp(fraction, 0.0, 1.0));
  std::string line = label + ": row " + std::to_string(row) + "/" + std::to_string(planned) + " (" + what + ") " +
                     percent + " in " + describe_duration(row_s);
  if (fraction > 0 && fraction < 1) line += ", about " + describe_duration(row_s / fraction * (1 - fraction)) + " left in it";
  return line + "; " + describe_duration(elapsed_s) + " elapsed";
}

namespace {
double seconds_between(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}
}  // namespace

BenchProgress::BenchProgress(std::string label, size_t planned, bool decorated, double within_every_s)
    : label_(std::move(label)), planned_(planned), decorated_(decorated), within_every_s_(within_every_s) {}

void BenchProgress::start() { start_ = last_ = said_ = std::chrono::steady_clock::now(); }

void BenchProgress::done(const std::string& what) {
  ++done_;
  const auto now = std::chrono::steady_clock::now();
  const double row_s = seconds_between(last_, now);
  std::cerr << bench_progress_line(label_, done_, planned_, what, row_s, seconds_between(start_, now), decorated_)
            << std::endl;
  last_ = said_ = now;
}

void BenchProgress::within(double fraction, const std::string& what) {
  const auto now = std::chrono::steady_clock::now();
  if (seconds_between(said_, now) < within_every_s_) return;
  said_ = now;
  std::cerr << bench_within_row_line(label_, done_ + 1, planned_, what, fraction, seconds_between(last_, now),
                                     seconds_between(start_, now))
            << std::endl;
}

BenchRows::BenchRows(std::string label, std::string csv_path, std::string head, size_t planned, bool decorated)
    : path_(std::move(csv_path)), head_(std::move(head)), progress_(std::move(label), planned, decorated) {}

std::string BenchRows::text(bool finished) const {
  std::string t = head_ + rows_;
  if (!finished)
    t += "# partial run: " + std::to_string(progress_.rows_done()) + " of " + std::to_string(progress_.planned()) +
         " rows (the run was stopped, or is still running)\n";
  return t;
}

Status BenchRows::start() {
  progress_.start();
  return write_file_atomically(path_, text(false));
}

Status BenchRows::add(const std::string& csv_line, const std::string& what) {
  rows_ += csv_line;
  progress_.done(what);
  return write_file_atomically(path_, text(false));
}

Status BenchRows::finish() { return write_file_atomically(path_, text(true)); }

}  // namespace sylva::cli
