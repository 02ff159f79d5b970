// SPDX-License-Identifier: Apache-2.0
#include "common/jpeg_codec.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/image_compare.h"
#include "common/test_images.h"

namespace mogao {
namespace {

// A gradient with a fine diagonal texture on top, so the entropy-coded size depends on quality
// at every quality level (a pure gradient saturates at low quality).
Rgb8Image textured(ImageSize size) {
    Rgb8Image img = test_images::gradient(size);
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            if (((x + y) / 3) % 2 == 0) {
                std::uint8_t* p = img.at(x, y);
                p[0] = static_cast<std::uint8_t>(p[0] / 2);
            }
        }
    }
    return img;
}

// Byte offset of the first SOF0/SOF2 marker's height field (FF C0|C2, length, precision, height).
std::size_t sof_size_offset(const std::vector<std::uint8_t>& jpeg) {
    for (std::size_t i = 2; i + 8 < jpeg.size(); ++i) {
        if (jpeg[i] == 0xFF && (jpeg[i + 1] == 0xC0 || jpeg[i + 1] == 0xC2)) return i + 5;
    }
    ADD_FAILURE() << "no SOF marker";
    return 0;
}

void set_declared_size(std::vector<std::uint8_t>& jpeg, int width, int height) {
    const std::size_t at = sof_size_offset(jpeg);
    jpeg[at + 0] = static_cast<std::uint8_t>(height >> 8);
    jpeg[at + 1] = static_cast<std::uint8_t>(height & 0xFF);
    jpeg[at + 2] = static_cast<std::uint8_t>(width >> 8);
    jpeg[at + 3] = static_cast<std::uint8_t>(width & 0xFF);
}

// Start of the entropy-coded data: just after the SOS segment.
std::size_t scan_data_offset(const std::vector<std::uint8_t>& jpeg) {
    for (std::size_t i = 2; i + 3 < jpeg.size(); ++i) {
        if (jpeg[i] == 0xFF && jpeg[i + 1] == 0xDA) return i + 2 + (std::size_t{jpeg[i + 2]} << 8 | jpeg[i + 3]);
    }
    ADD_FAILURE() << "no SOS marker";
    return 0;
}

void expect_decode_error(JpegDecoder& decoder, const std::vector<std::uint8_t>& bytes, const std::string& what) {
    try {
        (void)decoder.decode(bytes);
        ADD_FAILURE() << what << ": decoded without error";
    } catch (const DecodeError& e) {
        EXPECT_NE(std::string(e.what()).find("JpegDecoder::decode"), std::string::npos) << e.what();
    }
}

TEST(JpegCodec, SmoothGradientAtQuality90HasHighPsnr) {
    const Rgb8Image original = test_images::gradient({320, 240});
    JpegEncoder encoder;
    JpegDecoder decoder;
    const auto jpeg = encoder.encode(original, 90);
    const Rgb8Image decoded = decoder.decode(jpeg);
    ASSERT_EQ(decoded.size, original.size);
    // 4:2:0 at quality 90 on this gradient measures 49.4 dB (libjpeg-turbo 2.1.5). The 45 dB bound
    // leaves margin for other versions yet fails for a wrong pixel format, stride or channel order.
    EXPECT_GT(psnr(original, decoded), 45.0);
    EXPECT_LT(jpeg.size(), original.pixels.size() / 10) << "not compressing";
}

TEST(JpegCodec, BytesDecreaseWithQuality) {
    const Rgb8Image image = textured({256, 256});
    JpegEncoder encoder;  // one handle reused for every encode, as in the farm
    std::size_t previous = 0;
    for (const int quality : {100, 95, 85, 75, 50, 25, 10, 1}) {
        const std::size_t bytes = encoder.encode(image, quality).size();
        if (previous != 0) {
            EXPECT_LT(bytes, previous) << "quality " << quality;
        }
        previous = bytes;
    }
}

TEST(JpegCodec, FullChromaIsLargerAndMoreFaithfulThan420) {
    const Rgb8Image image = textured({128, 96});
    JpegEncoder encoder;
    JpegDecoder decoder;
    const auto full = encoder.encode(image, 90, Subsampling::yuv444);
    const auto half = encoder.encode(image, 90, Subsampling::yuv420);
    EXPECT_GT(full.size(), half.size());
    EXPECT_GT(psnr(image, decoder.decode(full)), psnr(image, decoder.decode(half)));
}

