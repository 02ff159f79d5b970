// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/pixel_format.h"

#include <linux/videodev2.h>

#include <gtest/gtest.h>

#include <utility>
#include <vector>

namespace mogao {
namespace {

TEST(PixelConversion, YuyvKeepsLumaAndSkipsRowPadding) {
    const int width = 4;
    const int height = 2;
    const int stride = 12;  // 8 bytes of pixels + 4 of padding
    std::vector<std::uint8_t> data(static_cast<std::size_t>(stride * height), 0xEE);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            data[static_cast<std::size_t>(y * stride + 2 * x)] = static_cast<std::uint8_t>(10 * y + x);  // Y
            data[static_cast<std::size_t>(y * stride + 2 * x + 1)] = 128;                                // U or V
        }
    }
    GrayImage out;
    ASSERT_TRUE(grey_from_yuyv(data, width, height, stride, out).ok());
    ASSERT_TRUE(out.valid());
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) EXPECT_EQ(out.at(x, y), 10 * y + x) << x << "," << y;
    }
}

TEST(PixelConversion, PackedRgbInBothByteOrders) {
    // 2x2 pixels, rows 8 bytes apart (2 bytes of padding); bytes R G B (RGB3) or B G R (BGR3).
    const std::vector<std::uint8_t> rgb{255, 0, 0, 0, 255, 0, 9, 9, 0, 0, 255, 10, 20, 30, 9, 9};
    std::vector<std::uint8_t> bgr = rgb;
    for (std::size_t i = 0; i + 2 < bgr.size(); i += (i % 8 == 3 ? 5 : 3)) std::swap(bgr[i], bgr[i + 2]);
    for (const auto& [format, bytes] : {std::pair{CaptureFormat::rgb24, rgb}, std::pair{CaptureFormat::bgr24, bgr}}) {
        GrayImage grey;
        Rgb8Image colour;
        ASSERT_TRUE(convert_rgb24(format, bytes, 2, 2, 8, grey, &colour).ok()) << pixel_format_name(format);
        EXPECT_EQ(colour.pixels, (std::vector<std::uint8_t>{255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30}));
        // BT.601 luma: red 0.299 * 255 = 76.2, green 149.7, blue 29.1, (10, 20, 30) 17.9.
        EXPECT_EQ(grey.pixels, (std::vector<std::uint8_t>{76, 150, 29, 18})) << pixel_format_name(format);
    }
    GrayImage grey;
    EXPECT_EQ(convert_rgb24(CaptureFormat::rgb24, rgb, 2, 2, 5, grey, nullptr).code(), EINVAL);  // stride < 6
    EXPECT_EQ(convert_rgb24(CaptureFormat::rgb24, std::span(rgb).first(13), 2, 2, 8, grey, nullptr).code(), EINVAL);
    EXPECT_EQ(convert_rgb24(CaptureFormat::yuyv, rgb, 2, 2, 8, grey, nullptr).code(), EINVAL);
    EXPECT_EQ(pixel_format_name(CaptureFormat::rgb24), "RGB3");
    EXPECT_EQ(pixel_format_name(CaptureFormat::bgr24), "BGR3");
}

TEST(PixelConversion, GreyCopiesRowsAndAcceptsAShortLastRow) {
    const int width = 3;
    const int stride = 5;
    // The last row has no padding: 5 + 3 bytes suffice for two rows.
    const std::vector<std::uint8_t> data{1, 2, 3, 0, 0, 4, 5, 6};
    GrayImage out;
    ASSERT_TRUE(grey_from_grey(data, width, 2, stride, out).ok());
    EXPECT_EQ(out.pixels, (std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6}));
}

TEST(PixelConversion, BadLayoutsNameTheLimit) {
    GrayImage out;
    const std::vector<std::uint8_t> data(100, 0);
    Status s = grey_from_grey(data, 20, 10, 20, out);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), EINVAL);
    EXPECT_NE(s.error().message.find("200 needed"), std::string::npos) << s.error().message;

    s = grey_from_yuyv(data, 5, 2, 10, out);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("odd"), std::string::npos) << s.error().message;

    s = grey_from_yuyv(data, 4, 2, 6, out);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("below the row size 8"), std::string::npos) << s.error().message;

    s = grey_from_grey(data, 0, 10, 10, out);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("outside [1, 8192]"), std::string::npos) << s.error().message;
}

