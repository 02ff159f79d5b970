// SPDX-License-Identifier: Apache-2.0
// The reference-library fixtures (../shared/data/mpcdi, PROVENANCE.md there), checked value by value
// against the analytic content their generators wrote.
#include <cmath>
#include <cstdlib>
#include <numbers>

#include <gtest/gtest.h>

#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_test_util.h"

namespace mogao {
namespace {

using test::fixture;

TEST(MpcdiFixtures, AllEightFilesRead) {
    MOGAO_REQUIRE_FIXTURES();
    for (const std::string& name : test::all_fixtures()) {
        EXPECT_NO_THROW((void)read_mpcdi(fixture(name))) << name;
    }
}

TEST(MpcdiFixtures, CustomMedia2dCoarseWarpAndAlphaRamps) {
    MOGAO_REQUIRE_FIXTURES();
    std::vector<std::string> notes;
    const MpcdiFile f = read_mpcdi(fixture("custom/Media2D_2x1920x1080_L1.mpcdi"), &notes);
    EXPECT_EQ(f.profile, MpcdiProfile::two_d);
    EXPECT_EQ(f.level, 1);
    EXPECT_EQ(f.version, "1.0");
    ASSERT_EQ(f.buffers.size(), 1U);
    EXPECT_EQ(f.buffers[0].id, "buffer1");
    EXPECT_EQ(f.buffers[0].resolution, (ImageSize{3456, 1080}));
    ASSERT_EQ(f.buffers[0].regions.size(), 2U);
    const MpcdiRegion& a = f.buffers[0].regions[0];
    const MpcdiRegion& b = f.buffers[0].regions[1];
    EXPECT_EQ(a.id, "projA_left");
    EXPECT_EQ(b.id, "projB_right");
    EXPECT_EQ(a.resolution, (ImageSize{1920, 1080}));
    EXPECT_EQ(a.x, 0.0);
    EXPECT_EQ(a.xsize, 0.555556);
    EXPECT_EQ(b.x, 0.444444);
    EXPECT_EQ(b.ysize, 1.0);
    EXPECT_FALSE(a.frustum);
    EXPECT_FALSE(a.beta);
    EXPECT_EQ(a.warp.interpolation, WarpInterpolation::linear);
    EXPECT_EQ(a.warp.origin_of_3d_data, OriginOf3DData::unknown);  // file says "linear": writer bug
    EXPECT_EQ(std::count_if(notes.begin(), notes.end(),
                            [](const std::string& n) { return n.find("writer bug") != std::string::npos; }),
              2);

    for (const MpcdiRegion* r : {&a, &b}) {
        const float sign = r == &a ? 1.0F : -1.0F;
        ASSERT_EQ(r->warp.map.size, (ImageSize{192, 108}));
        ASSERT_EQ(r->warp.map.channels, 3);
        int mismatches = 0;
        for (int j = 0; j < 108; ++j) {
            for (int i = 0; i < 192; ++i) {
                const float s = static_cast<float>(i) / 191.0F;
                const float t = static_cast<float>(j) / 107.0F;
                const float* p = r->warp.map.at(i, j);
                mismatches += p[0] != 0.05F + 0.90F * s + sign * 0.02F * t;
                mismatches += p[1] != 0.03F + 0.94F * t + 0.01F * s;
                mismatches += p[2] != 0.0F;
            }
        }
        EXPECT_EQ(mismatches, 0) << r->id;
        EXPECT_NEAR(r->warp.map.at(0, 0)[0], 0.05, 1e-7);
        EXPECT_NEAR(r->warp.map.at(0, 0)[1], 0.03, 1e-7);
        EXPECT_NEAR(r->warp.map.at(191, 107)[0], r == &a ? 0.97 : 0.93, 1e-6);
        EXPECT_NEAR(r->warp.map.at(191, 107)[1], 0.98, 1e-6);

        ASSERT_EQ(r->alpha.map.size, (ImageSize{1920, 1080}));
        EXPECT_EQ(r->alpha.map.channels, 1);
        EXPECT_EQ(r->alpha.map.bit_depth, 8);
        EXPECT_EQ(r->alpha.gamma_embedded, 2.2);
        int bad = 0;
        for (int y = 0; y < 1080; ++y) {
            for (int x = 0; x < 1920; ++x) {
                int expected = 255;
                if (r == &a && x >= 1536) expected = static_cast<int>(std::floor(255.0 * (1919 - x) / 383.0 + 0.5));
                if (r == &b && x < 384) expected = static_cast<int>(std::floor(255.0 * x / 383.0 + 0.5));
                if (y < 8) expected = 0;  // orientation marker: the top rows
                bad += r->alpha.map.at(x, y) != expected;
            }
        }
        EXPECT_EQ(bad, 0) << r->id;
    }
}

TEST(MpcdiFixtures, CustomSim3dPerPixelWarpIsBitExact) {
    MOGAO_REQUIRE_FIXTURES();
    const MpcdiFile f = read_mpcdi(fixture("custom/Sim3D_1024x768_L4.mpcdi"));
    EXPECT_EQ(f.profile, MpcdiProfile::three_d);
    EXPECT_EQ(f.level, 4);
    const MpcdiRegion& r = f.buffers.at(0).regions.at(0);
    EXPECT_EQ(r.id, "proj1");
    EXPECT_EQ(r.resolution, (ImageSize{1024, 768}));
    ASSERT_TRUE(r.frustum);
    EXPECT_EQ(*r.frustum, (MpcdiFrustum{-30.5, 4.25, -1.5, 26, -24, 17.5, -19.5}));
    ASSERT_EQ(r.warp.map.size, (ImageSize{1024, 768}));
    int mismatches = 0;
    float lo_r = INFINITY, hi_r = -INFINITY, lo_g = INFINITY, hi_g = -INFINITY;
    for (int j = 0; j < 768; ++j) {
        for (int i = 0; i < 1024; ++i) {
            const float s = (static_cast<float>(i) + 0.5F) / 1024.0F;
            const float t = (static_cast<float>(j) + 0.5F) / 768.0F;
            const float dx = s - 0.5F;
            const float dy = t - 0.5F;
            const float k = 1.0F + 0.08F * (dx * dx + dy * dy);
            const float* p = r.warp.map.at(i, j);
            mismatches += p[0] != 0.5F + dx * k;
            mismatches += p[1] != 0.5F + dy * k;
            mismatches += p[2] != 0.0F;
            lo_r = std::min(lo_r, p[0]);
            hi_r = std::max(hi_r, p[0]);
            lo_g = std::min(lo_g, p[1]);
            hi_g = std::max(hi_g, p[1]);
        }
    }
    EXPECT_EQ(mismatches, 0);
    // Normalised 2D warps may leave 0..1 slightly.
    EXPECT_NEAR(lo_r, -0.019447, 1e-6);
    EXPECT_NEAR(hi_r, 1.019447, 1e-6);
    EXPECT_NEAR(lo_g, -0.019277, 1e-6);
    EXPECT_NEAR(hi_g, 1.019277, 1e-6);

    EXPECT_EQ(r.alpha.gamma_embedded, 1.0);
    ASSERT_EQ(r.alpha.map.channels, 3);
    ASSERT_TRUE(r.beta);
    ASSERT_EQ(r.beta->map.size, (ImageSize{1024, 768}));
    int bad = 0;
    for (int y = 0; y < 768; ++y) {
        for (int x = 0; x < 1024; ++x) {
            bad += r.alpha.map.at(x, y, 0) != x * 255 / 1023;
            bad += r.alpha.map.at(x, y, 1) != y * 255 / 767;
            bad += r.alpha.map.at(x, y, 2) != 200;
            bad += r.beta->map.at(x, y) != (x < 512 ? 16 : 0);
        }
    }
    EXPECT_EQ(bad, 0);
}

TEST(MpcdiFixtures, CustomAdvanced3dPointsLieOnTheCylinderWithYUp) {
    MOGAO_REQUIRE_FIXTURES();
    const MpcdiFile f = read_mpcdi(fixture("custom/Advanced3D_3x1024x768_cylinder_L1.mpcdi"));
    EXPECT_EQ(f.profile, MpcdiProfile::advanced_3d);
    EXPECT_EQ(f.level, 1);
    EXPECT_EQ(f.buffers.at(0).resolution, (ImageSize{3072, 768}));
    ASSERT_EQ(f.buffers[0].regions.size(), 3U);
    const double xs[3] = {0.0, 0.333333, 0.666667};
    for (int k = 0; k < 3; ++k) {
        const MpcdiRegion& r = f.buffers[0].regions[static_cast<std::size_t>(k)];
        EXPECT_EQ(r.id, "proj" + std::to_string(k));
        EXPECT_EQ(r.x, xs[k]);
        EXPECT_EQ(r.xsize, 0.333333);
        EXPECT_EQ(r.warp.geometric_unit, GeometricUnit::m);
        ASSERT_EQ(r.warp.map.size, (ImageSize{102, 76}));
        double worst = 0.0;
        for (int j = 0; j < 76; ++j) {
            for (int i = 0; i < 102; ++i) {
                const double s = i / 101.0;
                const double t = j / 75.0;
                const double ang = (-60.0 + 40.0 * k + 40.0 * s) * std::numbers::pi / 180.0;
                const float* p = r.warp.map.at(i, j);
                worst = std::max({worst, std::abs(p[0] - 3.0 * std::sin(ang)), std::abs(p[1] - (2.5 - 2.0 * t)),
                                  std::abs(p[2] + 3.0 * std::cos(ang))});
            }
        }
        EXPECT_LE(worst, 2.4e-7) << r.id;                  // computed in double, stored as float32
        EXPECT_NEAR(r.warp.map.at(50, 0)[1], 2.5, 1e-7);   // top row: 2.5 m (Y up)
        EXPECT_NEAR(r.warp.map.at(50, 75)[1], 0.5, 1e-7);  // bottom row: 0.5 m
        const float* c = r.warp.map.at(33, 40);
        EXPECT_NEAR(std::hypot(c[0], c[2]), 3.0, 1e-6);  // radius-3 cylinder about the y axis
        EXPECT_EQ(r.alpha.map.size, (ImageSize{1024, 768}));
        EXPECT_TRUE(std::all_of(r.alpha.map.values.begin(), r.alpha.map.values.end(), [](auto v) { return v == 255; }));
    }
}

// examples/{Media2D, Sim3D, Advanced3D, ShaderLamp}: FillInCreatorCommonData of the reference examples.
void check_example_common(const MpcdiFile& f, ImageSize res, const std::string& name) {
    SCOPED_TRACE(name);
    EXPECT_EQ(f.level, 4);
    ASSERT_EQ(f.buffers.size(), 1U);
    EXPECT_EQ(f.buffers[0].id, "buffer1");
    EXPECT_EQ(f.buffers[0].resolution, res);
    ASSERT_EQ(f.buffers[0].regions.size(), 1U);
    const MpcdiRegion& r = f.buffers[0].regions[0];
    EXPECT_EQ(r.id, "proj1");
    EXPECT_EQ(r.resolution, res);
    EXPECT_EQ(r.x, 0.01);
    EXPECT_EQ(r.y, 0.07);
    EXPECT_EQ(r.xsize, 0.9);
    EXPECT_EQ(r.ysize, 0.92);
    const int W = res.width;
    const int H = res.height;
    ASSERT_EQ(r.warp.map.size, res);
    int bad = 0;
    for (int j = 0; j < H; ++j) {
        for (int i = 0; i < W; ++i) {
            const bool block = i <= W / 10 && j <= H / 10;
            const float* p = r.warp.map.at(i, j);
            bad += p[0] != (block ? 0.0F : static_cast<float>(i) / static_cast<float>(W));
            bad += p[1] != (block ? 0.0F : static_cast<float>(j) / static_cast<float>(H));
            bad += p[2] != 0.0F;
        }
    }
    EXPECT_EQ(bad, 0);
    EXPECT_NEAR(r.warp.map.at(W - 1, 5)[0], (W - 1.0) / W, 1e-7);
    ASSERT_EQ(r.alpha.map.channels, 3);
    EXPECT_EQ(r.alpha.gamma_embedded, 2.2);
    bad = 0;
    for (int j = 0; j < H; ++j) {
        for (int i = 0; i < W; ++i) {
            for (int c = 0; c < 3; ++c) {
                const bool inside =
                    std::abs(i - W / 2) <= (W / 4 + W / 4 * c) / 2 && std::abs(j - H / 2) <= (H / 4 + H / 4 * c) / 2;
                bad += r.alpha.map.at(i, j, c) != (inside ? 255 : 0);
            }
        }
    }
    EXPECT_EQ(bad, 0);
    ASSERT_TRUE(r.beta);
    EXPECT_EQ(r.beta->map.size, (ImageSize{100, 100}));  // deliberately not the region size
    EXPECT_EQ(r.beta->map.channels, 1);
    EXPECT_TRUE(std::all_of(r.beta->map.values.begin(), r.beta->map.values.end(), [](auto v) { return v == 0; }));
}

TEST(MpcdiFixtures, ExamplesHoldTheGradientWithAZeroBlock) {
    MOGAO_REQUIRE_FIXTURES();
    const MpcdiFrustum frustum{5, -10, 7, 12, -20, 10, -10};
    const MpcdiFile media = read_mpcdi(fixture("examples/Media2D.mpcdi"));
    EXPECT_EQ(media.profile, MpcdiProfile::two_d);
    check_example_common(media, {300, 200}, "Media2D");
    EXPECT_FALSE(media.buffers[0].regions[0].frustum);

    const MpcdiFile sim = read_mpcdi(fixture("examples/Sim3D.mpcdi"));
    EXPECT_EQ(sim.profile, MpcdiProfile::three_d);
    check_example_common(sim, {300, 200}, "Sim3D");
    EXPECT_EQ(sim.buffers[0].regions[0].frustum, frustum);

    const MpcdiFile adv = read_mpcdi(fixture("examples/Advanced3D.mpcdi"));
    EXPECT_EQ(adv.profile, MpcdiProfile::advanced_3d);
    check_example_common(adv, {300, 200}, "Advanced3D");
    EXPECT_EQ(adv.buffers[0].regions[0].warp.geometric_unit, GeometricUnit::m);
    EXPECT_EQ(adv.buffers[0].regions[0].warp.origin_of_3d_data, OriginOf3DData::unknown);

    const MpcdiFile lamp = read_mpcdi(fixture("examples/ShaderLamp.mpcdi"));
    EXPECT_EQ(lamp.profile, MpcdiProfile::shader_lamp);
    check_example_common(lamp, {400, 200}, "ShaderLamp");
    const MpcdiRegion& r = lamp.buffers[0].regions[0];
    EXPECT_EQ(r.frustum, frustum);
    ASSERT_TRUE(r.coordinate_frame);
    EXPECT_EQ(*r.coordinate_frame, (MpcdiCoordinateFrame{{0, 0, 1}, {0, 0, 1}, {0, 1, 0}, {1, 0, 0}}));
    ASSERT_TRUE(r.distortion);
    EXPECT_EQ(r.distortion->map.size, (ImageSize{400, 200}));
    EXPECT_TRUE(std::all_of(r.distortion->map.values.begin(), r.distortion->map.values.end(),
                            [](float v) { return v == 0.0F; }));
}

TEST(MpcdiFixtures, SampleMpcdiThreeRegions) {
    MOGAO_REQUIRE_FIXTURES();
    std::vector<std::string> notes;
    const MpcdiFile f = read_mpcdi(fixture("examples/SampleMPCDI.mpcdi"), &notes);
    EXPECT_EQ(f.profile, MpcdiProfile::shader_lamp);
    EXPECT_EQ(f.level, 4);
    ASSERT_EQ(f.buffers.size(), 1U);
    EXPECT_EQ(f.buffers[0].id, "sample_buffer");
    EXPECT_EQ(f.buffers[0].resolution, (ImageSize{200, 200}));
    ASSERT_EQ(f.buffers[0].regions.size(), 3U);
    for (int k = 0; k < 3; ++k) {
        const MpcdiRegion& r = f.buffers[0].regions[static_cast<std::size_t>(k)];
        SCOPED_TRACE(r.id);
        EXPECT_EQ(r.id, "Proj" + std::to_string(k));
        EXPECT_EQ(r.resolution, (ImageSize{200, 200}));
        EXPECT_NEAR(r.x, 0.01 + 0.01 * k, 1e-12);
        EXPECT_NEAR(r.y, 0.07 + 0.01 * k, 1e-12);
        EXPECT_NEAR(r.xsize, 0.9 - 0.01 * k, 1e-12);
        EXPECT_NEAR(r.ysize, 0.92 - 0.01 * k, 1e-12);
        ASSERT_TRUE(r.frustum);
        const double kk = k;
        EXPECT_EQ(*r.frustum, (MpcdiFrustum{5 + kk, -10 + kk, 7 + kk, 12 + kk, -20 - kk, 10 + kk, -11 - kk}));
        EXPECT_EQ(r.coordinate_frame, (MpcdiCoordinateFrame{{0, 0, 1}, {0, 0, 1}, {0, 1, 0}, {1, 0, 0}}));
        EXPECT_EQ(r.warp.geometric_unit, GeometricUnit::unknown);
        EXPECT_EQ(r.alpha.gamma_embedded, 0.0);  // never set by the example: "not recorded"
        EXPECT_EQ(r.alpha.map.channels, 3);
        ASSERT_TRUE(r.beta);
        EXPECT_EQ(r.beta->map.size, (ImageSize{100, 100}));
        ASSERT_TRUE(r.distortion);
        EXPECT_EQ(r.distortion->map.size, (ImageSize{200, 200}));
        EXPECT_EQ(*r.warp.map.at(20, 20), 0.0F);  // zero block i, j <= 20
        EXPECT_EQ(r.warp.map.at(20, 20)[1], 0.0F);
        EXPECT_EQ(r.warp.map.at(21, 20)[0], 21.0F / 200.0F);
        EXPECT_EQ(r.warp.map.at(5, 199)[1], 199.0F / 200.0F);
    }
    EXPECT_EQ(std::count_if(notes.begin(), notes.end(),
                            [](const std::string& n) { return n.find("gammaEmbedded") != std::string::npos; }),
              3);
}

}  // namespace
}  // namespace mogao
