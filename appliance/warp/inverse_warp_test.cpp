// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/inverse_warp.h"

#include <cmath>

#include <gtest/gtest.h>

#include "appliance/warp/ideal_calibration.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao {
namespace {

TEST(InverseWarp, IdealWarpMatchesTheAnalyticInverse) {
    IdealCalibrationParams p;
    p.output = {256, 192};
    p.content = {480, 270};
    const ScreenCalibration s = make_ideal_calibration(p);
    const auto bands = ideal_bands(3, 0.15);
    for (std::size_t k = 0; k < 3; ++k) {
        const InverseWarp inv = build_inverse_warp(s.projectors[k].warp, p.output, p.content);
        const double b = bands[k].u1 - bands[k].u0;
        double worst = 0.0;
        int covered = 0;
        for (int j = 0; j < p.content.height; ++j) {
            for (int i = 0; i < p.content.width; ++i) {
                const std::size_t idx = (static_cast<std::size_t>(j) * 480 + static_cast<std::size_t>(i)) * 2;
                // Analytic: u = u0 + b (x + 0.5) / W  <=>  x = (u - u0) / b * W - 0.5 (pixel-index coords).
                const double u = (i + 0.5) / 480.0;
                const double v = (j + 0.5) / 270.0;
                const double x = (u - bands[k].u0) / b * 256.0 - 0.5;
                const double y = v * 192.0 - 0.5;
                const bool inside = x >= 0.0 && x <= 255.0 && y >= 0.0 && y <= 191.0;
                const bool got = !std::isnan(inv.xy[idx]);
                // Pixels within float rounding of the grid's edge may go either way.
                const bool marginal = std::abs(x) < 1e-3 || std::abs(x - 255.0) < 1e-3 || std::abs(y) < 1e-3 ||
                                      std::abs(y - 191.0) < 1e-3;
                if (!marginal) {
                    EXPECT_EQ(got, inside) << "k=" << k << " i=" << i << " j=" << j;
                }
                if (got) {
                    ++covered;
                    worst = std::max(worst, std::abs(inv.xy[idx] - x));
                    worst = std::max(worst, std::abs(inv.xy[idx + 1] - y));
                }
            }
        }
        EXPECT_LT(worst, 2e-3) << "projector " << k;  // float32 warp values of a 480-wide frame
        EXPECT_GT(covered, 170 * 265);
    }
}

TEST(InverseWarp, CurvedWarpRoundTripsThroughTheForwardSampler) {
    // Barrel-like warp (the custom Sim3D fixture's formula) on a coarse 33x25 grid of a 320x240
    // output: inverse then forward must land back on the content pixel centre.
    const ImageSize out{320, 240};
    const ImageSize content{200, 150};
    WarpMap w;
    w.size = {33, 25};
    for (int j = 0; j < 25; ++j) {
        for (int i = 0; i < 33; ++i) {
            const double s = (i + 0.5) / 33.0 - 0.5;
            const double t = (j + 0.5) / 25.0 - 0.5;
            const double k = 1.0 + 0.08 * (s * s + t * t);
            w.uv.push_back(static_cast<float>(0.5 + s * k));
            w.uv.push_back(static_cast<float>(0.5 + t * k));
        }
    }
    const InverseWarp inv = build_inverse_warp(w, out, content);
    int covered = 0;
    double worst = 0.0;
    for (int j = 0; j < content.height; ++j) {
        for (int i = 0; i < content.width; ++i) {
            const std::size_t idx = (static_cast<std::size_t>(j) * 200 + static_cast<std::size_t>(i)) * 2;
            if (std::isnan(inv.xy[idx])) continue;
            ++covered;
            const ContentUv uv = sample_warp_at(w, out, inv.xy[idx], inv.xy[idx + 1]);
            worst = std::max(worst, std::abs(uv.u * 200.0 - 0.5 - i));
            worst = std::max(worst, std::abs(uv.v * 150.0 - 0.5 - j));
        }
    }
    EXPECT_LT(worst, 1e-3);  // content pixels
    EXPECT_GT(covered, 180 * 130);
}

TEST(InverseWarp, NanCellsAndOneSampleGridsCoverNothing) {
    WarpMap w;
    w.size = {2, 2};
    w.uv = {0.0F, 0.0F, 1.0F, 0.0F, NAN, NAN, 1.0F, 1.0F};
    const InverseWarp inv = build_inverse_warp(w, {4, 4}, {4, 4});
    for (float value : inv.xy) EXPECT_TRUE(std::isnan(value));
    w.size = {1, 1};
    w.uv = {0.5F, 0.5F};
    const InverseWarp one = build_inverse_warp(w, {4, 4}, {4, 4});
    for (float value : one.xy) EXPECT_TRUE(std::isnan(value));
    w.size = {5, 1};
    w.uv.assign(10, 0.5F);
    EXPECT_THROW((void)build_inverse_warp(w, {4, 4}, {4, 4}), std::invalid_argument);  // grid finer than output
}

}  // namespace
}  // namespace mogao
