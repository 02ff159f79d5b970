// SPDX-License-Identifier: Apache-2.0
// HeadlessRecorder: every k-th round's outputs reach disk as PNGs although they are encoded on the
// recorder's thread: flush() waits for them, and destruction writes what is still queued.
#include "kiosk/display/headless_recorder.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "common/png_io.h"
#include "drivers/egl/egl_test_support.h"

namespace mogao {
namespace {

class HeadlessRecorderTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = std::filesystem::path(::testing::TempDir()) /
               ("mogao-recorder-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        std::filesystem::remove_all(dir_);
        HeadlessOptions options;
        options.outputs = {{16, 8}, {12, 6}};
        auto backend = HeadlessOutputBackend::create(options);
        if (!backend) {
            if (backend.code() == ENODEV) return mogao::testing::skip_or_fail_without_egl(backend.error().message);
            FAIL() << backend.error().message;
        }
        backend_ = std::move(backend).value();
        for (std::size_t i = 0; i < 2; ++i) {  // a black frame on each output to record
            ASSERT_TRUE(backend_->begin_frame(i));
            ASSERT_TRUE(backend_->stage(i));
        }
        ASSERT_TRUE(backend_->commit_round());
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    std::filesystem::path png(int output, int round, int request) const {
        char name[64];
        std::snprintf(name, sizeof name, "headless-%d-%06d-req%d.png", output, round, request);
        return dir_ / name;
    }

    std::filesystem::path dir_;
    std::unique_ptr<HeadlessOutputBackend> backend_;
};

TEST_F(HeadlessRecorderTest, EveryKthRoundIsOnDiskAfterFlush) {
    HeadlessRecorder recorder(*backend_, dir_, 2);
    for (std::uint64_t round = 1; round <= 6; ++round) {
        EXPECT_EQ(recorder.write_round(round, 7), round % 2 == 0 ? 2u : 0u) << "round " << round;
    }
    recorder.flush();
    for (int round = 1; round <= 6; ++round) {
        EXPECT_EQ(std::filesystem::exists(png(0, round, 7)), round % 2 == 0) << "round " << round;
        EXPECT_EQ(std::filesystem::exists(png(1, round, 7)), round % 2 == 0) << "round " << round;
    }
    const Rgb8Image second = read_png(png(1, 4, 7));
    EXPECT_EQ(second.size, (ImageSize{12, 6}));
    EXPECT_EQ(second.pixels, backend_->last_frame(1).pixels);
}

// A round the display forced (a held frame drawn again for the recording) is recorded whatever its number.
TEST_F(HeadlessRecorderTest, AForcedRoundIsRecordedOffTheCadence) {
    HeadlessRecorder recorder(*backend_, dir_, 4);
    EXPECT_EQ(recorder.write_round(3, 5), 0u);
    EXPECT_EQ(recorder.write_round(5, 5, true), 2u);
    recorder.flush();
    EXPECT_FALSE(std::filesystem::exists(png(0, 3, 5)));
    EXPECT_TRUE(std::filesystem::exists(png(0, 5, 5)));
    EXPECT_TRUE(std::filesystem::exists(png(1, 5, 5)));
}

TEST_F(HeadlessRecorderTest, DestructionWritesWhatIsStillQueued) {
    {
        HeadlessRecorder recorder(*backend_, dir_, 1);
        for (std::uint64_t round = 1; round <= 5; ++round) EXPECT_EQ(recorder.write_round(round, 3), 2u);
    }
    for (int round = 1; round <= 5; ++round) {
        EXPECT_TRUE(std::filesystem::exists(png(0, round, 3))) << "round " << round;
        EXPECT_TRUE(std::filesystem::exists(png(1, round, 3))) << "round " << round;
    }
}

}  // namespace
}  // namespace mogao
