// grow_worker.h — the studio's one worker thread (docs/spec/studio.md "Never blocking"): it parses
// the grammar text, derives, interprets and builds the skeletons while the UI thread
// keeps drawing frames; GL work (skinning into the renderer, uploads) stays on the UI
// thread, which takes finished results with poll().
//
// The mailbox holds one request, the latest: submit() replaces a request not yet started
// and cancels the one running (L-Py's coalescing
// "shouldrerun"). Each request gets a generation number; the worker checks between
// derivation steps (DeriveOptions::on_step) and between phases whether its generation is
// still the newest and stops early when it is not; poll() hands out only a result of the
// newest generation, so a stale plant never reaches the screen.
//
// Step cache: the words of every derivation step of the first plant are kept (up to a
// memory budget) with the text, defines, seed and module limit they came from, so
// Step / Rewind / Animate and "more steps" of the same grammar re-interpret a cached
// word instead of deriving again.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/geometry/skeleton.h"
#include "core/util/diagnostic.h"
#include "core/grow/grow.h"

namespace sylva::studio {

// How one plant of the document is grown from the text: -D overrides, seed and steps
// (unset: the grammar's own).
struct PlantVariant {
  std::map<std::string, double> defines;
  std::optional<uint64_t> seed;
  std::optional<int64_t> steps;
  bool operator==(const PlantVariant&) const = default;
};

struct GrowRequest {
  std::string text;                  // the grammar text
  std::string file;                  // its name in messages (the path as the user gave it)
  // A vlab object's folder when `text` is its model (docs/cpfg.md): parsed with the object's
  // view file, functions, environment and colours (lsys::parse_vlab_object). Empty: none.
  std::string object_folder;
  std::vector<PlantVariant> plants;  // at least one; plants[0] is the one the panel steps
  std::optional<int64_t> show_step;  // plants[0]: show this step's word, clamped to its
                                     // steps; unset: the last step
  uint64_t max_modules = 50'000'000;
  // The light a grammar with ?E queries grows in (docs/spec/light.md): the scene's sun,
  // ground and environment (its plants are not read). A grammar without queries ignores it.
  Scene light;
};

struct GrowOutcome {
  uint64_t generation = 0;
  std::optional<Diagnostic> error;   // the first parse or derivation error; then nothing below
                                     // but `defines` (empty) is set
  std::vector<Skeleton> skeletons;   // one per requested plant
  std::vector<std::vector<GrowQuery>> queries;  // per skeleton: its ?E answers where the turtle
                                     //   met them (the plant's frame; none without ?E)
  // plants[0]'s grammar: its defines after overrides, seed and derivation length.
  std::vector<lsys::Define> defines;
  std::vector<lsys::Grammar::Colour> colours;  // a vlab object's colour map (none: empty)
  uint64_t grammar_seed = 1;
  int64_t grammar_steps = 1;
  int64_t steps = 0;                 // the derivation length used for plants[0]
  int64_t shown_step = 0;            // the step whose word the first skeleton shows
  uint64_t modules = 0;              // modules in that word
  uint64_t segments = 0;             // segments of all skeletons
  uint64_t leaves = 0;               // leaves (polygons) of all skeletons
  bool from_cache = false;           // plants[0]'s word came from the step cache
  std::string warning;               // e.g. interpretation stopped at maximum depth
  LightGrowthStats light;            // what answering plants[0]'s ?E cost (zero without)
  double worker_seconds = 0;         // parse + derive + build, on the worker
  std::chrono::steady_clock::time_point submitted;  // when submit() was called
};

struct WorkerCounts {
  uint64_t submitted = 0;   // submit() calls
  uint64_t started = 0;     // requests the worker began
  uint64_t cancelled = 0;   // begun and stopped early by a newer request
  uint64_t finished = 0;    // ran to the end (result or located error)
  uint64_t dropped = 0;     // finished but stale when poll() saw them
};

class GrowWorker {
 public:
  // `cache_bytes`: the most bytes the step cache may hold (words beyond it are not kept,
  // and stepping to them derives again).
  explicit GrowWorker(uint64_t cache_bytes = 1ull << 30);
  // Called on the worker thread whenever a result becomes ready (a window loop that
  // sleeps between events wakes itself with it: glfwPostEmptyEvent). Set before submit().
  void on_result(std::function<void()> notify) { notify_ = std::move(notify); }
  ~GrowWorker();  // cancels and joins
  GrowWorker(const GrowWorker&) = delete;
  GrowWorker& operator=(const GrowWorker&) = delete;

  // Queues `request` as the latest, cancelling whatever runs; returns its generation.
  uint64_t submit(GrowRequest request);
  // Cancels the queued and the running request (their results never come).
  void cancel();
  // The result of the newest generation if it is done (once); stale results are dropped.
  std::optional<GrowOutcome> poll();
  // Whether a finished result waits for poll().
  bool result_waiting() const;
  // Whether a request is queued or running.
  bool busy() const;
  // Progress of the running request: derivation step reached and of how many.
  void progress(int64_t* step, int64_t* steps) const;
  WorkerCounts counts() const;
  uint64_t generation() const { return generation_.load(); }
  // Blocks until the worker is idle (tests and --screenshot); false after `timeout_s`.
  bool wait_idle(double timeout_s) const;

 private:
  struct Cache;
  void run();
  GrowOutcome grow(const GrowRequest& request, uint64_t generation, bool* cancelled);
  bool stale(uint64_t generation) const { return generation != generation_.load(); }

  mutable std::mutex mutex_;
  mutable std::condition_variable wake_, idle_;
  std::optional<GrowRequest> pending_;
  uint64_t pending_generation_ = 0;
  std::chrono::steady_clock::time_point pending_submitted_;
  bool running_ = false;
  bool quit_ = false;
  std::optional<GrowOutcome> done_;
  WorkerCounts counts_;
  std::atomic<uint64_t> generation_{0};
  std::atomic<int64_t> progress_step_{0}, progress_steps_{0};
  std::unique_ptr<Cache> cache_;  // touched by the worker thread only
  std::function<void()> notify_;
  uint64_t cache_bytes_;
  std::thread thread_;
};

}  // namespace sylva::studio
