// SPDX-License-Identifier: Apache-2.0
#include "common/image_compare.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/test_images.h"

namespace mogao {
namespace {

TEST(ImageCompare, IdenticalImagesHaveInfinitePsnrAndNoDifference) {
    const Rgb8Image a = test_images::noise({13, 7});
    EXPECT_EQ(psnr(a, a), std::numeric_limits<double>::infinity());
    EXPECT_EQ(max_abs_difference(a, a), 0.0);
    EXPECT_EQ(count_differing_pixels(a, a), 0);
}

TEST(ImageCompare, UniformOffsetGivesKnownPsnr) {
    const Rgb8Image a(ImageSize{10, 10}, 100);
    const Rgb8Image b(ImageSize{10, 10}, 105);
    // MSE = 25 -> 10 log10(255^2 / 25) = 20 log10(51) = 34.1514 dB.
    EXPECT_NEAR(psnr(a, b), 20.0 * std::log10(51.0), 1e-12);
    EXPECT_NEAR(psnr(a, b), 34.1514, 1e-4);
    EXPECT_EQ(psnr(a, b), psnr(b, a));
    EXPECT_EQ(max_abs_difference(a, b), 5.0);
    EXPECT_EQ(count_differing_pixels(a, b), 100);
    EXPECT_EQ(count_differing_pixels(a, b, 5), 0);
    EXPECT_EQ(count_differing_pixels(a, b, 4), 100);
}

TEST(ImageCompare, SingleFullScaleErrorGivesTenLog10OfSampleCount) {
    const Rgb8Image a(ImageSize{20, 5}, 0);
    Rgb8Image b = a;
    b.at(3, 2)[1] = 255;  // one sample of 300 off by 255: MSE = 255^2 / 300
    EXPECT_NEAR(psnr(a, b), 10.0 * std::log10(300.0), 1e-12);
    EXPECT_EQ(max_abs_difference(a, b), 255.0);
    EXPECT_EQ(count_differing_pixels(a, b), 1);
}

TEST(ImageCompare, MismatchedOrMalformedImagesThrow) {
    const Rgb8Image a(ImageSize{4, 4}, 0);
    const Rgb8Image b(ImageSize{4, 5}, 0);
    EXPECT_THROW((void)psnr(a, b), std::invalid_argument);
    EXPECT_THROW((void)max_abs_difference(a, b), std::invalid_argument);
    EXPECT_THROW((void)count_differing_pixels(a, b), std::invalid_argument);
    Rgb8Image broken = a;
    broken.pixels.resize(5);
    EXPECT_THROW((void)psnr(a, broken), std::invalid_argument);
    EXPECT_THROW((void)count_differing_pixels(a, a, -1), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
