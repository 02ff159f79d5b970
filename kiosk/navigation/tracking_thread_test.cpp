// SPDX-License-Identifier: Apache-2.0
#include "kiosk/navigation/tracking_thread.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "appliance/tracker/lab/hand_sequence.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;

// A short hand-held sequence (make-sequence's generator) played through the thread.
class TrackingThreadTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("mogao-kiosk-tracking-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        spec_.seconds = 0.5;
        spec_.frames_per_second = 20.0;
        spec_.camera = ideal_camera(320, 240, 280.0);
        write_hand_sequence(dir_, spec_);
        config_.camera = "replay:" + dir_.string();
        config_.source.kind = CameraSourceSpec::Kind::replay;
        config_.source.folder = dir_;
        config_.intrinsics = spec_.camera;
        config_.intrinsics_file = dir_ / "camera.json";
    }
    void TearDown() override { fs::remove_all(dir_); }

    // Drains `queue` until it is closed (the replay ended); the thread paces the replay in real
    // time, so this takes about spec_.seconds.
    static std::vector<TagSample> drain(TagSampleQueue& queue) {
        std::vector<TagSample> all;
        for (int i = 0; i < 6000; ++i) {  // a bound so that a broken thread fails instead of hanging
            auto batch = queue.take_all();
            all.insert(all.end(), batch.samples.begin(), batch.samples.end());
            if (batch.closed) return all;
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        ADD_FAILURE() << "the replay never ended";
        return all;
    }

    fs::path dir_;
    HandSequenceSpec spec_;
    TrackingConfig config_;
};

TEST_F(TrackingThreadTest, ReplaysEveryFrameInOrderOnTheMonotonicClock) {
    TagSampleQueue queue;
    const std::int64_t before = monotonic_ns();
    TrackingThread thread(config_, queue);
    const std::vector<TagSample> samples = drain(queue);
    thread.stop();
    const TrackingCounters c = thread.counters();
    ASSERT_EQ(samples.size(), 10u);  // 0.5 s at 20 Hz
    EXPECT_TRUE(c.ended);
    EXPECT_EQ(c.frames, 10u);
    // The script is compressed into 0.5 s (hand_sequence.h); each sample against its frame's truth.
    const std::vector<HandFrame> truth = hand_trajectory(spec_);
    ASSERT_EQ(truth.size(), samples.size());
    std::uint64_t visible = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
        EXPECT_EQ(samples[i].visible, truth[i].visible) << i;
        if (!samples[i].visible || !truth[i].visible) continue;
        ++visible;
        EXPECT_NEAR(samples[i].translation_m.z(), truth[i].pose.translation_m.z(), 0.02) << i;
    }
    EXPECT_GT(visible, 0u);
    EXPECT_EQ(c.visible, visible);
    EXPECT_EQ(c.frame_errors, 0u);
    // Rebased onto CLOCK_MONOTONIC: after the start, the replay's spacing kept exactly (50 ms).
    EXPECT_GE(samples.front().time_ns, before);
    for (std::size_t i = 1; i < samples.size(); ++i) {
        EXPECT_EQ(samples[i].time_ns - samples[i - 1].time_ns, 50'000'000) << i;
    }
}

// A "camera" far faster than any tracker: 10 frames 1 us apart. Reading and detecting a frame take
// far longer than 1 us, so every frame but the last (which has no successor) and perhaps the first
// (read as the replay's clock starts) has a successor already due when it is read: those are
// skipped, as a live camera would have overwritten them.
TEST_F(TrackingThreadTest, FramesBehindANewerDueFrameAreSkipped) {
    {
        std::ofstream stamps(dir_ / "timestamps.txt");
        for (int i = 0; i < 10; ++i) stamps << i * 1000 << "\n";
    }
    TagSampleQueue queue;
    TrackingThread thread(config_, queue);
    const std::vector<TagSample> samples = drain(queue);
    thread.stop();
    const TrackingCounters c = thread.counters();
    EXPECT_TRUE(c.ended);
    EXPECT_GE(c.frames, 1u);
    EXPECT_LE(c.frames, 2u);
    EXPECT_EQ(c.frames + c.skipped, 10u);
    ASSERT_EQ(samples.size(), c.frames);
    EXPECT_EQ(samples.back().time_ns - samples.front().time_ns, samples.size() == 2 ? 9000 : 0);  // the last frame
}

TEST_F(TrackingThreadTest, StopsWhileALoopingReplayRuns) {
    config_.source.loop = true;
    TagSampleQueue queue;
    TrackingThread thread(config_, queue);
    while (queue.pushed() < 3) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    thread.stop();
    thread.stop();  // idempotent
    const auto pushed = queue.pushed();
    EXPECT_FALSE(thread.counters().ended);
    EXPECT_EQ(queue.pushed(), pushed);  // nothing after stop()
}

TEST_F(TrackingThreadTest, FramesOfAnotherSizeAreSkippedAndCounted) {
    config_.intrinsics = ideal_camera(640, 480, 560.0);  // not the replay's 320x240
    TagSampleQueue queue;
    TrackingThread thread(config_, queue);
    const auto samples = drain(queue);
    EXPECT_TRUE(samples.empty());
    EXPECT_EQ(thread.counters().frame_errors, 10u);
}

TEST_F(TrackingThreadTest, AMissingCameraIsAnErrorNamingTheField) {
    config_.source.folder = dir_ / "absent";
    config_.camera = "replay:absent";
    TagSampleQueue queue;
    try {
        TrackingThread thread(config_, queue);
        ADD_FAILURE() << "no error for a missing replay folder";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("[navigation].camera = 'replay:absent'"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mogao
