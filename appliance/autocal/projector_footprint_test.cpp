// SPDX-License-Identifier: Apache-2.0
// A projector pixel's light at a continuous position (projector_footprint.h): the sharp box, a defocused ramp that
// stays continuous, the light lost beyond the image's border, and the refusals.
#include "appliance/autocal/projector_footprint.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

namespace mogao::autocal {
namespace {

double ramp_light(double t, int extent, double sigma) {
    const FootprintTaps taps = footprint_taps(t, extent, sigma);
    double light = 0.0;
    for (int i = 0; i < taps.count; ++i) light += taps.weight[static_cast<std::size_t>(i)] * (taps.first + i);
    return light;
}

TEST(ProjectorFootprint, ASharpPixelIsTheOneThatContainsThePosition) {
    for (const double t : {0.0, 0.49, 0.5, 7.99, 8.0, 99.7}) {
        const FootprintTaps taps = footprint_taps(t, 100, 0.0);
        ASSERT_EQ(taps.count, 1);
        EXPECT_EQ(taps.first, static_cast<int>(std::floor(t)));
        EXPECT_EQ(taps.weight[0], 1.0);
    }
    EXPECT_EQ(footprint_taps(120.0, 100, 0.0).first, 99);  // clamped, as output_pixel
}

// Pixel values rising by one per pixel (value q at pixel q, centre q + 1/2): a sharp projector's light steps by one
// at each pixel edge, a defocused one's is the ramp t - 1/2 itself up to a ripple of about exp(-2 pi^2 sigma^2) / pi
// (the box's spectrum has simple zeros at the pixel frequency; 0.013 at sigma 0.4) and the 5-sigma cut, so two such
// ramps that sum to 1 at the pixel centres sum to 1 between them as well.
TEST(ProjectorFootprint, ADefocusedRampOfPixelValuesIsAContinuousRampOfLight) {
    double sharp_worst = 0.0;
    for (double t = 40.0; t < 60.0; t += 0.05) {
        EXPECT_NEAR(ramp_light(t, 100, 0.4), t - 0.5, 0.015);
        for (const double sigma : {0.7, 1.0}) EXPECT_NEAR(ramp_light(t, 100, sigma), t - 0.5, 2e-4) << sigma;
        EXPECT_NEAR(ramp_light(t, 100, 3.0), t - 0.5, 2e-3);
        sharp_worst = std::max(sharp_worst, std::abs(ramp_light(t, 100, 0.0) - (t - 0.5)));
    }
    EXPECT_NEAR(sharp_worst, 0.5, 0.05);
    const FootprintTaps interior = footprint_taps(50.3, 100, 0.7);
    double sum = 0.0;
    for (int i = 0; i < interior.count; ++i) sum += interior.weight[static_cast<std::size_t>(i)];
    EXPECT_NEAR(sum, 1.0, 1e-6);
}

TEST(ProjectorFootprint, LightSpreadBeyondTheImageIsLostAndBadBlurIsRefused) {
    const FootprintTaps edge = footprint_taps(0.0, 100, 0.7);  // the image's left border
    double sum = 0.0;
    for (int i = 0; i < edge.count; ++i) sum += edge.weight[static_cast<std::size_t>(i)];
    EXPECT_EQ(edge.first, 0);
    EXPECT_NEAR(sum, 0.5, 1e-3);
    EXPECT_EQ(footprint_taps(-10.0, 100, 0.7).count, 0);
    EXPECT_THROW((void)footprint_taps(1.0, 100, -0.1), std::invalid_argument);
    EXPECT_THROW((void)footprint_taps(1.0, 100, 10.5), std::invalid_argument);
    EXPECT_THROW((void)footprint_taps(1.0, 0, 1.0), std::invalid_argument);
    EXPECT_NO_THROW((void)footprint_taps(1.0, 100, 10.0));
}

}  // namespace
}  // namespace mogao::autocal
