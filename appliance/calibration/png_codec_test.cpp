// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/png_codec.h"

#include <png.h>

#include <string>

#include <gtest/gtest.h>

#include "appliance/calibration/mpcdi_error.h"

namespace mogao {
namespace {

std::vector<std::string> chunk_types(const std::vector<std::uint8_t>& png) {
    std::vector<std::string> types;
    std::size_t pos = 8;
    while (pos + 8 <= png.size()) {
        const std::size_t length = std::size_t{png[pos]} << 24 | std::size_t{png[pos + 1]} << 16 |
                                   std::size_t{png[pos + 2]} << 8 | png[pos + 3];
        types.emplace_back(reinterpret_cast<const char*>(png.data() + pos + 4), 4);
        pos += 12 + length;
    }
    return types;
}

std::string error_of(const std::vector<std::uint8_t>& bytes) {
    try {
        (void)decode_png_map(bytes, "f.mpcdi: entry 'A.png'");
    } catch (const MpcdiError& e) {
        return e.what();
    }
    return "";
}

TEST(PngCodec, RoundTripsGrayRgbAnd16Bit) {
    PngMap gray{{3, 2}, 1, 8, {0, 1, 2, 253, 254, 255}};
    PngMap rgb{{2, 1}, 3, 8, {10, 20, 30, 40, 50, 60}};
    PngMap deep{{2, 2}, 1, 16, {0, 1, 65534, 65535}};
    for (const PngMap& m : {gray, rgb, deep}) {
        const std::vector<std::uint8_t> bytes = encode_png_map(m, "test");
        EXPECT_EQ(decode_png_map(bytes, "test"), m);
        // Like the reference writer: no gAMA/sRGB/iCCP, so no reader colour-manages the values.
        const std::vector<std::string> expected = {"IHDR", "IDAT", "IEND"};
        EXPECT_EQ(chunk_types(bytes), expected);
    }
}

TEST(PngCodec, RejectsOtherColourTypesAndGarbage) {
    // An RGBA PNG written with libpng's simplified API: colour type 6.
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    image.width = 2;
    image.height = 1;
    image.format = PNG_FORMAT_RGBA;
    const std::uint8_t pixels[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    png_alloc_size_t size = 1024;
    std::vector<std::uint8_t> rgba(size);
    ASSERT_NE(png_image_write_to_memory(&image, rgba.data(), &size, 0, pixels, 0, nullptr), 0);
    rgba.resize(size);
    EXPECT_NE(error_of(rgba).find("entry 'A.png': PNG: colour type 6 is not supported"), std::string::npos)
        << error_of(rgba);

    EXPECT_NE(error_of({1, 2, 3}).find("not a PNG (bad signature)"), std::string::npos);
    std::vector<std::uint8_t> truncated =
        encode_png_map(PngMap{{64, 64}, 1, 8, std::vector<std::uint16_t>(4096, 7)}, "t");
    truncated.resize(truncated.size() / 2);
    EXPECT_NE(error_of(truncated).find("PNG:"), std::string::npos) << error_of(truncated);
}

TEST(PngCodec, EncoderRejectsInconsistentMaps) {
    EXPECT_THROW((void)encode_png_map(PngMap{{1, 1}, 2, 8, {0, 0}}, "t"), MpcdiError);
    EXPECT_THROW((void)encode_png_map(PngMap{{1, 1}, 1, 4, {0}}, "t"), MpcdiError);
    EXPECT_THROW((void)encode_png_map(PngMap{{1, 1}, 1, 8, {256}}, "t"), MpcdiError);
    EXPECT_THROW((void)encode_png_map(PngMap{{2, 1}, 1, 8, {0}}, "t"), MpcdiError);
}

}  // namespace
}  // namespace mogao
