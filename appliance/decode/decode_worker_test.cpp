// SPDX-License-Identifier: Apache-2.0
#include "appliance/decode/decode_worker.h"

#include <gtest/gtest.h>

#include <condition_variable>
#include <mutex>
#include <thread>

#include "common/jpeg_codec.h"

namespace mogao {
namespace {

constexpr ImageSize kSize{64, 48};

LinkFrame jpeg_frame(std::uint64_t request_id, std::uint8_t value) {
    JpegEncoder encoder;
    LinkFrame f;
    f.request_id = request_id;
    f.frame_id = request_id;
    f.size = kSize;
    f.jpeg = encoder.encode(Rgb8Image(kSize, value), 90);
    return f;
}

TEST(DecodeWorker, DecodesOnItsOwnThreadAndHandsTheFrameOver) {
    std::mutex mutex;
    std::thread::id decoded_on;
    DecodeWorker worker([&] {
        const std::lock_guard lock(mutex);
        decoded_on = std::this_thread::get_id();
    });
    worker.put(jpeg_frame(1, 120));
    worker.wait_idle();
    {
        const std::lock_guard lock(mutex);
        EXPECT_NE(decoded_on, std::thread::id{}) << "on_decoded was not called";
        EXPECT_NE(decoded_on, std::this_thread::get_id()) << "decoded on the caller's thread";
    }
    DecodeWorker::Taken taken = worker.take();
    ASSERT_TRUE(taken.frame.has_value());
    EXPECT_EQ(taken.frame->request_id, 1u);
    EXPECT_EQ(taken.frame->image.size, kSize);
    EXPECT_NEAR(taken.frame->image.at(10, 10)[0], 120, 3);
    EXPECT_TRUE(taken.rejections.empty());
    EXPECT_FALSE(worker.take().frame.has_value()) << "taken once";
}

TEST(DecodeWorker, ACorruptFrameIsRejectedAndTheLastGoodOneStays) {
    DecodeWorker worker(nullptr);
    worker.put(jpeg_frame(1, 90));
    worker.wait_idle();
    ASSERT_TRUE(worker.take().frame.has_value());
    LinkFrame corrupt = jpeg_frame(2, 200);
    corrupt.jpeg.resize(corrupt.jpeg.size() * 2 / 3);
    worker.put(std::move(corrupt));
    worker.wait_idle();
    DecodeWorker::Taken taken = worker.take();
    EXPECT_FALSE(taken.frame.has_value()) << "nothing newer to show: the loop keeps frame 1";
    ASSERT_EQ(taken.rejections.size(), 1u);
    EXPECT_EQ(taken.rejections[0].number, 1u);
    EXPECT_NE(taken.rejections[0].why.find("request 2"), std::string::npos) << taken.rejections[0].why;
    // An older request after a newer one is refused too (the wall never goes back).
    worker.put(jpeg_frame(1, 50));
    worker.put(jpeg_frame(3, 60));
    worker.wait_idle();
    taken = worker.take();
    ASSERT_TRUE(taken.frame.has_value());
    EXPECT_EQ(taken.frame->request_id, 3u);
    EXPECT_EQ(worker.rejected() + worker.superseded(), 2u) << "request 1 again: rejected or superseded";
}

// While the worker is busy, frames from the link replace each other; a decoded frame the loop has
// not taken is replaced by a newer decoded one. Both count as superseded; the newest is shown.
TEST(DecodeWorker, NewestWinsAtBothHandOversAndSupersededFramesAreCounted) {
    std::mutex mutex;
    std::condition_variable cv;
    bool release = false;
    int calls = 0;
    DecodeWorker worker([&] {
        std::unique_lock lock(mutex);
        if (++calls != 1) return;
        cv.notify_all();                         // frame 1 is decoded
        cv.wait(lock, [&] { return release; });  // hold the worker until frames 2-4 were put
    });
    worker.put(jpeg_frame(1, 10));
    {
        std::unique_lock lock(mutex);
        cv.wait_for(lock, std::chrono::seconds(30), [&] { return calls == 1; });
        ASSERT_EQ(calls, 1);
    }
    worker.put(jpeg_frame(2, 20));
    worker.put(jpeg_frame(3, 30));
    worker.put(jpeg_frame(4, 40));  // 2 and 3 never decoded
    {
        const std::lock_guard lock(mutex);
        release = true;
    }
    cv.notify_all();
    worker.wait_idle();
    DecodeWorker::Taken taken = worker.take();  // 1 was decoded but never taken: replaced by 4
    ASSERT_TRUE(taken.frame.has_value());
    EXPECT_EQ(taken.frame->request_id, 4u);
    EXPECT_NEAR(taken.frame->image.at(5, 5)[0], 40, 3);
    EXPECT_EQ(worker.superseded(), 3u);
    EXPECT_EQ(worker.rejected(), 0u);
}

}  // namespace
}  // namespace mogao
