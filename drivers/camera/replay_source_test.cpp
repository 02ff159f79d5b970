// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/replay_source.h"
#include "tests/support/scratch_dir.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

namespace mogao {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test, removed afterwards.
class ReplayFolder : public ::testing::Test {
protected:
    mogao::testing::ScratchDir scratch_{"replay"};

    // An image whose every pixel is `value`, so the frame order can be read back from the pixels.
    void write(const std::string& name, int value, int channels = 1) {
        cv::Mat m(12, 16, channels == 1 ? CV_8UC1 : CV_8UC3, cv::Scalar::all(value));
        ASSERT_TRUE(cv::imwrite((dir_ / name).string(), m));
    }
    void write_text(const std::string& name, const std::string& text) { std::ofstream(dir_ / name) << text; }

    const fs::path dir_ = scratch_.path();
};

TEST_F(ReplayFolder, PlaysPngPgmJpegInNameOrderAndEndsWithEnodata) {
    write("frame-002.jpg", 150, 3);  // colour JPEG: converted to grey
    write("frame-000.png", 50);
    write("frame-001.pgm", 100);
    write_text("notes.txt", "not an image");
    auto src = ReplaySource::open({dir_, 25.0, false});
    ASSERT_TRUE(src.ok()) << src.error().message;
    ASSERT_EQ((*src)->files().size(), 3U);
    const int expected[] = {50, 100, 150};
    for (int i = 0; i < 3; ++i) {
        auto frame = (*src)->next_frame();
        ASSERT_TRUE(frame.ok()) << frame.error().message;
        EXPECT_EQ(frame->image.width, 16);
        EXPECT_EQ(frame->image.height, 12);
        EXPECT_NEAR(frame->image.at(3, 3), expected[i], 2) << "frame " << i;
        EXPECT_EQ(frame->timestamp_ns, i * 40'000'000LL);  // 25 fps
        EXPECT_EQ(frame->sequence, static_cast<std::uint64_t>(i));
        EXPECT_EQ(frame->clock, TimestampSource::replay);
    }
    auto end = (*src)->next_frame();
    ASSERT_FALSE(end.ok());
    EXPECT_EQ(end.code(), ENODATA);
}

TEST_F(ReplayFolder, TimestampsFileAndLoop) {
    write("a.png", 1);
    write("b.png", 2);
    write_text("timestamps.txt", "1000\n3000\n");
    auto src = ReplaySource::open({dir_, 30.0, true});
    ASSERT_TRUE(src.ok()) << src.error().message;
    std::vector<std::int64_t> stamps;
    for (int i = 0; i < 4; ++i) {
        auto frame = (*src)->next_frame();
        ASSERT_TRUE(frame.ok()) << frame.error().message;
        stamps.push_back(frame->timestamp_ns);
    }
    // Second pass starts one mean period (2000 ns) after the last stamp.
    EXPECT_EQ(stamps, (std::vector<std::int64_t>{1000, 3000, 5000, 7000}));
}

TEST_F(ReplayFolder, BadTimestampsNameFileLineAndRule) {
    write("a.png", 1);
    write("b.png", 2);
    write_text("timestamps.txt", "1000\n900\n");
    auto src = ReplaySource::open({dir_, 30.0, false});
    ASSERT_FALSE(src.ok());
    EXPECT_EQ(src.code(), EINVAL);
    EXPECT_NE(src.error().message.find("timestamps.txt:2"), std::string::npos) << src.error().message;
    EXPECT_NE(src.error().message.find("does not increase"), std::string::npos);

    write_text("timestamps.txt", "1000\n");
    src = ReplaySource::open({dir_, 30.0, false});
    ASSERT_FALSE(src.ok());
    EXPECT_NE(src.error().message.find("1 timestamps for 2 images"), std::string::npos) << src.error().message;

    write_text("timestamps.txt", "1000\nabc\n");
    src = ReplaySource::open({dir_, 30.0, false});
    ASSERT_FALSE(src.ok());
    EXPECT_NE(src.error().message.find("'abc' is not an integer"), std::string::npos) << src.error().message;
}

TEST_F(ReplayFolder, CorruptImageIsEbadmsgNamingTheFileAndPlaybackContinues) {
    write_text("0-broken.png", "this is not a png");
    write("1-good.png", 7);
    auto src = ReplaySource::open({dir_, 30.0, false});
    ASSERT_TRUE(src.ok());
    auto bad = (*src)->next_frame();
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.code(), EBADMSG);
    EXPECT_NE(bad.error().message.find("0-broken.png"), std::string::npos) << bad.error().message;
    auto good = (*src)->next_frame();
    ASSERT_TRUE(good.ok());
    EXPECT_EQ(good->image.at(0, 0), 7);
}

