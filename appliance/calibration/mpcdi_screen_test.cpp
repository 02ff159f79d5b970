// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/mpcdi_screen.h"

#include <cmath>

#include <gtest/gtest.h>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_number.h"
#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_test_util.h"
#include "appliance/warp/ideal_calibration.h"

namespace mogao {
namespace {

TEST(MpcdiScreen, WarpIsRegionRelativeByDefault) {
    MpcdiFile f = test::small_file();  // region x 0.25 xsize 0.5, warp r = i/3, g = j
    const ScreenCalibration s = to_screen_calibration(f);
    EXPECT_EQ(s.content, (ImageSize{64, 32}));
    ASSERT_EQ(s.projectors.size(), 1U);
    const ProjectorCalibration& p = s.projectors[0];
    EXPECT_EQ(p.id, "p0");
    EXPECT_EQ(p.output, (ImageSize{16, 8}));
    EXPECT_EQ(p.warp.size, (ImageSize{4, 2}));
    EXPECT_FLOAT_EQ(p.warp.uv[0], 0.25F);      // x + xsize * 0
    EXPECT_FLOAT_EQ(p.warp.uv[2 * 3], 0.75F);  // x + xsize * 1
    EXPECT_FLOAT_EQ(p.warp.uv[2 * 7 + 1], 1.0F);
    ScreenConversionOptions buffer_space;
    buffer_space.warp_space = WarpSpace::buffer;
    EXPECT_FLOAT_EQ(to_screen_calibration(f, buffer_space).projectors[0].warp.uv[2 * 3], 1.0F);
}

TEST(MpcdiScreen, AlphaGammaIsRemovedAndZeroMeansAssumed) {
    MpcdiFile f = test::small_file();  // alpha = 17 i, gamma 2.2
    const auto weight = [](const MpcdiFile& file, int x, const ScreenConversionOptions& o = {}) {
        return to_screen_calibration(file, o).projectors[0].blend.weight[static_cast<std::size_t>(x)];
    };
    EXPECT_FLOAT_EQ(weight(f, 15), 1.0F);
    EXPECT_FLOAT_EQ(weight(f, 5), static_cast<float>(std::pow(85.0 / 255.0, 2.2)));
    f.buffers[0].regions[0].alpha.gamma_embedded = 1.0;
    EXPECT_FLOAT_EQ(weight(f, 5), static_cast<float>(85.0 / 255.0));
    f.buffers[0].regions[0].alpha.gamma_embedded = 0.0;  // SampleMPCDI: not recorded
    EXPECT_FLOAT_EQ(weight(f, 5), static_cast<float>(std::pow(85.0 / 255.0, 2.2)));
    ScreenConversionOptions o;
    o.assumed_gamma = 1.8;
    EXPECT_FLOAT_EQ(weight(f, 5, o), static_cast<float>(std::pow(85.0 / 255.0, 1.8)));
}

TEST(MpcdiScreen, RgbAlphaIsTheMeanAndNansMeanNoContent) {
    MpcdiFile f = test::small_file();
    MpcdiRegion& r = f.buffers[0].regions[0];
    r.alpha.gamma_embedded = 1.0;
    r.alpha.map = PngMap{{1, 1}, 3, 8, {255, 0, 51}};
    r.warp.map.values[3] = NAN;  // sample 1: r finite, g NaN
    std::vector<std::string> notes;
    const ScreenCalibration s = to_screen_calibration(f, {}, &notes);
    EXPECT_FLOAT_EQ(s.projectors[0].blend.weight[0], static_cast<float>((1.0 + 0.0 + 0.2) / 3.0));
    EXPECT_TRUE(std::isnan(s.projectors[0].warp.uv[2]));
    EXPECT_TRUE(std::isnan(s.projectors[0].warp.uv[3]));
    EXPECT_FALSE(notes.empty());
}

TEST(MpcdiScreen, UnsupportedInputsAreNamed) {
    MpcdiFile f = test::small_file();
    f.profile = MpcdiProfile::advanced_3d;
    EXPECT_THROW((void)to_screen_calibration(f), MpcdiError);
    f = test::small_file();
    f.buffers[0].regions[0].warp.map = PfmMap{{32, 2}, 3, std::vector<float>(192, 0.5F)};
    try {
        (void)to_screen_calibration(f);
        FAIL();
    } catch (const MpcdiError& e) {
        EXPECT_STREQ(
            e.what(),
            "to_screen_calibration: region \"p0\": geometry warp grid 32x2 is larger than the region resolution 16x8");
    }
    f = test::small_file();
    f.buffers[0].regions[0].warp.map = PfmMap{{1, 1}, 1, {0.5F}};
    EXPECT_THROW((void)to_screen_calibration(f), MpcdiError);
    ScreenConversionOptions o;
    o.buffer = 1;
    EXPECT_THROW((void)to_screen_calibration(test::small_file(), o), MpcdiError);
}

TEST(MpcdiScreen, ExportChoosesRegionLevelAndAlphaCodes) {
    IdealCalibrationParams p;
    p.projectors = 2;
    p.overlap = 0.2;
    p.output = {40, 30};
    p.content = {64, 32};
    const ScreenCalibration s = make_ideal_calibration(p);
    const MpcdiFile f = to_mpcdi(s);
    EXPECT_EQ(f.profile, MpcdiProfile::two_d);
    EXPECT_EQ(f.level, 3);
    ASSERT_EQ(f.buffers.size(), 1U);
    EXPECT_EQ(f.buffers[0].resolution, p.content);
    const MpcdiRegion& r = f.buffers[0].regions[1];
    EXPECT_EQ(r.id, "proj1");
    const auto bands = ideal_bands(2, 0.2);
    const double b = bands[1].u1 - bands[1].u0;
    EXPECT_NEAR(r.x, bands[1].u0 + b * 0.5 / 40, 1e-6);  // first pixel centre, 6 significant digits
    EXPECT_NEAR(r.x + r.xsize, bands[1].u1 - b * 0.5 / 40, 1e-6);
    EXPECT_EQ(format_number(r.xsize).size(), 8U);  // "0.xxxxxx": printed like the reference files
    EXPECT_EQ(r.alpha.map.bit_depth, 8);
    EXPECT_EQ(r.alpha.gamma_embedded, 2.2);
    EXPECT_EQ(r.alpha.map.at(39, 0), 255);
    EXPECT_EQ(r.warp.interpolation, WarpInterpolation::linear);

    ScreenCalibration coarse = s;
    for (auto& pc : coarse.projectors) {
        pc.warp.size = {2, 2};
        pc.warp.uv = {0.0F, 0.0F, 0.5F, 0.0F, 0.0F, 1.0F, 0.5F, 1.0F};
    }
    EXPECT_EQ(to_mpcdi(coarse).level, 1);
    MpcdiExportOptions bad;
    bad.alpha_bit_depth = 12;
    EXPECT_THROW((void)to_mpcdi(s, bad), std::invalid_argument);
    EXPECT_NEAR(alpha_quantisation_bound(8, 2.2), 2.2 * 0.5 / 255, 1e-15);
}

TEST(MpcdiScreen, CustomMedia2dFixtureConverts) {
    MOGAO_REQUIRE_FIXTURES();
    const ScreenCalibration s = to_screen_calibration(read_mpcdi(test::fixture("custom/Media2D_2x1920x1080_L1.mpcdi")));
    EXPECT_EQ(s.content, (ImageSize{3456, 1080}));
    ASSERT_EQ(s.projectors.size(), 2U);
    const ProjectorCalibration& b = s.projectors[1];
    EXPECT_EQ(b.id, "projB_right");
    EXPECT_EQ(b.warp.size, (ImageSize{192, 108}));
    EXPECT_NEAR(b.warp.uv[0], 0.444444 + 0.555556 * 0.05, 1e-6);
    EXPECT_EQ(b.blend.weight[5 * 1920 + 500], 0.0F);  // orientation rows
    EXPECT_FLOAT_EQ(b.blend.weight[100 * 1920 + 500], 1.0F);
    EXPECT_FLOAT_EQ(b.blend.weight[100 * 1920 + 191],
                    static_cast<float>(std::pow(std::floor(255.0 * 191 / 383 + 0.5) / 255.0, 2.2)));
}

}  // namespace
}  // namespace mogao
