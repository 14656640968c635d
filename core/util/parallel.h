// parallel.h — sylva's one way to run work on several threads: fork-join on the calling
// thread plus fresh std::threads, joined before the call returns. Every parallel stage
// (growing a scene's plants, proposing shadow cones, tracing sun photons, rendering
// tiles, seed batches, the benchmarks) goes through here, so the thread count, the
// exception contract and the order work is handed out in are decided once.
//
// No persistent pool: each call starts its threads and joins them. The most frequent
// caller, the shadow cones (a call per 4096 seeds proposed), makes a CPU fog render start
// threads about 150 times: some 10 ms on two cores against seconds of photons and cones.
// And threads that live only for the call carry no state (thread_local caches included)
// from one call to the next.
//
// Contract of run_on_workers and parallel_for:
//   - `workers` counts threads including the caller's; 0 asks for worker_count(0);
//   - worker 0 runs on the calling thread, workers 1.. on threads started for the call;
//   - the call returns after every worker has finished and its thread has been joined;
//   - an exception thrown by a worker (or a thread that cannot be started) is rethrown to
//     the caller after every worker has joined: the one of the lowest worker index when
//     several throw. The work's own results are then partial.
// What the work shares it must synchronise itself; results stay deterministic when each
// item writes only its own slot, whatever worker runs it.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <functional>

namespace sylva {

// The threads to use for `requested`: itself, or for 0 one per hardware thread (at
// least 1, where the hardware count is unknown).
unsigned worker_count(unsigned requested);

// Runs work(worker) once for every worker in [0, worker_count(workers)) (see the contract
// above): the primitive for work split into one fixed share per worker.
void run_on_workers(unsigned workers, const std::function<void(unsigned worker)>& work);

// Runs item(index, worker) for every index in [0, count), handed out in increasing order
// from a shared counter to min(worker_count(workers), max(1, count)) workers (see the
// contract above): each worker takes the next index when done with its last, so uneven
// items balance. No index is handed out once *cancel (may be null) is true or an item
// has thrown; the items already taken finish. Returns whether every index ran.
template <class Item>
bool parallel_for(size_t count, unsigned workers, const std::atomic<bool>* cancel, Item&& item) {
  std::atomic<size_t> next{0}, done{0};
  std::atomic<bool> failed{false};
  const unsigned threads = static_cast<unsigned>(std::min<size_t>(worker_count(workers), std::max<size_t>(1, count)));
  run_on_workers(threads, [&](unsigned worker) {
    try {
      for (;;) {
        if (failed.load(std::memory_order_relaxed)) return;
        if (cancel && cancel->load(std::memory_order_relaxed)) return;
        const size_t index = next.fetch_add(1, std::memory_order_relaxed);
        if (index >= count) return;
        item(index, worker);
        done.fetch_add(1, std::memory_order_relaxed);
      }
    } catch (...) {
      failed.store(true, std::memory_order_relaxed);
      throw;
    }
  });
  return done.load() == count;
}

}  // namespace sylva
