// SPDX-License-Identifier: Apache-2.0
// Clocks for timing work on a shared machine: the calling thread's CPU time (POSIX
// CLOCK_THREAD_CPUTIME_ID: unlike wall time it does not count the time other processes take the
// core away, which is why benchmarks and the farm's rank-speed figures use it) and monotonic wall
// time (CLOCK_MONOTONIC). Both in seconds from an unspecified origin: only differences mean anything.
#pragma once

#include <ctime>

namespace mogao {

[[nodiscard]] inline double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

[[nodiscard]] inline double monotonic_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace mogao
