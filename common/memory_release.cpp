// SPDX-License-Identifier: Apache-2.0
#include "common/memory_release.h"

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>

namespace mogao {

bool map_large_blocks(std::size_t bytes) {
    return bytes <= (std::size_t{32} << 20) && ::mallopt(M_MMAP_THRESHOLD, static_cast<int>(bytes)) == 1;
}

bool release_free_memory() { return ::malloc_trim(0) != 0; }

std::size_t resident_bytes() {
    std::ifstream statm("/proc/self/statm");
    std::size_t pages = 0, resident = 0;
    if (!(statm >> pages >> resident)) return 0;
    return resident * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
}

void MemoryRelease::tick(Clock::time_point now) {
    if (now - last_ < period_) return;
    last_ = now;
    const auto start = Clock::now();
    release_free_memory();
    max_ms_ = std::max(max_ms_, std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    ++releases_;
}

}  // namespace mogao
