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
// MemoryRelease calls it at most once per period from the caller's loop. A call walks every free
// chunk under its arena's lock and advises the kernel page range by page range, so it costs in
// proportion to the free chunks. Measured in synthetic heaps on this project's 2-core machine under
// load: at most 59 ms with 20 000 small live blocks and frame-sized buffers of varying size churning
// through it, 3 s the first time (0.1-0.2 s after) with 40 000 free holes in 440 MiB. The longest
// call is kept (max_ms) and the programs log it with their periodic statistics, so a stall shows.
// Under a sanitizer (its own allocator) it does nothing useful but is harmless.
//
// Trimming cannot hand back a page that still holds one live byte. glibc's mmap threshold, the size
// from which a block gets its own mapping (unmapped when freed), starts at 128 KiB but rises to the
// size of every mapped block freed, up to 32 MiB (mallopt(3), "M_MMAP_THRESHOLD"): after the first
// frame is freed, frame-sized buffers grow the heap, small long-lived blocks settle in the holes
// between them, and the pages those hold stay resident. map_large_blocks fixes the threshold, so a
// large block that the arenas' free memory cannot hold gets its own mapping instead of growing the
// heap. The price is a page fault per page of every new mapped block.
#pragma once

#include <chrono>
#include <cstddef>

namespace mogao {

// glibc's initial mmap threshold, kept from the start instead of rising.
inline constexpr std::size_t kLargeBlockBytes = 128 * 1024;

// mallopt(M_MMAP_THRESHOLD, bytes): from now on a block of `bytes` or more that free memory in the
// arenas cannot hold is mapped on its own (the heap does not grow for it).
// Call it once, before the process's loop. False when glibc refuses the value (above 32 MiB).
bool map_large_blocks(std::size_t bytes = kLargeBlockBytes);

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
    [[nodiscard]] double max_ms() const { return max_ms_; }  // the longest release so far

private:
    Clock::duration period_;
    Clock::time_point last_ = Clock::now();
    std::size_t releases_ = 0;
    double max_ms_ = 0;
};

}  // namespace mogao
