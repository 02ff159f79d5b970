// SPDX-License-Identifier: Apache-2.0
// The blend (autocal.h, step 6) and its predicted seam gate (step 7), judged by the seam luminance's
// maximum against the virtual rig's ground truth on a grid that sees one-pixel lines (rig_bridge.h).
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/colour_truth.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/rig/rig_file.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao::autocal {
namespace {

rig::VirtualRig load(const std::string& name) {
    return rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/" + name + ".toml");
}

// The rig's true projectors as models: the blend alone is under test, no fit error in the way.
std::vector<DeviceModel> true_models(const rig::VirtualRig& rig) {
    std::vector<DeviceModel> out;
    for (const rig::RigProjector& p : rig.projectors) {
        out.push_back({p.id,
                       p.resolution,
                       p.intrinsics.fx_px,
                       p.intrinsics.fy_px,
                       p.intrinsics.cx_px,
                       p.intrinsics.cy_px,
                       {},
                       rig::device_to_screen(p.pose),
                       p.pose.position_m,
                       {}});
    }
    return out;
}

ScreenModel screen_of(const rig::VirtualRig& rig) {
    return {rig.screen.radius_m, rig.screen.arc_deg, rig.screen.bottom_m, rig.screen.top_m, {}};
}

// On the 4-projector 200-degree rig the images' borders cross the screen's bottom edge inside the
// overlaps. A weight that counts a border only where its foot lies on the screen jumps there, and the
// jump shows as a bright line one pixel wide: its seam maximum (not a percentile, which a line
// hides in) against the ground truth, on a grid of one point per projector pixel.
TEST(Blend, WeightsStayContinuousWhereImageBordersLeaveTheScreen) {
    const rig::VirtualRig rig = scaled_rig(load("wide200"), 0.5, 0.5);
    const ScreenCalibration c = calibration_from_models(true_models(rig), screen_of(rig), {1920, 1080});
    const LuminanceError dense = measure_luminance(rig, c, 0.01, pixel_dense_seam_grid(rig));
    const double predicted = predicted_seam_deviation(true_models(rig), screen_of(rig), c).deviation;
    std::printf("seam luminance max %.4f (%d points), predicted seam %.4f\n", dense.seam_max_deviation, dense.samples,
                predicted);
    // A correct blend leaves the ramps' pixel quantisation: about 1.5 / 115 px at half scale.
    EXPECT_LT(dense.seam_max_deviation, 0.02);
    EXPECT_LT(predicted, 0.02);
}

// The colour table's seams at black see a spot one projector pixel wide only on a pixel-dense grid: the default
// 401 x 101 points fall between pixels (8 to 16 projector pixels apart at full resolution). One overlap pixel of
// projector 0 that no default grid point lands on is lifted at black (a black offset far above its neighbours'); the
// pixel-dense grid finds it at its own height, the default grid's maximum does not move. Sharp projectors: a point's
// light is its one pixel's.
TEST(Blend, ASeamPixelAtBlackIsSeenOnThePixelDenseGrid) {
    const rig::VirtualRig rig = scaled_rig(load("standard"), 0.25, 0.25);
    ScreenCalibration c = calibration_from_models(true_models(rig), screen_of(rig), {960, 540});
    ProjectorCalibration& p0 = c.projectors[0];
    const ImageSize out = p0.output;
    std::vector<bool> on_grid(static_cast<std::size_t>(out.pixel_count()), false);
    for (const rig::ScreenPoint& s : seam_grid(rig, 0.01))
        if (const auto px = output_pixel(rig, 0, p0, s))
            on_grid[static_cast<std::size_t>((*px)[1] * out.width + (*px)[0])] = true;
    int spot_x = -1;
    const int spot_y = out.height / 2;
    for (int x = out.width - 1; x > 0 && spot_x < 0; --x) {
        const float w = sample_blend(p0.blend, out, x, spot_y);  // in the overlap: both projectors show content
        if (w > 0.2F && w < 0.8F && !on_grid[static_cast<std::size_t>(spot_y * out.width + x)]) spot_x = x;
    }
    ASSERT_GE(spot_x, 0) << "no overlap pixel between the default grid's points on projector 0's middle row";
    const SeamColour sparse = measure_seam_colour(rig, c, 0.0);
    const SeamColour dense = measure_seam_colour(rig, c, 0.0, 0.01, nullptr, false, pixel_dense_seam_grid(rig));
    p0.beta.size = out;
    p0.beta.rgb.assign(static_cast<std::size_t>(out.pixel_count()) * 3, 0.0F);
    for (std::size_t ch = 0; ch < 3; ++ch)
        p0.beta.rgb[3 * (static_cast<std::size_t>(spot_y) * out.width + spot_x) + ch] = 0.2F;
    const SeamColour sparse_spot = measure_seam_colour(rig, c, 0.0);
    const SeamColour dense_spot = measure_seam_colour(rig, c, 0.0, 0.01, nullptr, false, pixel_dense_seam_grid(rig));
    std::printf("seam max at black: default grid %.4f -> %.4f, pixel-dense %.4f -> %.4f (%d seam points)\n",
                sparse.seam_luminance_deviation, sparse_spot.seam_luminance_deviation, dense.seam_luminance_deviation,
                dense_spot.seam_luminance_deviation, dense_spot.seam_samples);
    EXPECT_GE(dense.seam_luminance_deviation, sparse.seam_luminance_deviation - 1e-9);
    EXPECT_GT(dense_spot.seam_luminance_deviation, dense.seam_luminance_deviation + 0.5);
    EXPECT_GT(dense_spot.seam_luminance_pixel_max, dense.seam_luminance_pixel_max + 0.5);
    EXPECT_LT(sparse_spot.seam_luminance_deviation, sparse.seam_luminance_deviation + 0.01);
}

// The same blend on the same rig with its projectors defocused by 0.7 px (a focused real lens' blur): each pixel's
// light spread over its neighbours' (projector_footprint.h), the ramps' pixel quantisation, up to 1.5 % as a sharp
// step, is gone from the seams as the screen shows them. A line one output pixel wide would still show at about
// half its height through that blur (the predicted seam's test below).
TEST(Blend, ADefocusedProjectorsPixelStepsLeaveTheSeams) {
    rig::VirtualRig rig = scaled_rig(load("wide200"), 0.5, 0.5);
    for (rig::RigProjector& p : rig.projectors) p.blur_px = 0.7;
    const ScreenCalibration c = calibration_from_models(true_models(rig), screen_of(rig), {1920, 1080});
    const LuminanceError sharp = measure_luminance(rig, c, 0.01, pixel_dense_seam_grid(rig));
    const LuminanceError seen = measure_luminance(rig, c, 0.01, pixel_dense_seam_grid(rig), nullptr, true);
    std::printf("seam luminance max with each pixel a sharp step %.4f, through the defocus %.4f\n",
                sharp.seam_max_deviation, seen.seam_max_deviation);
    EXPECT_GT(sharp.seam_max_deviation, 0.005);
    EXPECT_LT(seen.seam_max_deviation, 0.3 * sharp.seam_max_deviation);
}

// The same rig calibrated from its camera, which integrates over its pixels (4 x 4 points each): the
// fitted models put the bottom edges' crossings inside the overlaps too. Quarter scale for speed: the
// ramps' quantisation doubles (about 3 %), a jumping weight's line stays tens of percent.
TEST(Blend, CameraIntegratingOverItsPixelsLeavesNoLineInTheSeams) {
    const rig::VirtualRig rig = scaled_rig(load("wide200"), 0.25, 0.25);
    ASSERT_EQ(rig.camera.supersample, 4);
    RigPatternSource source(rig);
    const AutocalResult r = calibrate(source, prior_from_rig(rig), {1920, 1080});
    const LuminanceError dense = measure_luminance(rig, r.calibration, 0.01, pixel_dense_seam_grid(rig));
    const LuminanceError coarse = measure_luminance(rig, r.calibration);
    std::printf("seam luminance max %.4f (one point per projector pixel), %.4f (401 x 101); predicted %.4f\n",
                dense.seam_max_deviation, coarse.seam_max_deviation, r.report.predicted_seam.deviation);
    EXPECT_LT(dense.seam_max_deviation, 0.05);
}

// The predicted seam walks every projector pixel: a line two output pixels wide (one grid column of the
// blend raised by 0.3 inside an overlap) is seen at most of its height, from the models alone.
TEST(Blend, PredictedSeamSeesALineOnePixelWide) {
    const rig::VirtualRig rig = scaled_rig(load("wide200"), 0.5, 0.5);
    const std::vector<DeviceModel> models = true_models(rig);
    ScreenCalibration c = calibration_from_models(models, screen_of(rig), {1920, 1080});
    const double clean = predicted_seam_deviation(models, screen_of(rig), c).deviation;
    // proj1's weight on its grid row through the image's middle, from the right: the first column whose
    // weight is between 0.2 and 0.7 (inside its ramp towards proj2) is raised by 0.3 over the whole column
    // (but not above 1).
    BlendMask& blend = c.projectors[1].blend;
    const int row = blend.size.height / 2;
    int column = blend.size.width - 1;
    const auto weight = [&](int x) { return blend.weight[static_cast<std::size_t>(row * blend.size.width + x)]; };
    while (column > 0 && !(weight(column) > 0.2F && weight(column) < 0.7F)) --column;
    ASSERT_GT(column, blend.size.width / 2) << "no ramp on proj1's right";
    for (int y = 0; y < blend.size.height; ++y) {
        float& w = blend.weight[static_cast<std::size_t>(y * blend.size.width + column)];
        if (w > 0.0F) w = std::min(1.0F, w + 0.3F);
    }
    const double spiked = predicted_seam_deviation(models, screen_of(rig), c).deviation;
    std::printf("predicted seam %.4f clean, %.4f with the line\n", clean, spiked);
    EXPECT_LT(clean, 0.02);
    EXPECT_GT(spiked, 0.2);  // a pixel between two grid samples shows part of the raised one
}

}  // namespace
}  // namespace mogao::autocal
