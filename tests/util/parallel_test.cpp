// Tests for core/util/parallel.h: how many workers run, on which threads, that every item
// runs exactly once, and what cancellation and exceptions look like to the caller.
#include "core/util/parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace sylva {
namespace {

using std::chrono_literals::operator""ms;

TEST(WorkerCount, ZeroAsksForOneWorkerPerHardwareThreadAndAtLeastOne) {
  EXPECT_EQ(worker_count(0), std::max(1u, std::thread::hardware_concurrency()));
  EXPECT_GE(worker_count(0), 1u);
}

TEST(WorkerCount, ANonZeroRequestIsTakenAsItIs) {
  EXPECT_EQ(worker_count(1), 1u);
  EXPECT_EQ(worker_count(7), 7u);
  EXPECT_EQ(worker_count(1000), 1000u);
}

TEST(RunOnWorkers, RunsEveryWorkerOnceWorkerZeroOnTheCallingThreadTheOthersOnTheirOwn) {
  for (unsigned workers : {1u, 2u, 7u}) {
    SCOPED_TRACE(workers);
    std::vector<int> runs(workers, 0);
    std::vector<std::thread::id> thread_of(workers);
    run_on_workers(workers, [&](unsigned worker) {
      ++runs[worker];
      thread_of[worker] = std::this_thread::get_id();
    });
    EXPECT_EQ(runs, std::vector<int>(workers, 1));
    EXPECT_EQ(thread_of[0], std::this_thread::get_id());
    const std::set<std::thread::id> distinct(thread_of.begin(), thread_of.end());
    EXPECT_EQ(distinct.size(), workers);
  }
}

TEST(RunOnWorkers, ZeroWorkersMeansOnePerHardwareThread) {
  std::atomic<unsigned> runs{0};
  run_on_workers(0, [&](unsigned) { ++runs; });
  EXPECT_EQ(runs.load(), worker_count(0));
}

TEST(RunOnWorkers, AWorkersExceptionReachesTheCallerAfterEveryWorkerHasFinished) {
  std::vector<std::atomic<bool>> finished(4);
  auto work = [&](unsigned worker) {
    if (worker == 1) throw std::runtime_error("worker 1 failed");
    std::this_thread::sleep_for(50ms);  // still running when worker 1 throws
    finished[worker] = true;
  };
  try {
    run_on_workers(4, work);
    FAIL() << "the exception was swallowed";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "worker 1 failed");
  }
  EXPECT_TRUE(finished[0] && finished[2] && finished[3]);
}

TEST(RunOnWorkers, AnExceptionOnTheCallingThreadStillWaitsForTheOthers) {
  std::atomic<bool> other_finished{false};
  EXPECT_THROW(run_on_workers(2,
                              [&](unsigned worker) {
                                if (worker == 0) throw std::logic_error("caller failed");
                                std::this_thread::sleep_for(50ms);
                                other_finished = true;
                              }),
               std::logic_error);
  EXPECT_TRUE(other_finished);
}

TEST(RunOnWorkers, OfSeveralExceptionsTheLowestWorkersReachesTheCaller) {
  auto work = [](unsigned worker) {
    if (worker == 2) {
      std::this_thread::sleep_for(50ms);  // fails after worker 3
      throw std::runtime_error("worker 2");
    }
    if (worker == 3) throw std::runtime_error("worker 3");
  };
  try {
    run_on_workers(4, work);
    FAIL() << "the exceptions were swallowed";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "worker 2");
  }
}

TEST(ParallelFor, VisitsEveryIndexExactlyOnce) {
  constexpr size_t kCount = 1000;
  for (unsigned workers : {1u, 2u, 7u}) {
    SCOPED_TRACE(workers);
    std::vector<std::atomic<int>> visits(kCount);
    std::atomic<unsigned> highest_worker{0};
    const bool complete = parallel_for(kCount, workers, nullptr, [&](size_t index, unsigned worker) {
      ++visits[index];
      unsigned seen = highest_worker.load();
      while (worker > seen && !highest_worker.compare_exchange_weak(seen, worker)) {}
    });
    EXPECT_TRUE(complete);
    for (size_t i = 0; i < kCount; ++i) ASSERT_EQ(visits[i].load(), 1) << "index " << i;
    EXPECT_LT(highest_worker.load(), workers);
  }
}

