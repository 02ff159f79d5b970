// SPDX-License-Identifier: Apache-2.0
// A projector's white where the camera clips it (camera_clipping.h), on images built from known light: the
// replaced light against the light the images were made from.
#include "appliance/autocal/camera_clipping.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

namespace mogao::autocal {
namespace {

constexpr float kBlack = 0.02f;
constexpr float kGreyShare = 1.0f / 4.6f;  // the grey's light over the white's (gamma 2.2 at signal 0.5)

// The camera's white and grey of a projector whose light is 0.5 on the left half and `right` on the right half,
// clipped at full scale, with Gaussian noise of `sigma` on each image.
struct Images {
    cv::Mat1f white, grey, black;
};

Images filmed(float right, float sigma) {
    std::mt19937 rng(11);
    std::normal_distribution<float> noise(0.0f, sigma);
    Images m{cv::Mat1f(64, 64), cv::Mat1f(64, 64), cv::Mat1f(64, 64, kBlack)};
    for (int y = 0; y < 64; ++y) {
        for (int x = 0; x < 64; ++x) {
            const float light = x < 32 ? 0.5f : right;
            m.white(y, x) = std::min(1.0f, kBlack + light + noise(rng));
            m.grey(y, x) = std::min(1.0f, kBlack + kGreyShare * light + noise(rng));
        }
    }
    return m;
}

// The mean replaced light over the clipped columns next to the unclipped half (where no window smooths the grey).
double edge_light(const DeclippedWhite& d) { return cv::mean(d.light.colRange(32, 34))[0]; }

// A white just at full scale is nearly its own light: the grey's noise, scaled by the ratio, must not raise it
// (it moved the noisy rig's edges by 0.04 px mean where every replaced pixel kept the larger of the two).
TEST(CameraClipping, AWhiteJustAtFullScaleKeepsItsLevel) {
    const Images m = filmed(1.0f, 0.01f);
    const DeclippedWhite d = declip_white(m.white, m.grey, m.black);
    ASSERT_GT(d.clipped_pixels, 1500);
    EXPECT_NEAR(d.ratio, 1.0 / kGreyShare, 0.2);
    EXPECT_NEAR(edge_light(d), 1.0 - kBlack, 0.006);
    EXPECT_LT(d.overdrive, 1.02);
}

// A white twice full scale is recovered from the grey, at the edge and inside.
TEST(CameraClipping, AWhiteTwiceFullScaleIsTakenFromTheGrey) {
    const Images m = filmed(2.0f, 0.01f);
    const DeclippedWhite d = declip_white(m.white, m.grey, m.black);
    EXPECT_NEAR(edge_light(d), 2.0, 0.06);
    EXPECT_NEAR(cv::mean(d.light.colRange(40, 60))[0], 2.0, 0.03);
    EXPECT_NEAR(d.overdrive, 2.0 + kBlack, 0.05);
    EXPECT_EQ(d.grey_clipped_pixels, 0);
}

}  // namespace
}  // namespace mogao::autocal
