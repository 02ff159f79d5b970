// SPDX-License-Identifier: Apache-2.0
#include "appliance/decode/latest_frame_slot.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

namespace mogao {
namespace {

LinkFrame frame(std::uint64_t request_id, std::size_t bytes = 4) {
    LinkFrame f;
    f.request_id = request_id;
    f.frame_id = request_id;
    f.jpeg.assign(bytes, static_cast<std::uint8_t>(request_id));
    return f;
}

TEST(LatestFrameSlot, EmptyUntilPutAndEmptyAgainAfterTake) {
    LatestFrameSlot slot;
    EXPECT_FALSE(slot.take().has_value());
    EXPECT_FALSE(slot.put(frame(1)));
    auto taken = slot.take();
    ASSERT_TRUE(taken.has_value());
    EXPECT_EQ(taken->request_id, 1u);
    EXPECT_EQ(taken->jpeg.size(), 4u);
    EXPECT_FALSE(slot.take().has_value());
    EXPECT_EQ(slot.replaced(), 0u);
    EXPECT_EQ(slot.stored(), 1u);
}

TEST(LatestFrameSlot, NewestWinsAndReplacedFramesAreCounted) {
    LatestFrameSlot slot;
    EXPECT_FALSE(slot.put(frame(1)));
    EXPECT_TRUE(slot.put(frame(2)));
    EXPECT_TRUE(slot.put(frame(3, 9)));
    auto taken = slot.take();
    ASSERT_TRUE(taken.has_value());
    EXPECT_EQ(taken->request_id, 3u);
    EXPECT_EQ(taken->jpeg.size(), 9u);
    EXPECT_EQ(slot.replaced(), 2u);
    EXPECT_EQ(slot.stored(), 3u);
}

// A producer thread (the link) and a consumer (the loop): every frame taken is newer than the one
// taken before, nothing is taken twice, and the last frame put is never lost.
TEST(LatestFrameSlot, ConsumerSeesIncreasingIdsAndTheLastFrame) {
    LatestFrameSlot slot;
    constexpr std::uint64_t kFrames = 20000;
    std::atomic<bool> done{false};
    std::thread producer([&] {
        for (std::uint64_t id = 1; id <= kFrames; ++id) slot.put(frame(id));
        done = true;
    });
    std::vector<std::uint64_t> seen;
    for (;;) {
        const bool finished = done.load();
        while (auto f = slot.take()) {
            ASSERT_EQ(f->jpeg.size(), 4u);
            ASSERT_EQ(f->jpeg[0], static_cast<std::uint8_t>(f->request_id));  // never a torn frame
            seen.push_back(f->request_id);
        }
        if (finished) break;
        std::this_thread::yield();
    }
    producer.join();
    ASSERT_FALSE(seen.empty());
    for (std::size_t i = 1; i < seen.size(); ++i) ASSERT_LT(seen[i - 1], seen[i]) << "at " << i;
    EXPECT_EQ(seen.back(), kFrames);
    EXPECT_EQ(slot.stored(), kFrames);
    EXPECT_EQ(slot.replaced() + seen.size(), kFrames);
}

}  // namespace
}  // namespace mogao
