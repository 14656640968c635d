// clock.h — the one clock of sylva's timings: wall time on a steady clock for passes and
// progress, and the process's CPU time for benchmarks on a shared machine.
#pragma once

#include <chrono>
#include <time.h>

namespace sylva {

using Clock = std::chrono::steady_clock;

// Wall seconds since `start` on Clock.
inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// CPU time of this process, all threads (core-seconds): what a stage costs, which other
// jobs on a shared machine disturb far less than its wall time.
inline double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace sylva
