// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/pixel_format.h"

#include <linux/videodev2.h>

#include <gtest/gtest.h>

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

TEST(PixelConversion, Names) {
    EXPECT_EQ(fourcc_name(V4L2_PIX_FMT_YUYV), "YUYV");
    EXPECT_EQ(fourcc_name(V4L2_PIX_FMT_MJPEG), "MJPG");
    EXPECT_EQ(fourcc_name(0x01020304), "????");
    EXPECT_EQ(pixel_format_name(CaptureFormat::grey), "GREY");
}

}  // namespace
}  // namespace mogao
