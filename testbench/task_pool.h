// Independent frames on a few host threads: `saarcor sweep`'s points and `saarcor paper`'s scenes
// and thread counts. Each task writes only its own slot of the caller's results, so the output is
// the same for any number of jobs.
#pragma once

#include <cstddef>
#include <functional>

namespace saarcor {

// Runs task(0..n-1) on `jobs` threads (the calling thread is one of them). A task that throws
// stops the tasks after it (in index order) from starting, the ones before it still run, and the
// exception of the lowest index is rethrown: the error a serial run (jobs = 1) would give.
void run_tasks(std::size_t n, int jobs, const std::function<void(std::size_t)>& task);

// `--jobs`: 0 = the host's cores, else `jobs` (>= 1; a negative count is one error line).
int resolve_jobs(int jobs);

}  // namespace saarcor
