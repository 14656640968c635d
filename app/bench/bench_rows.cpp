// bench_rows.cpp — progress and incremental CSV of a benchmark's rows (bench_rows.h).
#include "app/bench/bench_rows.h"

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

BenchRows::BenchRows(std::string label, std::string csv_path, std::string head, size_t planned, bool decorated)
    : label_(std::move(label)), path_(std::move(csv_path)), head_(std::move(head)), planned_(planned),
      decorated_(decorated) {}

std::string BenchRows::text(bool finished) const {
  std::string t = head_ + rows_;
  if (!finished)
    t += "# partial run: " + std::to_string(done_) + " of " + std::to_string(planned_) +
         " rows (the run was stopped, or is still running)\n";
  return t;
}

Status BenchRows::start() {
  start_ = last_ = std::chrono::steady_clock::now();
  return write_file_atomically(path_, text(false));
}

Status BenchRows::add(const std::string& csv_line, const std::string& what) {
  rows_ += csv_line;
  ++done_;
  const auto now = std::chrono::steady_clock::now();
  const double row_s = std::chrono::duration<double>(now - last_).count();
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  last_ = now;
  Status written = write_file_atomically(path_, text(false));
  std::cerr << bench_progress_line(label_, done_, planned_, what, row_s, elapsed_s, decorated_) << "\n";
  return written;
}

Status BenchRows::finish() { return write_file_atomically(path_, text(true)); }

}  // namespace sylva::cli
