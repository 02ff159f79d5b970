// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/connecting_screen.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "kiosk/display/bitmap_font.h"

namespace mogao {
namespace {

struct Census {
    double mean = 0;            // mean code over all samples
    double black_fraction = 0;  // pixels with every channel <= 8
    long bright = 0;            // pixels with every channel >= 200 (the title)
    long bright_in_middle = 0;  // ... in the middle third of the rows
};

Census census(const Rgb8Image& image) {
    Census c;
    const int w = image.size.width, h = image.size.height;
    long black = 0;
    double sum = 0;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const std::uint8_t* p = image.at(x, y);
            sum += p[0] + p[1] + p[2];
            if (p[0] <= 8 && p[1] <= 8 && p[2] <= 8) ++black;
            if (p[0] >= 200 && p[1] >= 200 && p[2] >= 200) {
                ++c.bright;
                if (y >= h / 3 && y < 2 * h / 3) ++c.bright_in_middle;
            }
        }
    }
    c.mean = sum / (3.0 * w * h);
    c.black_fraction = static_cast<double>(black) / (static_cast<double>(w) * h);
    return c;
}

TEST(ConnectingScreen, IsDimButNeverBlackAndCarriesTheTitle) {
    for (const ImageSize size : {ImageSize{1920, 1080}, ImageSize{480, 270}, ImageSize{160, 90}}) {
        const Rgb8Image image = make_connecting_screen(size, "FARM [FD00:6D6F::1]:7443");
        ASSERT_EQ(image.size, size);
        const Census c = census(image);
        EXPECT_EQ(c.black_fraction, 0.0) << size.width << ": no pixel is black";
        EXPECT_GT(c.mean, 20.0) << size.width;
        EXPECT_LT(c.mean, 90.0) << size.width << ": dim, not a white flash";
        EXPECT_GT(c.bright, 0) << size.width << ": the title is drawn";
        EXPECT_EQ(c.bright, c.bright_in_middle) << size.width << ": the title sits in the middle";
    }
}

TEST(ConnectingScreen, TheDetailLineIsDrawnBelowTheTitle) {
    const Rgb8Image without = make_connecting_screen({480, 270}, "");
    const Rgb8Image with = make_connecting_screen({480, 270}, "FARM [::1]:7443");
    long differing = 0;
    int lowest_row = -1;
    for (int y = 0; y < 270; ++y) {
        for (int x = 0; x < 480; ++x) {
            if (with.at(x, y)[0] != without.at(x, y)[0]) {
                ++differing;
                lowest_row = y;
            }
        }
    }
    EXPECT_GT(differing, 50);
    EXPECT_GT(lowest_row, 135);
}

TEST(ConnectingScreen, TinySizesWorkAndBadSizesThrow) {
    EXPECT_EQ(make_connecting_screen({1, 1}, "X").pixels.size(), 3u);
    EXPECT_EQ(census(make_connecting_screen({17, 3}, "LONG DETAIL TEXT")).black_fraction, 0.0);
    EXPECT_THROW((void)make_connecting_screen({0, 10}, ""), std::invalid_argument);
    EXPECT_THROW((void)make_connecting_screen({10, 20000}, ""), std::invalid_argument);
}

TEST(BitmapFont, GlyphsDifferAndUnknownCharactersAreQuestionMarks) {
    EXPECT_NE(glyph_rows('A'), glyph_rows('B'));
    EXPECT_EQ(glyph_rows('a'), glyph_rows('A'));
    EXPECT_EQ(glyph_rows('~'), glyph_rows('?'));
    EXPECT_EQ(text_width("AB", 2), (2 * kGlyphAdvance - 1) * 2);
    EXPECT_EQ(text_width("", 3), 0);
}

TEST(BitmapFont, DrawsScaledPixelsAndClipsAtTheEdges) {
    Rgb8Image image({12, 16});
    draw_text(image, 0, 0, 2, "I", {255, 0, 0});
    // 'I' row 0 is 01110: columns 1..3 at scale 2 -> pixels x 2..7 of rows 0..1.
    EXPECT_EQ(image.at(2, 0)[0], 255);
    EXPECT_EQ(image.at(7, 1)[0], 255);
    EXPECT_EQ(image.at(1, 0)[0], 0);
    EXPECT_EQ(image.at(8, 0)[0], 0);
    Rgb8Image small({3, 3});
    draw_text(small, -4, -4, 3, "WW", {1, 2, 3});  // partly outside: clipped, no crash
    draw_text(small, 100, 100, 1, "A", {1, 2, 3});
    SUCCEED();
}

}  // namespace
}  // namespace mogao