// Reference colours: 100% colour bars as the standards code them (8-bit), and the R'G'B' they
// stand for. BT.601 limited: ITU-R BT.601-7 Table 3 / SMPTE EG 1; BT.709 limited: ITU-R BT.709-6
// Part 1, 3.2-3.5; full range: the JFIF equations of ITU-T T.871, section 7.
struct Bar {
    std::uint8_t y, cb, cr;
    std::uint8_t r, g, b;
};

void expect_bars(YcbcrEncoding encoding, const std::vector<Bar>& bars) {
    for (const Bar& bar : bars) {
        std::uint8_t rgb[3] = {};
        rgb_from_ycbcr(bar.y, bar.cb, bar.cr, encoding, rgb);
        EXPECT_NEAR(rgb[0], bar.r, 2) << ycbcr_encoding_name(encoding) << " Y'CbCr " << int{bar.y} << "," << int{bar.cb}
                                      << "," << int{bar.cr};
        EXPECT_NEAR(rgb[1], bar.g, 2) << ycbcr_encoding_name(encoding) << " Y' " << int{bar.y};
        EXPECT_NEAR(rgb[2], bar.b, 2) << ycbcr_encoding_name(encoding) << " Y' " << int{bar.y};
    }
}

TEST(PixelConversion, YcbcrToRgbMatchesTheStandardsColourBars) {
    expect_bars({YcbcrMatrix::bt601, YcbcrRange::limited}, {{235, 128, 128, 255, 255, 255},
                                                            {16, 128, 128, 0, 0, 0},
                                                            {81, 90, 240, 255, 0, 0},
                                                            {145, 54, 34, 0, 255, 0},
                                                            {41, 240, 110, 0, 0, 255},
                                                            {210, 16, 146, 255, 255, 0}});
    expect_bars({YcbcrMatrix::bt709, YcbcrRange::limited}, {{235, 128, 128, 255, 255, 255},
                                                            {63, 102, 240, 255, 0, 0},
                                                            {173, 42, 26, 0, 255, 0},
                                                            {32, 240, 118, 0, 0, 255}});
    expect_bars({YcbcrMatrix::bt601, YcbcrRange::full}, {{255, 128, 128, 255, 255, 255},
                                                         {0, 128, 128, 0, 0, 0},
                                                         {76, 85, 255, 254, 0, 0},
                                                         {150, 44, 21, 0, 255, 1},
                                                         {29, 255, 107, 0, 0, 255}});
    // Limited-range footroom and headroom clamp rather than wrap.
    expect_bars({YcbcrMatrix::bt601, YcbcrRange::limited}, {{0, 128, 128, 0, 0, 0}, {255, 128, 128, 255, 255, 255}});
}

TEST(PixelConversion, V4l2ColourFieldsPickMatrixAndRange) {
    using E = YcbcrEncoding;
    EXPECT_EQ(ycbcr_encoding_from_v4l2(V4L2_COLORSPACE_SRGB, V4L2_YCBCR_ENC_DEFAULT, V4L2_QUANTIZATION_DEFAULT),
              (E{YcbcrMatrix::bt601, YcbcrRange::limited}));
    EXPECT_EQ(ycbcr_encoding_from_v4l2(V4L2_COLORSPACE_REC709, V4L2_YCBCR_ENC_DEFAULT, V4L2_QUANTIZATION_DEFAULT),
              (E{YcbcrMatrix::bt709, YcbcrRange::limited}));
    EXPECT_EQ(ycbcr_encoding_from_v4l2(V4L2_COLORSPACE_JPEG, V4L2_YCBCR_ENC_DEFAULT, V4L2_QUANTIZATION_DEFAULT),
              (E{YcbcrMatrix::bt601, YcbcrRange::full}));
    EXPECT_EQ(ycbcr_encoding_from_v4l2(V4L2_COLORSPACE_SRGB, V4L2_YCBCR_ENC_709, V4L2_QUANTIZATION_FULL_RANGE),
              (E{YcbcrMatrix::bt709, YcbcrRange::full}));
    EXPECT_EQ(ycbcr_encoding_from_v4l2(V4L2_COLORSPACE_BT2020, V4L2_YCBCR_ENC_DEFAULT, V4L2_QUANTIZATION_LIM_RANGE),
              (E{YcbcrMatrix::bt2020, YcbcrRange::limited}));
}