TEST(JpegCodec, HandlesOddSizesAndReusesHandlesAcrossSizes) {
    JpegEncoder encoder;
    JpegDecoder decoder;
    for (const ImageSize size : {ImageSize{1, 1}, ImageSize{17, 3}, ImageSize{640, 360}, ImageSize{33, 65}}) {
        const Rgb8Image image = test_images::gradient(size);
        const Rgb8Image decoded = decoder.decode(encoder.encode(image, 95, Subsampling::yuv444));
        EXPECT_EQ(decoded.size, size);
        EXPECT_LE(max_abs_difference(image, decoded), 16.0) << size.width << "x" << size.height;
    }
}

TEST(JpegCodec, RejectsBadArguments) {
    JpegEncoder encoder;
    const Rgb8Image image = test_images::gradient({8, 8});
    EXPECT_THROW((void)encoder.encode(image, 0), std::invalid_argument);
    EXPECT_THROW((void)encoder.encode(image, 101), std::invalid_argument);
    Rgb8Image broken = image;
    broken.pixels.pop_back();
    EXPECT_THROW((void)encoder.encode(broken, 85), std::invalid_argument);
    EXPECT_THROW((void)encoder.encode(Rgb8Image{}, 85), std::invalid_argument);
}

static_assert(!std::is_copy_constructible_v<JpegEncoder> && std::is_nothrow_move_constructible_v<JpegEncoder> &&
              std::is_nothrow_move_assignable_v<JpegEncoder>);
static_assert(!std::is_copy_constructible_v<JpegDecoder> && std::is_nothrow_move_constructible_v<JpegDecoder> &&
              std::is_nothrow_move_assignable_v<JpegDecoder>);

TEST(JpegCodec, MovedFromHandlesAreEmptyAndMovedToWork) {
    JpegEncoder a;
    JpegEncoder b = std::move(a);
    const Rgb8Image image = test_images::gradient({16, 16});
    EXPECT_THROW((void)a.encode(image, 85), std::logic_error);  // NOLINT(bugprone-use-after-move)
    JpegDecoder d1;
    JpegDecoder d2;
    d2 = std::move(d1);
    EXPECT_THROW((void)d1.decode(b.encode(image, 85)), std::logic_error);  // NOLINT(bugprone-use-after-move)
    EXPECT_EQ(d2.decode(b.encode(image, 85)).size, image.size);
}

// The moved-to object's handle outlives the moved-from object (which must not tjDestroy it), and
// assignment replaces a live handle; a failed decode replaces the handle in place, and the new one
// moves like the old. Under the sanitizer build a second tjDestroy is a reported double free.
TEST(JpegCodec, MovedHandlesSurviveTheSourceAndAssignmentReplacesALiveOne) {
    const Rgb8Image image = test_images::gradient({24, 16});
    std::optional<JpegEncoder> source(std::in_place);
    JpegEncoder encoder = std::move(*source);
    source.reset();
    JpegEncoder replaced;
    replaced = std::move(encoder);
    const std::vector<std::uint8_t> jpeg = replaced.encode(image, 90);

    std::optional<JpegDecoder> first(std::in_place);
    EXPECT_THROW((void)first->decode(std::vector<std::uint8_t>(64, 0x42)), DecodeError);  // replaces the handle
    JpegDecoder decoder;
    decoder = std::move(*first);
    first.reset();
    EXPECT_EQ(decoder.decode(jpeg).size, image.size);
    JpegDecoder again = std::move(decoder);
    EXPECT_EQ(again.decode(jpeg).size, image.size);
    decoder = std::move(again);  // assigning into a moved-from object
    EXPECT_EQ(decoder.decode(jpeg).size, image.size);
}

TEST(JpegDecode, EmptyAndGarbageInputAreDecodeErrors) {
    JpegDecoder decoder;
    expect_decode_error(decoder, {}, "empty");
    expect_decode_error(decoder, test_images::noise({64, 64}).pixels, "random bytes");
    expect_decode_error(decoder, {0xFF, 0xD8}, "bare SOI");
    expect_decode_error(decoder, {0xFF, 0xD8, 0xFF, 0xD9}, "SOI EOI");
}

