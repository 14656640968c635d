// progress.cpp — serialised, monotone progress reports (progress.h).
#include "core/util/progress.h"

#include <algorithm>
#include <cassert>
#include <mutex>

namespace sylva {

struct Progress::State {
  std::mutex mutex;
  Callback callback;
  double last = -1;  // the last fraction reported; -1: none yet
};

Progress::Progress(Callback callback, const std::atomic<bool>* cancel) : cancel_(cancel) {
  if (callback) {
    state_ = std::make_shared<State>();
    state_->callback = std::move(callback);
  }
}

void Progress::report(double fraction, std::string_view stage) const {
  if (!state_) return;
  // NaN becomes 0; the whole task's fraction is begin + f·(end − begin).
  const double f = std::clamp(fraction >= 0 ? fraction : 0.0, 0.0, 1.0);
  const double whole = std::min(end_, begin_ + f * (end_ - begin_));
  std::lock_guard lock(state_->mutex);
  if (whole < state_->last) return;  // an out-of-order report from another thread
  state_->last = whole;
  state_->callback(whole, stage);
}

Progress Progress::part(double begin, double end) const {
  assert(0 <= begin && begin <= end && end <= 1 && "Progress::part: not a sub-range of [0, 1]");
  Progress p = *this;
  p.begin_ = begin_ + begin * (end_ - begin_);
  p.end_ = begin_ + end * (end_ - begin_);
  return p;
}

}  // namespace sylva