TEST(PixelConversion, YuyvToRgbSharesChromaOfAPair) {
    // Two pixels: white and black luma sharing neutral chroma, then a red pair (BT.601 limited).
    const std::vector<std::uint8_t> data{235, 128, 16, 128, 81, 90, 81, 240};
    Rgb8Image out;
    ASSERT_TRUE(rgb_from_yuyv(data, 4, 1, 8, {YcbcrMatrix::bt601, YcbcrRange::limited}, out).ok());
    ASSERT_EQ(out.size.width, 4);
    EXPECT_EQ(std::vector<int>(out.pixels.begin(), out.pixels.begin() + 6), (std::vector<int>{255, 255, 255, 0, 0, 0}));
    EXPECT_NEAR(out.at(2, 0)[0], 255, 2);
    EXPECT_NEAR(out.at(3, 0)[1], 0, 2);
}

// A 4x2 frame: luma 10*y + x + 100; chroma sample 0 red, sample 1 blue (BT.709 limited codes).
struct Yuv420Fixture {
    static constexpr int kWidth = 4;
    static constexpr int kHeight = 2;
    std::vector<std::uint8_t> luma{100, 101, 102, 103, 110, 111, 112, 113};
    std::uint8_t cb[2] = {102, 240};
    std::uint8_t cr[2] = {240, 118};

    void expect(const GrayImage& grey, const Rgb8Image& colour) const {
        ASSERT_EQ(grey.pixels, luma);
        ASSERT_EQ(colour.size.width, kWidth);
        ASSERT_EQ(colour.size.height, kHeight);
        const YcbcrEncoding enc{YcbcrMatrix::bt709, YcbcrRange::limited};
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                std::uint8_t want[3];
                rgb_from_ycbcr(luma[static_cast<std::size_t>(y * kWidth + x)], cb[x / 2], cr[x / 2], enc, want);
                for (int c = 0; c < 3; ++c) EXPECT_EQ(colour.at(x, y)[c], want[c]) << x << "," << y << " c" << c;
            }
        }
        // Chroma 0 is reddish, chroma 1 bluish: the conversion used the right planes in the right order.
        EXPECT_GT(colour.at(0, 0)[0], colour.at(0, 0)[2]);
        EXPECT_GT(colour.at(3, 1)[2], colour.at(3, 1)[0]);
    }
};

TEST(PixelConversion, Yuv420OneBufferLayouts) {
    const Yuv420Fixture f;
    const YcbcrEncoding enc{YcbcrMatrix::bt709, YcbcrRange::limited};
    const int stride = 6;  // 2 bytes of row padding
    std::vector<std::uint8_t> luma_plane(static_cast<std::size_t>(stride * 2), 0xEE);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x)
            luma_plane[static_cast<std::size_t>(y * stride + x)] = f.luma[static_cast<std::size_t>(y * 4 + x)];
    struct Case {
        CaptureFormat format;
        std::vector<std::uint8_t> chroma;
    };
    const Case cases[] = {
        {CaptureFormat::nv12, {f.cb[0], f.cr[0], f.cb[1], f.cr[1], 0xEE, 0xEE}},
        {CaptureFormat::nv21, {f.cr[0], f.cb[0], f.cr[1], f.cb[1], 0xEE, 0xEE}},
        {CaptureFormat::yuv420, {f.cb[0], f.cb[1], 0xEE, f.cr[0], f.cr[1], 0xEE}},  // chroma stride 3
        {CaptureFormat::yvu420, {f.cr[0], f.cr[1], 0xEE, f.cb[0], f.cb[1], 0xEE}},
    };
    for (const Case& c : cases) {
        std::vector<std::uint8_t> buffer = luma_plane;
        buffer.insert(buffer.end(), c.chroma.begin(), c.chroma.end());
        const PlaneBytes plane{buffer, stride};
        GrayImage grey;
        Rgb8Image colour;
        const Status s = convert_yuv420(c.format, std::span(&plane, 1), 4, 2, enc, grey, &colour);
        ASSERT_TRUE(s.ok()) << pixel_format_name(c.format) << ": " << s.error().message;
        SCOPED_TRACE(pixel_format_name(c.format));
        f.expect(grey, colour);
    }
}