TEST(JpegDecode, TruncatedDataIsAnErrorNotAHalfImage) {
    JpegEncoder encoder;
    JpegDecoder decoder;
    const auto jpeg = encoder.encode(textured({128, 128}), 85);
    const std::size_t scan = scan_data_offset(jpeg);
    // Inside the header, right after it, halfway through the scan, and just before EOI. libjpeg
    // itself would return a grey-filled image for the last three (a warning, not an error).
    for (const std::size_t keep : {std::size_t{20}, scan, scan + (jpeg.size() - scan) / 2, jpeg.size() - 2}) {
        const std::vector<std::uint8_t> cut(jpeg.begin(), jpeg.begin() + static_cast<std::ptrdiff_t>(keep));
        expect_decode_error(decoder, cut, "truncated to " + std::to_string(keep));
    }
}

TEST(JpegDecode, CorruptDataIsAnError) {
    JpegEncoder encoder;
    JpegDecoder decoder;
    const auto jpeg = encoder.encode(textured({128, 128}), 85);

    auto bad_magic = jpeg;
    bad_magic[1] = 0x00;
    expect_decode_error(decoder, bad_magic, "bad SOI");

    // A marker in the middle of the entropy-coded data: libjpeg warns "premature end of data
    // segment" and pads with grey; we must refuse.
    auto stray_marker = jpeg;
    const std::size_t mid = scan_data_offset(jpeg) + 100;
    stray_marker[mid] = 0xFF;
    stray_marker[mid + 1] = 0xD9;
    expect_decode_error(decoder, stray_marker, "EOI inside scan");

    // The decoder stays usable after a failure (the handle's error state is per call).
    EXPECT_EQ(decoder.decode(jpeg).size, (ImageSize{128, 128}));
}

// Robustness sweep, mainly for the sanitizer build: every outcome must be a complete image of the
// declared size or a DecodeError; anything else (crash, other exception, other size) fails. After
// each failure the same decoder must still decode the intact file: libjpeg-turbo 2.1.5 leaves a
// handle unusable after some header errors, which JpegDecoder has to hide.
TEST(JpegDecode, DamagedStreamsGiveAnImageOrDecodeErrorAndNeverPoisonTheDecoder) {
    JpegEncoder encoder;
    JpegDecoder decoder;
    const auto jpeg = encoder.encode(textured({64, 48}), 80);
    auto still_usable = [&](const std::string& after) {
        try {
            EXPECT_EQ(decoder.decode(jpeg).size, (ImageSize{64, 48})) << "after " << after;
        } catch (const DecodeError& e) {
            ADD_FAILURE() << "intact JPEG refused after " << after << ": " << e.what();
        }
    };
    for (std::size_t keep = 0; keep < jpeg.size(); ++keep) {  // no truncation is acceptable
        const std::string what = "truncation to " + std::to_string(keep);
        expect_decode_error(
            decoder, std::vector<std::uint8_t>(jpeg.begin(), jpeg.begin() + static_cast<std::ptrdiff_t>(keep)), what);
        still_usable(what);
    }
    int refused = 0;
    std::uint32_t rng = 7;
    for (int trial = 0; trial < 300; ++trial) {
        auto damaged = jpeg;
        for (int flips = 0; flips < 3; ++flips) {
            rng = rng * 1664525u + 1013904223u;
            damaged[(rng >> 8) % damaged.size()] ^= static_cast<std::uint8_t>(1u << (rng >> 29));
        }
        try {
            EXPECT_EQ(decoder.decode(damaged).size, (ImageSize{64, 48}));
        } catch (const DecodeError&) {
            ++refused;
        }
        still_usable("bit flips, trial " + std::to_string(trial));
    }
    EXPECT_GT(refused, 0) << "no bit flip was detected: the sweep is not exercising the error path";
}

TEST(JpegDecode, DeclaredSizeAboveLimitIsRefusedBeforeAllocation) {
    JpegEncoder encoder;
    JpegDecoder decoder;
    const auto jpeg = encoder.encode(test_images::gradient({16, 16}), 85);

    auto huge = jpeg;
    set_declared_size(huge, 60000, 60000);  // 10.8 GB of RGB if we believed it
    try {
        (void)decoder.decode(huge);
        FAIL() << "60000x60000 accepted";
    } catch (const DecodeError& e) {
        EXPECT_NE(std::string(e.what()).find("60000x60000"), std::string::npos) << e.what();
    }
    auto just_over = jpeg;
    set_declared_size(just_over, kMaxDecodedDimension + 1, 16);
    expect_decode_error(decoder, just_over, "one column over the limit");
    auto zero = jpeg;
    set_declared_size(zero, 16, 0);
    expect_decode_error(decoder, zero, "zero height");
}

}  // namespace
}  // namespace mogao
