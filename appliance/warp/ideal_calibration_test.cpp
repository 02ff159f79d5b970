// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/ideal_calibration.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "appliance/warp/calibration_validation.h"

namespace mogao {
namespace {

TEST(IdealCalibration, BandsTileTheFrameWithTheRequestedOverlap) {
    const auto bands = ideal_bands(3, 0.15);
    const double b = 1.0 / 2.7;
    ASSERT_EQ(bands.size(), 3U);
    EXPECT_DOUBLE_EQ(bands[0].u0, 0.0);
    EXPECT_DOUBLE_EQ(bands[0].u1, b);
    EXPECT_DOUBLE_EQ(bands[1].u0, 0.85 * b);
    EXPECT_DOUBLE_EQ(bands[2].u0, 1.7 * b);
    EXPECT_EQ(bands[2].u1, 1.0);
    for (std::size_t k = 0; k + 1 < bands.size(); ++k) {
        EXPECT_NEAR(bands[k].u1 - bands[k + 1].u0, 0.15 * b, 1e-15);  // shared part = overlap * band
        EXPECT_NEAR(bands[k].u1 - bands[k].u0, b, 1e-15);
    }
    const auto one = ideal_bands(1, 0.3);
    EXPECT_EQ(one[0].u0, 0.0);
    EXPECT_EQ(one[0].u1, 1.0);
}

TEST(IdealCalibration, WeightsSumToOneAtEveryContentPoint) {
    for (const int n : {1, 2, 3, 7}) {
        for (const double overlap : {0.0, 0.15, 0.49}) {
            const auto bands = ideal_bands(n, overlap);
            double worst = 0.0;
            for (int i = 0; i <= 100000; ++i) {
                const double u = i / 100000.0;
                double sum = 0.0;
                for (int k = 0; k < n; ++k) {
                    const double w = ideal_blend_weight(bands, k, u);
                    ASSERT_GE(w, 0.0);
                    ASSERT_LE(w, 1.0);
                    sum += w;
                }
                worst = std::max(worst, std::abs(sum - 1.0));
            }
            EXPECT_LE(worst, 2.3e-16) << "n=" << n << " overlap=" << overlap;
        }
    }
}

TEST(IdealCalibration, RampIsSmoothstep) {
    EXPECT_EQ(smooth_ramp(0.0), 0.0);
    EXPECT_EQ(smooth_ramp(1.0), 1.0);
    EXPECT_EQ(smooth_ramp(0.5), 0.5);
    EXPECT_DOUBLE_EQ(smooth_ramp(0.25), 0.15625);
    EXPECT_EQ(smooth_ramp(-2.0), 0.0);
    EXPECT_EQ(smooth_ramp(3.0), 1.0);
}

TEST(IdealCalibration, WarpMapsPixelCentresLinearlyOntoTheBand) {
    IdealCalibrationParams p;  // 3 x 1024x768, overlap 0.15, content 1920x1080
    const ScreenCalibration s = make_ideal_calibration(p);
    ASSERT_NO_THROW(validate_screen(s));
    ASSERT_EQ(s.projectors.size(), 3U);
    EXPECT_EQ(s.content, (ImageSize{1920, 1080}));
    const auto bands = ideal_bands(3, 0.15);
    for (std::size_t k = 0; k < 3; ++k) {
        const ProjectorCalibration& pc = s.projectors[k];
        EXPECT_EQ(pc.id, "proj" + std::to_string(k));
        EXPECT_EQ(pc.output, (ImageSize{1024, 768}));
        EXPECT_EQ(pc.warp.size, pc.output);
        const double b = bands[k].u1 - bands[k].u0;
        for (const auto& [x, y] : {std::pair{0, 0}, std::pair{1023, 767}, std::pair{511, 300}}) {
            const std::size_t i = static_cast<std::size_t>(y) * 1024 + static_cast<std::size_t>(x);
            EXPECT_FLOAT_EQ(pc.warp.uv[2 * i], static_cast<float>(bands[k].u0 + b * (x + 0.5) / 1024));
            EXPECT_FLOAT_EQ(pc.warp.uv[2 * i + 1], static_cast<float>((y + 0.5) / 768));
        }
        EXPECT_EQ(pc.response.lut[0].size(), static_cast<std::size_t>(kDefaultResponseEntries));
    }
    // Outside overlaps full weight; in the overlap the left projector ramps down, the right one up.
    EXPECT_EQ(s.projectors[1].blend.weight[512], 1.0F);
    EXPECT_EQ(s.projectors[0].blend.weight[100], 1.0F);
    EXPECT_LT(s.projectors[0].blend.weight[1020], 0.01F);
    EXPECT_LT(s.projectors[1].blend.weight[3], 0.01F);
    for (int x = 1; x < 1024; ++x) {
        EXPECT_LE(s.projectors[0].blend.weight[static_cast<std::size_t>(x)],
                  s.projectors[0].blend.weight[static_cast<std::size_t>(x - 1)]);
    }
}

TEST(IdealCalibration, SingleProjectorCoversEverythingAtFullWeight) {
    IdealCalibrationParams p;
    p.projectors = 1;
    p.output = {4, 2};
    p.content = {4, 2};
    const ScreenCalibration s = make_ideal_calibration(p);
    for (float w : s.projectors[0].blend.weight) EXPECT_EQ(w, 1.0F);
    EXPECT_FLOAT_EQ(s.projectors[0].warp.uv[0], 0.125F);
    EXPECT_FLOAT_EQ(s.projectors[0].warp.uv[2 * 7], 0.875F);
    EXPECT_FLOAT_EQ(s.projectors[0].warp.uv[2 * 7 + 1], 0.75F);
}

TEST(IdealCalibration, ParametersAreValidated) {
    const auto throws = [](auto mutate) {
        IdealCalibrationParams p;
        p.output = {8, 8};
        p.content = {8, 8};
        mutate(p);
        EXPECT_THROW((void)make_ideal_calibration(p), std::invalid_argument);
    };
    throws([](IdealCalibrationParams& p) { p.projectors = 0; });
    throws([](IdealCalibrationParams& p) { p.projectors = 65; });
    throws([](IdealCalibrationParams& p) { p.overlap = 0.5; });
    throws([](IdealCalibrationParams& p) { p.overlap = -0.01; });
    throws([](IdealCalibrationParams& p) { p.overlap = NAN; });
    throws([](IdealCalibrationParams& p) { p.output = {0, 8}; });
    throws([](IdealCalibrationParams& p) { p.content = {16385, 8}; });
    throws([](IdealCalibrationParams& p) { p.gamma = -1.0; });
    try {
        (void)ideal_bands(3, 0.7);
        FAIL() << "overlap 0.7 accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("overlap 0.700000 is outside [0, 0.5)"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mogao