TEST(ParallelFor, OneWorkerTakesTheIndicesInIncreasingOrderOnTheCallingThread) {
  const std::thread::id caller = std::this_thread::get_id();
  std::vector<size_t> order;
  parallel_for(5, 1, nullptr, [&](size_t index, unsigned worker) {
    EXPECT_EQ(worker, 0u);
    EXPECT_EQ(std::this_thread::get_id(), caller);
    order.push_back(index);
  });
  EXPECT_EQ(order, (std::vector<size_t>{0, 1, 2, 3, 4}));
}

TEST(ParallelFor, StartsNoMoreWorkersThanThereAreIndices) {
  // With 64 workers for 2 indices the 63 threads the caller starts before it works
  // itself would take both: only workers 0 and 1 may exist.
  for (int repeat = 0; repeat < 20; ++repeat) {
    std::atomic<unsigned> highest_worker{0};
    parallel_for(2, 64, nullptr, [&](size_t, unsigned worker) {
      unsigned seen = highest_worker.load();
      while (worker > seen && !highest_worker.compare_exchange_weak(seen, worker)) {}
    });
    ASSERT_LE(highest_worker.load(), 1u);
  }
}

TEST(ParallelFor, NoIndicesRunNothingAndCountAsComplete) {
  bool ran = false;
  EXPECT_TRUE(parallel_for(0, 4, nullptr, [&](size_t, unsigned) { ran = true; }));
  EXPECT_FALSE(ran);
}

TEST(ParallelFor, ACancelledFlagHandsOutNoIndex) {
  const std::atomic<bool> cancel{true};
  std::atomic<int> ran{0};
  EXPECT_FALSE(parallel_for(100, 4, &cancel, [&](size_t, unsigned) { ++ran; }));
  EXPECT_EQ(ran.load(), 0);
}

TEST(ParallelFor, CancellingStopsHandingOutIndicesAndReportsTheWorkIncomplete) {
  std::atomic<bool> cancel{false};
  std::vector<size_t> ran;
  const bool complete = parallel_for(100, 1, &cancel, [&](size_t index, unsigned) {
    ran.push_back(index);
    if (index == 10) cancel = true;
  });
  EXPECT_FALSE(complete);
  ASSERT_EQ(ran.size(), 11u);  // the item that cancelled finishes, no other starts
  EXPECT_EQ(ran.back(), 10u);
}

TEST(ParallelFor, AnItemsExceptionStopsTheHandingOutAndReachesTheCaller) {
  std::vector<size_t> ran;
  try {
    parallel_for(100, 1, nullptr, [&](size_t index, unsigned) {
      ran.push_back(index);
      if (index == 3) throw std::runtime_error("item 3 failed");
    });
    FAIL() << "the exception was swallowed";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "item 3 failed");
  }
  EXPECT_EQ(ran, (std::vector<size_t>{0, 1, 2, 3}));
}

TEST(ParallelFor, AfterAnExceptionTheOtherWorkersFinishTheirItemsAndTakeNoMore) {
  constexpr size_t kCount = 10000;
  std::vector<std::atomic<int>> visits(kCount);
  EXPECT_THROW(parallel_for(kCount, 4, nullptr,
                            [&](size_t index, unsigned) {
                              ++visits[index];
                              if (index == 0) throw std::runtime_error("item 0 failed");
                              std::this_thread::sleep_for(std::chrono::microseconds(100));
                            }),
               std::runtime_error);
  size_t ran = 0;
  for (const std::atomic<int>& v : visits) {
    ASSERT_LE(v.load(), 1);
    ran += v.load();
  }
  // The other three workers finish the item they hold and perhaps one the flag had not
  // yet reached; handing out on would take them through all 10000 (a third of a second).
  EXPECT_LT(ran, kCount / 2);
}

}  // namespace
}  // namespace sylva
