// progress_bar.cpp — see progress_bar.h.
#include "app/front/progress_bar.h"

#include <cstdio>

namespace sylva::cli {

ProgressBar::ProgressBar(std::string label, bool enabled) : label_(std::move(label)), enabled_(enabled) {}

Progress ProgressBar::progress(const std::atomic<bool>* cancel) {
  if (!enabled_) return Progress(cancel);
  return Progress([this](double fraction, std::string_view) { on_progress(fraction); }, cancel);
}

void ProgressBar::on_progress(double fraction) {
  fraction_ = fraction;
  if (ended_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (fraction >= 1) {
    if (drawn_) {
      draw(fraction, elapsed);
      std::fputc('\n', stderr);
    }
    ended_ = true;
    return;
  }
  if (elapsed > 1.0 && (!drawn_ || now - last_draw_ >= std::chrono::milliseconds(100))) {
    draw(fraction, elapsed);
    last_draw_ = now;
  }
}

void ProgressBar::draw(double fraction, double elapsed_s) {
  constexpr int kWidth = 40;
  const int filled = static_cast<int>(kWidth * fraction);
  char bar[kWidth + 1];
  for (int i = 0; i < kWidth; ++i) bar[i] = i < filled ? '#' : '.';
  bar[kWidth] = 0;
  std::fprintf(stderr, "\r%s: [%s] %3d%% %.1f s", label_.c_str(), bar, static_cast<int>(100.0 * fraction), elapsed_s);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (!drawn_ || ended_) return;
  draw(fraction_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
  std::fputc('\n', stderr);
  ended_ = true;
}

}  // namespace sylva::cli