TEST(PixelConversion, Yuv420MultiPlaneLayoutsAndGreyOnly) {
    const Yuv420Fixture f;
    const YcbcrEncoding enc{YcbcrMatrix::bt709, YcbcrRange::limited};
    const std::vector<std::uint8_t> cbcr{f.cb[0], f.cr[0], f.cb[1], f.cr[1]};
    const std::vector<std::uint8_t> cb{f.cb[0], f.cb[1]};
    const std::vector<std::uint8_t> cr{f.cr[0], f.cr[1]};
    GrayImage grey;
    Rgb8Image colour;
    const PlaneBytes nv12m[] = {{f.luma, 4}, {cbcr, 4}};
    ASSERT_TRUE(convert_yuv420(CaptureFormat::nv12, nv12m, 4, 2, enc, grey, &colour).ok());
    f.expect(grey, colour);
    const PlaneBytes yvu420m[] = {{f.luma, 4}, {cr, 2}, {cb, 2}};
    ASSERT_TRUE(convert_yuv420(CaptureFormat::yvu420, yvu420m, 4, 2, enc, grey, &colour).ok());
    f.expect(grey, colour);
    // Grey only: the colour image is not touched.
    Rgb8Image untouched;
    GrayImage grey_only;
    ASSERT_TRUE(convert_yuv420(CaptureFormat::nv12, nv12m, 4, 2, enc, grey_only, nullptr).ok());
    EXPECT_EQ(grey_only.pixels, f.luma);
}

TEST(PixelConversion, Yuv420BadLayoutsNameThePlane) {
    const std::vector<std::uint8_t> luma(8, 0);
    const std::vector<std::uint8_t> short_chroma(3, 0);
    const YcbcrEncoding enc;
    GrayImage grey;
    Rgb8Image colour;
    const PlaneBytes nv12m[] = {{luma, 4}, {short_chroma, 4}};
    Status s = convert_yuv420(CaptureFormat::nv12, nv12m, 4, 2, enc, grey, &colour);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), EINVAL);
    EXPECT_NE(s.error().message.find("NV12 buffer, chroma plane 1: 3 bytes, 4 needed"), std::string::npos)
        << s.error().message;
    const PlaneBytes one[] = {{luma, 4}};  // no chroma at all after the luma
    s = convert_yuv420(CaptureFormat::yuv420, one, 4, 2, enc, grey, &colour);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("YU12 buffer, chroma plane 1"), std::string::npos) << s.error().message;
    const PlaneBytes two[] = {{luma, 4}, {short_chroma, 2}};
    s = convert_yuv420(CaptureFormat::yuv420, two, 4, 2, enc, grey, &colour);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("2 planes, expected 1 or 3"), std::string::npos) << s.error().message;
    s = convert_yuv420(CaptureFormat::yuyv, one, 4, 2, enc, grey, &colour);
    ASSERT_FALSE(s.ok());
}

TEST(PixelConversion, GreyAndRgbRoundTrip) {
    GrayImage grey(2, 1);
    grey.pixels = {7, 200};
    Rgb8Image rgb;
    rgb_from_grey(grey, rgb);
    EXPECT_EQ(rgb.pixels, (std::vector<std::uint8_t>{7, 7, 7, 200, 200, 200}));
    rgb.pixels = {255, 0, 0, 0, 0, 255};
    GrayImage luma;
    grey_from_rgb(rgb, luma);
    EXPECT_EQ(luma.pixels, (std::vector<std::uint8_t>{76, 29}));  // 0.299 * 255, 0.114 * 255
}

TEST(PixelConversion, Names) {
    EXPECT_EQ(fourcc_name(V4L2_PIX_FMT_YUYV), "YUYV");
    EXPECT_EQ(fourcc_name(V4L2_PIX_FMT_MJPEG), "MJPG");
    EXPECT_EQ(fourcc_name(0x01020304), "????");
    EXPECT_EQ(pixel_format_name(CaptureFormat::grey), "GREY");
    EXPECT_EQ(pixel_format_name(CaptureFormat::yuv420), "YU12");
    EXPECT_EQ(ycbcr_encoding_name({YcbcrMatrix::bt709, YcbcrRange::full}), "BT.709 full");
}

}  // namespace
}  // namespace mogao
