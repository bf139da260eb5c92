// testbench/task_pool.h: every task runs once on any number of jobs, and a failing run rethrows
// the error of the lowest failing index, as a serial run would.
#include "testbench/task_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

namespace saarcor {
namespace {

TEST(TaskPool, EveryTaskRunsOnceOnAnyNumberOfJobs) {
  for (int jobs : {1, 2, 3, 8, 64}) {
    std::vector<std::atomic<int>> runs(37);
    run_tasks(runs.size(), jobs, [&](std::size_t i) { ++runs[i]; });
    for (std::size_t i = 0; i < runs.size(); ++i) {
      EXPECT_EQ(runs[i].load(), 1) << "task " << i << ", " << jobs << " jobs";
    }
  }
  int ran = 0;
  run_tasks(0, 4, [&](std::size_t) { ++ran; });
  EXPECT_EQ(ran, 0);
}

TEST(TaskPool, TheLowestFailingTaskIsTheError) {
  for (int jobs : {1, 2, 4}) {
    std::vector<std::atomic<int>> runs(20);
    try {
      run_tasks(runs.size(), jobs, [&](std::size_t i) {
        ++runs[i];
        if (i == 5 || i == 11) {
          throw std::runtime_error("task " + std::to_string(i));
        }
      });
      ADD_FAILURE() << "no error with " << jobs << " jobs";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "task 5") << jobs << " jobs";
    }
    // The tasks before the first failure all ran (a serial run would have run them).
    for (std::size_t i = 0; i <= 5; ++i) {
      EXPECT_EQ(runs[i].load(), 1) << "task " << i << ", " << jobs << " jobs";
    }
  }
}

TEST(TaskPool, JobsResolve) {
  EXPECT_EQ(resolve_jobs(3), 3);
  EXPECT_GE(resolve_jobs(0), 1);
  try {
    resolve_jobs(-1);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "bad --jobs -1: 1 or more");
  }
}

}  // namespace
}  // namespace saarcor
