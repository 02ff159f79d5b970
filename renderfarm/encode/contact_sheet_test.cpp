// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/encode/contact_sheet.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <utility>
#include <vector>

#include "common/test_images.h"

namespace mogao {
namespace {

TEST(DownscaleBox, TwoByTwoCheckerGivesTheMean) {
    Rgb8Image checker(ImageSize{2, 2}, 0);
    for (std::uint8_t* p : {checker.at(1, 0), checker.at(0, 1)}) p[0] = p[1] = p[2] = 200;
    EXPECT_EQ(downscale_box(checker, {1, 1}).pixels, (std::vector<std::uint8_t>{100, 100, 100}));
    // Black/white: mean 127.5 rounds half up.
    for (std::uint8_t* p : {checker.at(1, 0), checker.at(0, 1)}) p[0] = p[1] = p[2] = 255;
    EXPECT_EQ(downscale_box(checker, {1, 1}).pixels, (std::vector<std::uint8_t>{128, 128, 128}));
}

TEST(DownscaleBox, FractionalFootprintsAreWeightedByCoverage) {
    Rgb8Image row(ImageSize{3, 1});
    row.pixels = {0, 0, 0, 90, 90, 90, 180, 180, 180};
    // 3 -> 2: output 0 covers source [0, 1.5) = (0 * 1 + 90 * 0.5) / 1.5 = 30, output 1 = 150.
    EXPECT_EQ(downscale_box(row, {2, 1}).pixels, (std::vector<std::uint8_t>{30, 30, 30, 150, 150, 150}));
}

TEST(DownscaleBox, IntegerFactorAveragesEachBlock) {
    const Rgb8Image src = test_images::noise({8, 12});
    const Rgb8Image out = downscale_box(src, {2, 3});
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 2; ++x) {
            for (int c = 0; c < 3; ++c) {
                int sum = 0;
                for (int v = 0; v < 4; ++v)
                    for (int u = 0; u < 4; ++u) sum += src.at(x * 4 + u, y * 4 + v)[c];
                EXPECT_EQ(out.at(x, y)[c], (sum + 8) / 16) << x << "," << y << "," << c;
            }
        }
    }
    EXPECT_EQ(downscale_box(src, src.size).pixels, src.pixels);
    EXPECT_THROW((void)downscale_box(src, {0, 3}), std::invalid_argument);
}

TEST(ContactSheet, DimensionsFollowTheDocumentedLayout) {
    const std::vector<Rgb8Image> frames(5, test_images::gradient({64, 32}));
    const Rgb8Image sheet = make_contact_sheet(frames, 3, 16, 4);
    // 3 columns x 2 rows of 16x8 thumbnails, 4 px borders.
    EXPECT_EQ(sheet.size, (ImageSize{3 * 16 + 4 * 4, 2 * 8 + 3 * 4}));
    // More columns than frames: only as many columns as frames.
    EXPECT_EQ(make_contact_sheet(frames, 10, 16, 2).size, (ImageSize{5 * 16 + 6 * 2, 8 + 2 * 2}));
    EXPECT_THROW((void)make_contact_sheet({}, 3, 16), std::invalid_argument);
    EXPECT_THROW((void)make_contact_sheet(frames, 0, 16), std::invalid_argument);
    EXPECT_THROW((void)make_contact_sheet(frames, 3, 0), std::invalid_argument);
}

TEST(ContactSheet, UniformFrameFillsItsCellWithItsColour) {
    std::vector<Rgb8Image> frames(3, test_images::noise({40, 20}));
    frames[1] = Rgb8Image(ImageSize{40, 20}, 0);
    for (std::size_t i = 0; i < frames[1].pixels.size(); i += 3) {
        frames[1].pixels[i] = 200;
        frames[1].pixels[i + 1] = 50;
        frames[1].pixels[i + 2] = 10;
    }
    const int border = 3;
    const Rgb8Image sheet = make_contact_sheet(frames, 3, 10, border);  // thumbnails 10x5
    const int x0 = border + (10 + border);                              // second cell
    for (int y = border; y < border + 5; ++y) {
        for (int x = x0; x < x0 + 10; ++x) {
            const std::uint8_t* p = sheet.at(x, y);
            ASSERT_EQ((std::vector<std::uint8_t>{p[0], p[1], p[2]}), (std::vector<std::uint8_t>{200, 50, 10}))
                << x << "," << y;
        }
    }
    // Border pixels on each side of the cell keep the background.
    for (const auto& [x, y] : {std::pair{x0 - 1, border}, std::pair{x0 + 10, border}, std::pair{x0, border - 1},
                               std::pair{x0, border + 5}}) {
        EXPECT_EQ(sheet.at(x, y)[0], kContactSheetBackground) << x << "," << y;
    }
}

TEST(ContactSheet, ShorterThumbnailsAreCentredInTallerCells) {
    const std::vector<Rgb8Image> frames = {Rgb8Image(ImageSize{40, 40}, 255), Rgb8Image(ImageSize{40, 20}, 255)};
    const Rgb8Image sheet = make_contact_sheet(frames, 2, 10, 0);  // cells 10x10, second thumb 10x5
    ASSERT_EQ(sheet.size, (ImageSize{20, 10}));
    EXPECT_EQ(sheet.at(15, 1)[0], kContactSheetBackground);
    EXPECT_EQ(sheet.at(15, 2)[0], 255);  // rows 2..6 hold the 5-row thumbnail ((10 - 5) / 2 = 2)
    EXPECT_EQ(sheet.at(15, 6)[0], 255);
    EXPECT_EQ(sheet.at(15, 7)[0], kContactSheetBackground);
}

}  // namespace
}  // namespace mogao