TEST_F(ReplayFolder, MissingOrEmptyFolderAndBadRate) {
    auto src = ReplaySource::open({dir_ / "absent", 30.0, false});
    ASSERT_FALSE(src.ok());
    EXPECT_EQ(src.code(), ENOENT);
    EXPECT_NE(src.error().message.find("absent"), std::string::npos);

    src = ReplaySource::open({dir_, 30.0, false});
    ASSERT_FALSE(src.ok());
    EXPECT_EQ(src.code(), ENOENT);
    EXPECT_NE(src.error().message.find("no .png/.pgm/.jpg/.jpeg images"), std::string::npos);

    src = ReplaySource::open({dir_, 0.0, false});
    ASSERT_FALSE(src.ok());
    EXPECT_EQ(src.code(), EINVAL);
    EXPECT_NE(src.error().message.find("frames_per_second"), std::string::npos);
}

// skip-before-decode: a frame whose successor is due is dropped without being read, so a corrupt
// file among the dropped ones costs nothing and raises no EBADMSG; the last frame, with no
// successor, is never dropped.
TEST_F(ReplayFolder, SkippingDueFramesDoesNotDecodeThem) {
    write("f0.png", 10);
    write_text("f1.png", "not a PNG: decoding this would fail");
    write_text("f2.png", "nor this");
    write("f3.png", 40);
    auto probe = ReplaySource::open({dir_, 10.0, false});  // 100 ms per frame
    ASSERT_TRUE(probe.ok()) << probe.error().message;
    ASSERT_TRUE((*probe)->next_frame().ok());
    EXPECT_EQ((*probe)->next_frame().code(), EBADMSG);  // f1 really cannot be decoded

    auto src = ReplaySource::open({dir_, 10.0, false});
    ASSERT_TRUE(src.ok());
    auto first = (*src)->next_frame();
    ASSERT_TRUE(first.ok()) << first.error().message;
    EXPECT_EQ((*src)->skip_frames_due_by(199'999'999), 0U);  // f1's successor f2 is due at 200 ms
    EXPECT_EQ((*src)->skip_frames_due_by(300'000'000), 2U);  // f1 and f2; f3 is the last
    EXPECT_EQ((*src)->skip_frames_due_by(900'000'000), 0U);
    auto last = (*src)->next_frame();
    ASSERT_TRUE(last.ok()) << last.error().message;
    EXPECT_EQ(last->sequence, 3U);
    EXPECT_EQ(last->timestamp_ns, 300'000'000);
    EXPECT_NEAR(last->image.at(3, 3), 40, 1);
}

// Looping, far behind: whole passes are skipped at once and the frame handed out next is the one
// being captured at `now` (its successor not yet due), with the sequence number of its pass.
TEST_F(ReplayFolder, SkippingWhileLoopingLandsOnTheCurrentFrame) {
    write("a.png", 1);
    write("b.png", 2);
    write("c.png", 3);
    auto src = ReplaySource::open({dir_, 10.0, true});  // a pass is 300 ms
    ASSERT_TRUE(src.ok());
    const std::int64_t now = 1'000'000LL * 300'000'000 + 150'000'000;  // a million passes + 150 ms
    const std::uint64_t skipped = (*src)->skip_frames_due_by(now);
    EXPECT_EQ(skipped, 3'000'001U);  // frames 0 .. 3e6: the frame at now - 50 ms is next
    ASSERT_EQ((*src)->next_capture_time_ns(), std::optional<std::int64_t>(now - 50'000'000));
    auto frame = (*src)->next_frame();
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    EXPECT_EQ(frame->sequence, 3'000'001U);
    EXPECT_NEAR(frame->image.at(3, 3), 2, 1);  // b.png
}

}  // namespace
}  // namespace mogao
