// What the benchmarks share (host/, units/, testbench/ *_bench.cpp): the clocks they time with and
// the built-in room at its default image, built once per process. Benchmarks only; no library code
// includes this.
#pragma once

#include <chrono>
#include <ctime>

#include "host/image_builder.h"
#include "host/scene.h"

namespace saarcor::host::bench {

// CPU seconds on a POSIX clock. The machines are shared, so wall time would measure the
// neighbours: a single-threaded frame is timed by its thread's CPU time, work on several threads
// (Embree's build under TBB) by the process's.
inline double cpu_seconds(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
inline double thread_cpu_seconds() {
  return cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
}
inline double process_cpu_seconds() {
  return cpu_seconds(CLOCK_PROCESS_CPUTIME_ID);
}
// Two threads working at once are timed by the wall clock (their CPU times add up).
inline double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// builtin:room with its memory image at the default build parameters (512x384 camera).
struct Room {
  Scene scene = load_scene("builtin:room");
  BuiltImage built = build_image(scene, {});
};
inline const Room& room() {
  static const Room r;
  return r;
}

}  // namespace saarcor::host::bench
