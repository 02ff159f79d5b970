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

// A header error (here: a marker length that runs past the data) left libjpeg-turbo 2.1's handle
// unusable, so every later good frame failed too: the decoder must recover on the next frame.
TEST(MjpegDecoder, RecoversAfterACorruptFrame) {
    auto decoder = MjpegDecoder::create();
    ASSERT_TRUE(decoder.ok());
    const auto good = ramp_jpeg(64, 16);
    std::vector<std::uint8_t> bogus_length = good;
    for (std::size_t i = 0; i + 6 < bogus_length.size(); ++i) {
        if (bogus_length[i] == 0xFF && bogus_length[i + 1] == 0xC0) {  // SOF0: length field follows
            bogus_length[i + 5] = 0;                                   // height 0 in the frame header
            bogus_length[i + 6] = 0;
            break;
        }
    }
    std::vector<std::uint8_t> scrambled = good;  // damaged tables: "SOS before SOF"
    for (std::size_t i = 20; i < 200 && i < scrambled.size(); ++i) scrambled[i] ^= 0x5A;
    const std::vector<std::uint8_t> truncated(good.begin(),
                                              good.begin() + static_cast<std::ptrdiff_t>(good.size() / 2));
    const std::vector<const std::vector<std::uint8_t>*> bads{&bogus_length, &scrambled, &truncated};
    for (const std::vector<std::uint8_t>* bad : bads) {
        GrayImage out;
        ASSERT_TRUE(decoder->decode_grey(good, out, 64, 16).ok());
        const Status s = decoder->decode_grey(*bad, out, 64, 16);
        ASSERT_FALSE(s.ok());
        EXPECT_EQ(s.code(), EBADMSG);
        const Status again = decoder->decode_grey(good, out, 64, 16);
        ASSERT_TRUE(again.ok()) << "after '" << s.error().message << "': " << again.error().message;
        EXPECT_NEAR(out.at(63, 8), 255, 4);
        Rgb8Image colour;
        ASSERT_TRUE(decoder->decode_colour(*bad, out, colour).code() == EBADMSG);
        ASSERT_TRUE(decoder->decode_colour(good, out, colour, 64, 16).ok());
    }
}

// A frame whose entropy-coded data is damaged but complete decodes as a smeared image with only a
// libjpeg warning: an error here. Frames above the size limit are refused before decoding.
TEST(MjpegDecoder, DamagedEntropyDataAndOversizedFramesAreErrors) {
    auto decoder = MjpegDecoder::create();
    ASSERT_TRUE(decoder.ok());
    const auto good = ramp_jpeg(64, 16);
    std::size_t sos = 0;
    for (std::size_t i = 0; i + 1 < good.size(); ++i) {
        if (good[i] == 0xFF && good[i + 1] == 0xDA) sos = i;
    }
    ASSERT_GT(sos, 0u);
    std::vector<std::uint8_t> damaged = good;
    for (std::size_t i = sos + 20; i < sos + 40 && i < damaged.size(); ++i) {
        if (damaged[i] != 0xFF && damaged[i] != 0x00) damaged[i] ^= 0x33;  // no new markers
    }
    GrayImage out;
    const Status s = decoder->decode_grey(damaged, out);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), EBADMSG);
    const std::vector<std::uint8_t> huge(kMaxMjpegFrameBytes + 1, 0xFF);
    const Status big = decoder->decode_grey(huge, out);
    ASSERT_FALSE(big.ok());
    EXPECT_NE(big.error().message.find("above the limit"), std::string::npos) << big.error().message;
}

TEST(MjpegDecoder, DecodesColourAndItsLuma) {
    auto decoder = MjpegDecoder::create();
    ASSERT_TRUE(decoder.ok());
    const auto jpeg = ramp_jpeg(64, 16);
    GrayImage grey;
    Rgb8Image colour;
    ASSERT_TRUE(decoder->decode_colour(jpeg, grey, colour, 64, 16).ok());
    ASSERT_EQ(colour.size.width, 64);
    ASSERT_EQ(grey.width, 64);
    GrayImage luma;
    ASSERT_TRUE(decoder->decode_grey(jpeg, luma).ok());
    for (int x = 0; x < 64; x += 7) {
        EXPECT_NEAR(colour.at(x, 8)[0], x * 255 / 63, 4) << "x=" << x;
        EXPECT_NEAR(grey.at(x, 8), luma.at(x, 8), 1) << "x=" << x;
    }
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
