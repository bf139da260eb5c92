// testbench/task_pool.h
#include "testbench/task_pool.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace saarcor {

void run_tasks(std::size_t n, int jobs, const std::function<void(std::size_t)>& task) {
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> first_error{n};
  std::vector<std::exception_ptr> errors(n);
  auto worker = [&] {
    for (std::size_t i = next++; i < n; i = next++) {
      if (i > first_error.load()) {
        continue;
      }
      try {
        task(i);
      } catch (...) {
        errors[i] = std::current_exception();
        std::size_t e = first_error.load();
        while (i < e && !first_error.compare_exchange_weak(e, i)) {
        }
      }
    }
  };
  const int threads =
      static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(std::max(jobs, 1)), n));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) {
    pool.emplace_back(worker);
  }
  worker();
  for (std::thread& t : pool) {
    t.join();
  }
  if (first_error.load() < n) {
    std::rethrow_exception(errors[first_error.load()]);
  }
}

int resolve_jobs(int jobs) {
  if (jobs < 0) {
    throw std::runtime_error("bad --jobs " + std::to_string(jobs) + ": 1 or more");
  }
  if (jobs > 0) {
    return jobs;
  }
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

}  // namespace saarcor
