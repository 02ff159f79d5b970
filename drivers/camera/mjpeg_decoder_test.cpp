// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/mjpeg_decoder.h"

#include <turbojpeg.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <cstdlib>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

namespace mogao {
namespace {

// A 4:2:2 colour JPEG (what UVC cameras send) of a horizontal grey ramp, made with TurboJPEG.
std::vector<std::uint8_t> ramp_jpeg(int width, int height) {
    std::vector<std::uint8_t> rgb(static_cast<std::size_t>(width * height * 3));
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            for (int c = 0; c < 3; ++c)
                rgb[static_cast<std::size_t>((y * width + x) * 3 + c)] =
                    static_cast<std::uint8_t>(x * 255 / (width - 1));
        }
    }
    tjhandle tj = tjInitCompress();
    unsigned char* out = nullptr;
    unsigned long size = 0;
    EXPECT_EQ(tjCompress2(tj, rgb.data(), width, 0, height, TJPF_RGB, &out, &size, TJSAMP_422, 95, 0), 0);
    std::vector<std::uint8_t> bytes(out, out + size);
    tjFree(out);
    tjDestroy(tj);
    return bytes;
}

TEST(MjpegDecoder, DecodesLumaOfAColourFrame) {
    auto decoder = MjpegDecoder::create();
    ASSERT_TRUE(decoder.ok());
    const auto jpeg = ramp_jpeg(64, 16);
    GrayImage out;
    ASSERT_TRUE(decoder->decode_grey(jpeg, out, 64, 16).ok());
    ASSERT_EQ(out.width, 64);
    ASSERT_EQ(out.height, 16);
    for (int x = 0; x < 64; x += 7) EXPECT_NEAR(out.at(x, 8), x * 255 / 63, 4) << "x=" << x;
}

TEST(MjpegDecoder, RefusesWrongSizeTruncatedAndEmptyFrames) {
    auto decoder = MjpegDecoder::create();
    ASSERT_TRUE(decoder.ok());
    const auto jpeg = ramp_jpeg(64, 16);
    GrayImage out;

    Status s = decoder->decode_grey(jpeg, out, 640, 480);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), EBADMSG);
    EXPECT_NE(s.error().message.find("64x16 differs from the negotiated 640x480"), std::string::npos)
        << s.error().message;

    const std::vector<std::uint8_t> truncated(jpeg.begin(),
                                              jpeg.begin() + static_cast<std::ptrdiff_t>(jpeg.size() / 2));
    s = decoder->decode_grey(truncated, out);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), EBADMSG);

    s = decoder->decode_grey({}, out);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), EBADMSG);

    const std::vector<std::uint8_t> junk(300, 0x42);
    s = decoder->decode_grey(junk, out);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), EBADMSG);
}

static_assert(!std::is_copy_constructible_v<MjpegDecoder> && std::is_nothrow_move_constructible_v<MjpegDecoder> &&
              std::is_nothrow_move_assignable_v<MjpegDecoder>);

TEST(MjpegDecoder, MovedFromDecoderIsSafeToDestroy) {
    auto decoder = MjpegDecoder::create();
    ASSERT_TRUE(decoder.ok());
    MjpegDecoder moved = std::move(decoder).value();
    MjpegDecoder other = std::move(moved);
    GrayImage out;
    EXPECT_TRUE(other.decode_grey(ramp_jpeg(8, 8), out).ok());
    const Status s = moved.decode_grey(ramp_jpeg(8, 8), out);  // NOLINT(bugprone-use-after-move)
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), EINVAL) << s.error().message;
}

// The handle outlives its moved-from owners (which must not tjDestroy it) and assignment replaces
// a live one; a double tjDestroy is a reported double free in the sanitizer build.
TEST(MjpegDecoder, MovedHandleOutlivesItsSourceAndAssignmentReplacesALiveOne) {
    auto first = MjpegDecoder::create();
    auto second = MjpegDecoder::create();
    ASSERT_TRUE(first.ok() && second.ok());
    std::optional<MjpegDecoder> source(std::move(first).value());
    MjpegDecoder target = std::move(*source);
    source.reset();
    MjpegDecoder replaced = std::move(second).value();
    replaced = std::move(target);
    GrayImage out;
    ASSERT_TRUE(replaced.decode_grey(ramp_jpeg(16, 8), out, 16, 8).ok());
    EXPECT_EQ(out.width, 16);
    target = std::move(replaced);  // into a moved-from decoder
    EXPECT_TRUE(target.decode_grey(ramp_jpeg(8, 8), out).ok());
    EXPECT_EQ(replaced.decode_grey(ramp_jpeg(8, 8), out).code(), EINVAL);  // NOLINT(bugprone-use-after-move)
}

}  // namespace
}  // namespace mogao
