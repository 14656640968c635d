// progress.h — progress reports and cancellation for long work (derivation, turtle,
// skinning, CPU rendering, batches), so that a front end can draw a progress bar or run
// the work on a worker thread and stop it. The core libraries never print: they report
// here, and the front end decides what to show (the CLI's bar on stderr, the studio's
// status line).
//
// The caller makes a Progress from a callback and/or a cancellation flag and hands it
// down by const reference; the work reports fractions of itself and checks cancelled()
// between steps and chunks (never inside a hot inner loop). A task made of parts (grow =
// derive, interpret, turtle) hands each part a part() of its Progress, which maps the
// part's [0, 1] onto a sub-range of the whole.
//
// Guarantees to the callback:
//   - calls are serialised (never two at once, whatever threads the work runs on) and
//     happen on the thread that does the work (a worker: hand results to a UI thread
//     yourself);
//   - the fraction never decreases across all the parts of one Progress (a smaller
//     report than the last is dropped) and stays within [0, 1];
//   - work that runs to its end reports 1; cancelled work stops without reporting 1.
// Cost: a default Progress holds nothing; cancelled() is one relaxed atomic load, and
// report() on a Progress without a callback one null check. With a callback each report
// takes a mutex, so work reports per chunk (a step, a tile, 64 Ki modules), not per item.
//
// Cancelled work returns a distinguishable result, never an exception: an
// Expected whose error has `cancelled` set (cancelled_diagnostic(), diagnostic.h), or a
// result with its own `cancelled` flag (RenderResult).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string_view>

namespace sylva {

class Progress {
 public:
  // fraction in [0, 1] of the whole task; stage names the part running ("derive",
  // "interpret", "turtle", "skin", "render", ...), a view valid only during the call.
  using Callback = std::function<void(double fraction, std::string_view stage)>;

  Progress() = default;  // reports nothing, never cancelled
  // Reports to `callback` (may be empty); cancelled() once *cancel is true (may be null;
  // the flag must outlive the work).
  explicit Progress(Callback callback, const std::atomic<bool>* cancel = nullptr);
  explicit Progress(const std::atomic<bool>* cancel) : cancel_(cancel) {}

  // Whether the work should stop now. Thread-safe.
  bool cancelled() const { return cancel_ != nullptr && cancel_->load(std::memory_order_relaxed); }
  // The cancellation flag itself (may be null), for work that polls a raw flag.
  const std::atomic<bool>* cancel_flag() const { return cancel_; }
  // Whether report() reaches a callback (lets work skip computing fractions).
  bool reporting() const { return state_ != nullptr; }
  // Reports that `fraction` (clamped to [0, 1]) of this task or part is done. Thread-safe.
  void report(double fraction, std::string_view stage) const;
  // The part [begin, end] (0 <= begin <= end <= 1) of this task: its fraction f is
  // reported as begin + f·(end − begin) of this one. Shares the callback and the flag.
  Progress part(double begin, double end) const;

 private:
  struct State;
  std::shared_ptr<State> state_;
  const std::atomic<bool>* cancel_ = nullptr;
  double begin_ = 0, end_ = 1;  // of the whole task
};

}  // namespace sylva
