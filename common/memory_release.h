// SPDX-License-Identifier: Apache-2.0
// Handing freed memory back to the kernel in processes that run for months (the farm's admin, the
// kiosk).
//
// Why: glibc's malloc keeps what a program frees in its arenas (the main heap and one arena per
// group of threads) and returns to the kernel only the top of the main heap, and only above
// M_TRIM_THRESHOLD. A process whose frames in flight vary in size (the frame-time controller
// changes the resolution with the machine's load) leaves free holes below live blocks, so its
// resident memory ratchets up to the largest set of frames it ever had in flight: in the 2-hour
// soak the admin's RSS grew in steps (+2.4 MiB/h) while its live allocations, traced with
// heaptrack, stayed flat. malloc_trim(0) (glibc >= 2.8) releases every whole free page of every
// arena (madvise MADV_DONTNEED), which bounds RSS by what is live plus what was freed since the
// last call.
//
// MemoryRelease calls it at most once per period from the caller's loop; one call costs about a
// millisecond for a heap of a few hundred MiB (it walks the free lists under each arena's lock).
// Under a sanitizer (its own allocator) it does nothing useful but is harmless.
#pragma once

#include <chrono>
#include <cstddef>

namespace mogao {

// malloc_trim(0): true when memory was released.
bool release_free_memory();

// The process's resident set size now, bytes (/proc/self/statm); 0 when it cannot be read.
[[nodiscard]] std::size_t resident_bytes();

class MemoryRelease {
public:
    using Clock = std::chrono::steady_clock;
    explicit MemoryRelease(Clock::duration period = std::chrono::seconds(60)) : period_(period) {}

    // Releases free memory when a period has passed since the last release (or since construction).
    void tick(Clock::time_point now = Clock::now());
    [[nodiscard]] std::size_t releases() const { return releases_; }

private:
    Clock::duration period_;
    Clock::time_point last_ = Clock::now();
    std::size_t releases_ = 0;
};

}  // namespace mogao
