// SPDX-License-Identifier: Apache-2.0
#include "common/memory_release.h"

#include <gtest/gtest.h>
#include <malloc.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <vector>

namespace mogao {
namespace {

// What a long-running process meets: blocks freed below one that stays live are kept by malloc
// (resident), and only release_free_memory hands them back.
TEST(MemoryRelease, FreedBlocksBelowALiveOneAreHandedBackToTheKernel) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    GTEST_SKIP() << "a sanitizer's allocator replaces glibc's malloc (not run in the CI suite)";
#endif
    constexpr std::size_t kBlock = 64 * 1024;  // below glibc's mmap threshold: from the heap
    constexpr std::size_t kBlocks = 512;       // 32 MiB
    release_free_memory();
    std::vector<std::unique_ptr<char[]>> blocks;
    for (std::size_t i = 0; i < kBlocks; ++i) {
        blocks.emplace_back(new char[kBlock]);
        std::memset(blocks.back().get(), int(i), kBlock);  // resident
    }
    const std::size_t filled = resident_bytes();
    ASSERT_GT(filled, 0u) << "no /proc/self/statm";
    // The last block, the highest in the heap, stays live: free() cannot trim the heap's top.
    for (std::size_t i = 0; i + 1 < kBlocks; ++i) blocks[i].reset();
    const std::size_t freed = resident_bytes();
    EXPECT_GT(freed + kBlock * kBlocks / 4, filled) << "malloc handed the blocks back by itself: not the case meant";
    ASSERT_TRUE(release_free_memory());
    const std::size_t released = resident_bytes();
    EXPECT_LT(released + kBlock * kBlocks / 2, freed)
        << "resident " << freed / 1024 << " KiB before the release, " << released / 1024 << " KiB after";
}

// Without the fixed threshold, freeing the first mapped block raises glibc's threshold above its size,
// and the second block of that size grows the heap (no new mapping).
TEST(MemoryRelease, LargeBlocksKeepTheirOwnMappingAfterOneIsFreed) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    GTEST_SKIP() << "a sanitizer's allocator replaces glibc's malloc (not run in the CI suite)";
#endif
    ASSERT_TRUE(map_large_blocks());
    EXPECT_FALSE(map_large_blocks(std::size_t{64} << 20)) << "above glibc's 32 MiB limit";
    // Larger than any free memory in the arenas (earlier tests leave some), which would serve it first.
    const std::size_t kFrame = std::max<std::size_t>(3 << 20, ::mallinfo2().fordblks + (1 << 20));
    for (int round = 0; round < 3; ++round) {
        const auto mapped_before = ::mallinfo2().hblks;
        auto frame = std::make_unique<char[]>(kFrame);
        std::memset(frame.get(), round, kFrame);
        EXPECT_EQ(::mallinfo2().hblks, mapped_before + 1) << "round " << round << ": the frame came from the heap";
    }
}

TEST(MemoryRelease, ReleasesOncePerPeriod) {
    using namespace std::chrono_literals;
    MemoryRelease release(60s);
    const auto t0 = MemoryRelease::Clock::now();
    release.tick(t0);
    EXPECT_EQ(release.releases(), 0u) << "not before a period has passed";
    release.tick(t0 + 61s);
    EXPECT_EQ(release.releases(), 1u);
    release.tick(t0 + 100s);
    EXPECT_EQ(release.releases(), 1u);
    release.tick(t0 + 122s);
    EXPECT_EQ(release.releases(), 2u);
}

}  // namespace
}  // namespace mogao
