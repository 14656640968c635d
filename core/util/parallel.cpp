// parallel.cpp — see parallel.h for the contract.
#include "core/util/parallel.h"

#include <exception>
#include <thread>
#include <vector>

namespace sylva {

unsigned worker_count(unsigned requested) {
  return requested ? requested : std::max(1u, std::thread::hardware_concurrency());
}

void run_on_workers(unsigned workers, const std::function<void(unsigned worker)>& work) {
  workers = worker_count(workers);
  // One slot per worker, each written by its own worker only: no lock, and the caller
  // sees the lowest worker's exception whatever order they failed in.
  std::vector<std::exception_ptr> failure(workers);
  auto guarded = [&](unsigned worker) {
    try {
      work(worker);
    } catch (...) {
      failure[worker] = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  threads.reserve(workers - 1);
  for (unsigned worker = 1; worker < workers; ++worker) {
    // A thread that cannot start is that worker's failure: the started ones must still
    // be joined (a joinable std::thread's destructor would terminate).
    try {
      threads.emplace_back(guarded, worker);
    } catch (...) {
      failure[worker] = std::current_exception();
    }
  }
  guarded(0);
  for (std::thread& thread : threads) thread.join();
  for (const std::exception_ptr& f : failure)
    if (f) std::rethrow_exception(f);
}

}  // namespace sylva
