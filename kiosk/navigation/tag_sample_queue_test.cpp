// SPDX-License-Identifier: Apache-2.0
#include "kiosk/navigation/tag_sample_queue.h"

#include <gtest/gtest.h>

#include <thread>

namespace mogao {
namespace {

TagSample at(std::int64_t t) {
    TagSample s;
    s.time_ns = t;
    s.visible = true;
    return s;
}

TEST(TagSampleQueue, HandsOverEverySampleInOrder) {
    TagSampleQueue q(8);
    for (int i = 1; i <= 5; ++i) EXPECT_TRUE(q.push(at(i)));
    TagSampleQueue::Batch b = q.take_all();
    ASSERT_EQ(b.samples.size(), 5u);
    for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(b.samples[i].time_ns, static_cast<std::int64_t>(i + 1));
    EXPECT_FALSE(b.closed);
    EXPECT_TRUE(q.take_all().samples.empty());  // emptied
    EXPECT_EQ(q.pushed(), 5u);
    EXPECT_EQ(q.dropped(), 0u);
}

TEST(TagSampleQueue, WhenFullDropsTheOldest) {
    TagSampleQueue q(3);
    EXPECT_TRUE(q.push(at(1)));
    EXPECT_TRUE(q.push(at(2)));
    EXPECT_TRUE(q.push(at(3)));
    EXPECT_FALSE(q.push(at(4)));
    EXPECT_FALSE(q.push(at(5)));
    const auto b = q.take_all();
    ASSERT_EQ(b.samples.size(), 3u);
    EXPECT_EQ(b.samples.front().time_ns, 3);
    EXPECT_EQ(b.samples.back().time_ns, 5);
    EXPECT_EQ(q.dropped(), 2u);
}

TEST(TagSampleQueue, CloseIsReportedWithTheLastSamples) {
    TagSampleQueue q;
    (void)q.push(at(1));
    q.close();
    (void)q.push(at(2));  // ignored after close
    const auto b = q.take_all();
    ASSERT_EQ(b.samples.size(), 1u);
    EXPECT_EQ(b.samples[0].time_ns, 1);
    EXPECT_TRUE(b.closed);
    EXPECT_TRUE(q.take_all().closed);
}

TEST(TagSampleQueue, NothingIsLostOrReorderedAcrossThreads) {
    constexpr int kSamples = 20000;
    TagSampleQueue q(kSamples);
    std::thread producer([&] {
        for (int i = 1; i <= kSamples; ++i) (void)q.push(at(i));
        q.close();
    });
    std::int64_t last = 0;
    int seen = 0;
    for (bool closed = false; !closed;) {
        auto b = q.take_all();
        for (const auto& s : b.samples) {
            ASSERT_EQ(s.time_ns, last + 1);
            last = s.time_ns;
            ++seen;
        }
        closed = b.closed;
    }
    producer.join();
    EXPECT_EQ(seen, kSamples);
    EXPECT_EQ(q.dropped(), 0u);
}

}  // namespace
}  // namespace mogao
