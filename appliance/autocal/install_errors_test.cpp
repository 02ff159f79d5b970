// SPDX-License-Identifier: Apache-2.0
// A real installation's measuring and camera errors on the virtual rig, each alone on the standard rig at half
// scale (rig keys [prior] screen_bottom_error_m / screen_top_error_m, [camera] mjpeg_quality; docs/calibration.md,
// "Rig files"): the calibration must meet its goals or refuse naming the cause, never put content silently off.
// Measured against the virtual rig's ground truth (rig_bridge.h), never against the calibration's own prediction.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/camera_timing.h"
#include "appliance/autocal/gray_code.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/autocal/screen_geometry.h"
#include "appliance/autocal/self_check.h"
#include "appliance/rig/rig_file.h"

namespace mogao::autocal {
namespace {

rig::VirtualRig standard_half() {
    return scaled_rig(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml"), 0.5, 0.5);
}

struct Outcome {
    std::string refused;     // the refusal's reason, empty when calibrated
    GeometryError geometry;  // against the rig's truth, also where the self-check's gate refused it
    SelfCheckResult check;
    AutocalResult result;
};

// Calibrates the rig as the calibrate command does (calibrate, then the self-check and its gate), measuring the
// result against the rig's ground truth apart (also where the gate refuses it: `gate_refused` has the reason).
Outcome calibrate_rig(const rig::VirtualRig& rig, const AutocalOptions& options, const char* what,
                      int drop_frames = 0) {
    RigPatternSource source(rig, drop_frames);
    const CalibrationPrior prior = prior_from_rig(rig);
    Outcome out;
    try {
        out.result = calibrate(source, prior, {1920, 1080}, options);
    } catch (const CalibrationRefused& e) {
        out.refused = e.what();
        std::printf("%s: refused: %s\n", what, e.what());
        return out;
    }
    out.check = run_self_check(source, prior, out.result);
    out.geometry = measure_geometry(rig, out.result.calibration, 4);
    try {
        check_self_check_gate(out.check, SelfCheckOptions{});
    } catch (const CalibrationRefused& e) {
        out.refused = e.what();
    }
    std::printf(
        "%s: geometry mean %.3f p95 %.3f max %.3f px; self-check mean %.3f px; screen radius %.4f m arc "
        "%.3f deg%s%s\n",
        what, out.geometry.mean_px, out.geometry.p95_px, out.geometry.max_px, out.check.mean_px,
        out.result.screen.radius_m, out.result.screen.arc_deg,
        out.refused.empty() ? "" : "; refused: ", out.refused.c_str());
    return out;
}

bool meets_goals(const Outcome& o) {
    // The calibration's goals against the rig's ground truth: mean <= 0.3 px, p95 <= 0.8 px.
    return o.refused.empty() && o.geometry.mean_px <= 0.3 && o.geometry.p95_px <= 0.8 &&
           o.geometry.missing + o.geometry.outside < o.geometry.samples / 100;
}

// Calibrates with the top edge's height fitted (AutocalOptions::fit_heights) and expects the goals met.
Outcome calibrate_heights_fitted(const rig::VirtualRig& rig, const char* what) {
    AutocalOptions top;
    top.fit_heights = true;
    Outcome o = calibrate_rig(rig, top, what);
    EXPECT_TRUE(meets_goals(o)) << what << ": " << o.refused << " " << o.geometry.mean_px << " / " << o.geometry.p95_px;
    return o;
}

// The screen's heights as a tape measures them: the bottom edge told 2 cm high, the top edge 2 cm low, so the
// screen is told 4 cm (2.7 %) short of its 1.5 m. Taken as exact (the default), the screen's shape is wrong and
// content would land pixels off (3.7 px measured with the heights' check off, which the self-check refuses too): the
// heights' check refuses it first, naming the heights and --fit-heights. With the top edge's height
// fitted (AutocalOptions::fit_heights; the bottom stays as the gauge) the span comes out right and content lands
// where it belongs. Fitting the screen (fit_screen) instead takes the told heights as the scale and finds the rest:
// the whole room scaled is the same to the camera.
TEST(InstallErrors, TapeMeasuredHeightsAreFittedOrRefused) {
    rig::VirtualRig rig = standard_half();
    rig.prior.screen_bottom_error_m = 0.02;
    rig.prior.screen_top_error_m = -0.02;
    const CalibrationPrior prior = prior_from_rig(rig);
    ASSERT_NEAR(prior.screen.bottom_m, rig.screen.bottom_m + 0.02, 1e-12);
    ASSERT_NEAR(prior.screen.top_m, rig.screen.top_m - 0.02, 1e-12);
    const Outcome told = calibrate_rig(rig, {}, "heights taken as exact");
    EXPECT_NE(told.refused.find("screen heights"), std::string::npos) << told.refused;
    EXPECT_NE(told.refused.find("--fit-heights"), std::string::npos) << told.refused;
    const Outcome heights = calibrate_heights_fitted(rig, "top edge fitted");
    EXPECT_EQ(heights.result.screen.bottom_m, prior.screen.bottom_m);  // the gauge
    const double true_span = rig.screen.top_m - rig.screen.bottom_m;
    EXPECT_NEAR(heights.result.screen.top_m - heights.result.screen.bottom_m, true_span, 0.004);
    AutocalOptions fit;
    fit.fit_screen = true;
    const Outcome fitted = calibrate_rig(rig, fit, "screen fitted");
    EXPECT_TRUE(meets_goals(fitted)) << fitted.geometry.mean_px << " / " << fitted.geometry.p95_px;
    // The scale is the told heights': the fitted radius is the true one times told / true height (1.46 / 1.5).
    EXPECT_NEAR(fitted.result.screen.radius_m, rig.screen.radius_m * 1.46 / 1.5, 0.01);
}

// Radius, arc and heights all as a tape measures them (the radius told 2 % long, the arc 2 degrees short, the span
// told 4 cm short): without fit_screen the told screen's shape is wrong and the calibration is refused, naming the
// heights and --fit-screen; with it, the told span is the only scale left and content lands where it belongs (a room
// scaled uniformly is the same room to the camera and to the content).
TEST(InstallErrors, RadiusArcAndHeightsAllTapeMeasuredAreFittedWithTheScreen) {
    rig::VirtualRig rig = standard_half();
    rig.prior.screen_radius_error_m = 0.06;
    rig.prior.screen_arc_error_deg = -2.0;
    rig.prior.screen_bottom_error_m = 0.02;
    rig.prior.screen_top_error_m = -0.02;
    const Outcome told = calibrate_rig(rig, {}, "radius, arc and heights taken as exact");
    ASSERT_FALSE(told.refused.empty());
    EXPECT_NE(told.refused.find("--fit-screen"), std::string::npos) << told.refused;
    AutocalOptions fit;
    fit.fit_screen = true;
    const Outcome fitted = calibrate_rig(rig, fit, "radius, arc and heights tape-measured, screen fitted");
    EXPECT_TRUE(meets_goals(fitted)) << fitted.refused << " " << fitted.geometry.mean_px << " / "
                                     << fitted.geometry.p95_px;
    EXPECT_NEAR(fitted.result.screen.arc_deg, rig.screen.arc_deg, 0.3);
    const double told_over_true_span = 1.46 / (rig.screen.top_m - rig.screen.bottom_m);
    EXPECT_NEAR(fitted.result.screen.radius_m, rig.screen.radius_m * told_over_true_span, 0.01);
}

// Heights a few millimetres off, as a careful tape leaves them: the span told 8 mm short (0.5 %). Taken as exact
// with the heights' check off, content lands further off than the goals allow (measured p95 1.15 px) while the edges
// still meet their gate and the self-check, through the same told screen, passes (0.27 px): a silent error. The
// check (on by default) sees the top edge 8 mm from the told height and refuses, naming the heights and
// --fit-heights; its figure, the content's shift between the told and the fitted span, is the error the truth
// measures. With the top edge fitted the goals are met (0.30 px).
TEST(InstallErrors, HeightsAFewMillimetresOffAreRefusedOrFitted) {
    rig::VirtualRig rig = standard_half();
    rig.prior.screen_bottom_error_m = 0.005;
    rig.prior.screen_top_error_m = -0.003;
    // The check's gate lifted: the calibration as it was before the check (the check leaves the fit as it is), and
    // the check's figure against the truth's error of that calibration.
    AutocalOptions ungated;
    ungated.max_heights_shift_px = 1e9;
    const Outcome told = calibrate_rig(rig, ungated, "span 8 mm short, taken as exact, the check's gate lifted");
    EXPECT_TRUE(told.refused.empty()) << told.refused;  // silent: the failure the check exists for
    EXPECT_FALSE(meets_goals(told));
    const HeightsCheck& h = told.result.report.heights;
    ASSERT_TRUE(h.tried);
    EXPECT_NEAR(h.fitted_top_m - prior_from_rig(rig).screen.top_m, 0.008, 0.002);
    EXPECT_GT(h.shift_mean_px, AutocalOptions{}.max_heights_shift_px);
    EXPECT_NEAR(h.shift_mean_px, told.geometry.mean_px, 0.5 * told.geometry.mean_px);
    const Outcome checked = calibrate_rig(rig, {}, "span 8 mm short, taken as exact");
    EXPECT_NE(checked.refused.find("screen heights"), std::string::npos) << checked.refused;
    EXPECT_NE(checked.refused.find("--fit-heights"), std::string::npos) << checked.refused;
    const Outcome fitted = calibrate_heights_fitted(rig, "span 8 mm short, top edge fitted");
    EXPECT_LT(fitted.geometry.p95_px, 0.5 * told.geometry.p95_px);
}

// Told heights that are right: the check finds the top edge where it was told and content moving by a small part
// of its gate (0.04 px measured on the standard rig at half scale).
TEST(InstallErrors, RightHeightsPassTheirCheck) {
    const rig::VirtualRig rig = standard_half();
    const Outcome o = calibrate_rig(rig, {}, "heights right");
    ASSERT_TRUE(o.refused.empty()) << o.refused;
    const HeightsCheck& h = o.result.report.heights;
    ASSERT_TRUE(h.tried);
    EXPECT_NEAR(h.fitted_top_m, rig.screen.top_m, 0.002);
    EXPECT_LT(h.shift_mean_px, 0.5 * AutocalOptions{}.max_heights_shift_px);
    EXPECT_TRUE(meets_goals(o)) << o.geometry.mean_px << " / " << o.geometry.p95_px;
}

// The radius told 2 % long (6 cm), the heights right. Taken as told, the screen's shape is wrong: to the camera a
// radius told long looks like a span told short, and the heights' check refuses it. With the top edge fitted the
// told radius is the scale: the span comes out 2 % long too, the room scaled about the bottom edge, which the camera
// sees alike, so content lands where it belongs.
TEST(InstallErrors, WithTheHeightsFittedARadiusOffIsTheRoomScaled) {
    rig::VirtualRig rig = standard_half();
    rig.prior.screen_radius_error_m = 0.06;
    const Outcome told = calibrate_rig(rig, {}, "radius 6 cm long, heights taken as exact");
    EXPECT_NE(told.refused.find("screen heights"), std::string::npos) << told.refused;
    const Outcome fitted = calibrate_heights_fitted(rig, "radius 6 cm long, top edge fitted");
    const double span = rig.screen.top_m - rig.screen.bottom_m;
    EXPECT_NEAR(fitted.result.screen.top_m - fitted.result.screen.bottom_m, span * 3.06 / 3.0, 0.004);
}

// With the screen to be fitted, the camera pose's first edge fit (on the told cylinder) is only a start: its gate is
// five times looser there (a sanity limit), and the gate holds the bundle adjustment's edge fit instead. Here the
// gate is tightened to 5 mm so that the told screen's start (5.6 mm: heights 2 cm off each) fails it: taken
// as exact, the start is refused; fitted, the screen's edges meet the gate after the bundle adjustment (4.1 mm).
TEST(InstallErrors, WithTheScreenFittedTheEdgeGateHoldsTheFittedScreen) {
    rig::VirtualRig rig = standard_half();
    rig.prior.screen_bottom_error_m = 0.02;
    rig.prior.screen_top_error_m = -0.02;
    AutocalOptions told;
    told.max_edge_rms_m = 0.005;
    const Outcome refused = calibrate_rig(rig, told, "edge gate 5 mm, heights taken as exact");
    EXPECT_NE(refused.refused.find("camera pose: edge fit rms"), std::string::npos) << refused.refused;
    for (const bool screen : {false, true}) {
        AutocalOptions fit = told;
        fit.fit_heights = !screen;
        fit.fit_screen = screen;
        const Outcome fitted =
            calibrate_rig(rig, fit, screen ? "edge gate 5 mm, screen fitted" : "edge gate 5 mm, top edge fitted");
        EXPECT_TRUE(meets_goals(fitted)) << fitted.refused << " " << fitted.geometry.mean_px << " / "
                                         << fitted.geometry.p95_px;
        EXPECT_LE(fitted.result.report.edge_rms_m, fit.max_edge_rms_m);
    }
}

// Both heights 2 cm high: the screen told where it is not along its axis, its size right. The edges fix the
// camera's pose to the screen, so the whole room is told 2 cm higher, and content lands where it belongs.
TEST(InstallErrors, ACommonHeightErrorMovesNothing) {
    rig::VirtualRig rig = standard_half();
    rig.prior.screen_bottom_error_m = 0.02;
    rig.prior.screen_top_error_m = 0.02;
    const Outcome o = calibrate_rig(rig, {}, "both heights 2 cm high");
    EXPECT_TRUE(meets_goals(o)) << o.refused << " " << o.geometry.mean_px << " / " << o.geometry.p95_px;
}

// Motion-JPEG frames at quality 80 (8 x 8 blocks, ringing at the patterns' edges): the Gray code compares each
// pattern with its inverse and the phase sinusoids are smooth, so the decoding holds and the goals are met.
TEST(InstallErrors, MjpegFramesMeetTheGoals) {
    rig::VirtualRig rig = standard_half();
    rig.camera.mjpeg_quality = 80;
    const Outcome o = calibrate_rig(rig, {}, "MJPEG quality 80");
    EXPECT_TRUE(meets_goals(o)) << o.refused << " " << o.geometry.mean_px << " / " << o.geometry.p95_px;
}

// rigs/realistic-install.toml at half scale, its screen fitted: the camera's chessboard intrinsics off (focal 0.8 %,
// principal point (7, -9) px at full scale, k1 +0.01, k2 -0.004), the heights told 3.5 cm short, projector lenses,
// defocus, vignetting, Motion-JPEG. The edge points are assigned to the screen's edges through the prior's
// intrinsics, which left out 45 % of the top edge's, and some crossings in the overlaps lay 4 to 5 mm off the edge
// within the assignment's gate: the fitted arc came 0.29 degrees short, content 0.28 px off on average (0.48 px at
// full scale) while the self-check, through the same camera model, saw 0.18 px. Now the edge points are assigned
// again through the refined model and the adjustment drops edge points beyond 4x the median distance.
TEST(InstallErrors, TheFittedScreenHoldsItsArcWithTheCamerasLensPriorOff) {
    const rig::VirtualRig rig =
        scaled_rig(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/realistic-install.toml"), 0.5, 0.5);
    AutocalOptions fit;
    fit.fit_screen = true;
    const Outcome o = calibrate_rig(rig, fit, "realistic-install x0.5, screen fitted");
    ASSERT_TRUE(o.refused.empty()) << o.refused;
    EXPECT_TRUE(o.result.report.intrinsics.kept);  // the camera's intrinsics refined with the screen
    EXPECT_NEAR(o.result.screen.arc_deg, rig.screen.arc_deg, 0.1);
    EXPECT_LE(o.geometry.mean_px, 0.1);  // measured 0.04 (0.28 before)
    EXPECT_LE(o.geometry.p95_px, 0.2);   // measured 0.06 (0.52 before)
}

// The lit edges one projector at a time (lit_screen). realistic-install's camera integrates over its pixels and
// reaches full scale on one projector's white, so with every projector white at once the overlaps saturate and their
// edge points cross the half level outward. Posed on the true screen with the exact prior, the camera's edge fit
// from lit_screen's image keeps its points closer to the edges.
TEST(InstallErrors, TheLitEdgesAreFoundOneProjectorAtATime) {
    rig::VirtualRig rig =
        scaled_rig(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/realistic-install.toml"), 0.5, 0.5);
    rig.prior = {};  // the truth: the camera's pose and intrinsics, the screen
    RigPatternSource source(rig);
    const CalibrationPrior prior = prior_from_rig(rig);
    std::vector<ImageSize> sizes;
    for (const DeviceModel& p : prior.projectors) sizes.push_back(p.resolution);
    std::vector<cv::Mat> signals(sizes.size());
    const cv::Mat1f black = show_averaged(source, signals, 1).clone();
    for (std::size_t k = 0; k < sizes.size(); ++k) signals[k] = cv::Mat1f(sizes[k].height, sizes[k].width, 1.0f);
    cv::Mat1f together;
    cv::subtract(show_averaged(source, signals, 1), black, together);
    int captures = 0;
    const cv::Mat1f apart = lit_screen(source, sizes, black, 1, captures);
    EXPECT_EQ(captures, 2 * static_cast<int>(sizes.size()));  // each projector's white and grey
    const EdgeFit all_at_once = fit_camera_pose(together, prior, AutocalOptions{});
    const EdgeFit one_at_a_time = fit_camera_pose(apart, prior, AutocalOptions{});
    std::printf("lit edges rms: every projector at once %.2f mm (%d points), one at a time %.2f mm (%d points)\n",
                1e3 * all_at_once.rms_m, all_at_once.points, 1e3 * one_at_a_time.rms_m, one_at_a_time.points);
    EXPECT_LT(one_at_a_time.rms_m, 0.8 * all_at_once.rms_m);  // measured 1.19 mm against 2.03
    EXPECT_LE(one_at_a_time.rms_m, 0.0015);
}

// Light the screen throws back onto itself (realistic-screen's gain screen), filmed brighter than the rig sets it
// (exposure 1.3 of its 0.7): past a projector's image the screen's own light passes the absolute shadow threshold
// (min_contrast), carries no pattern, and the coarsest Gray bits stop resolving over the lit pixels. The threshold
// relative to the projector's own contrast (shadow_relative) keeps the mask to its image, and the calibration gets past
// the Gray code, and (with the lit edges' level taken from each projector's grey where its white clips,
// camera_clipping.h) meets the goals.
TEST(InstallErrors, LightTheScreenThrowsBackIsNotTakenForTheProjectors) {
    rig::VirtualRig rig =
        scaled_rig(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/realistic-screen.toml"), 0.5, 0.5);
    std::vector<ImageSize> sizes;
    for (const DeviceModel& p : prior_from_rig(rig).projectors) sizes.push_back(p.resolution);
    const AutocalOptions relative;
    AutocalOptions absolute;
    absolute.shadow_relative = 0.0;
    const auto decode = [&](const AutocalOptions& o) {
        RigPatternSource source(rig);
        return decode_projector(source, 1, sizes, o);
    };
    const Correspondences as_set = decode(relative);
    rig.camera.exposure = 1.3;
    const Correspondences bright = decode(relative);
    const Correspondences bright_absolute = decode(absolute);
    std::printf(
        "lit pixels / column, row bits: exposure 0.7 %d / %d, %d; 1.3 %d / %d, %d; 1.3 absolute mask %d / %d, "
        "%d\n",
        as_set.lit_pixels, as_set.column_bits, as_set.row_bits, bright.lit_pixels, bright.column_bits, bright.row_bits,
        bright_absolute.lit_pixels, bright_absolute.column_bits, bright_absolute.row_bits);
    EXPECT_LT(std::min(bright_absolute.column_bits, bright_absolute.row_bits), absolute.min_bits);
    EXPECT_NEAR(bright.lit_pixels, as_set.lit_pixels, 0.1 * as_set.lit_pixels);
    EXPECT_GE(bright.column_bits, as_set.column_bits - 1);
    EXPECT_GE(bright.row_bits, as_set.row_bits - 1);
    const Outcome o = calibrate_rig(rig, relative, "realistic-screen x0.5 at exposure 1.3");
    EXPECT_EQ(o.refused.find("Gray-code"), std::string::npos) << o.refused;
    EXPECT_TRUE(meets_goals(o)) << o.refused << " " << o.geometry.mean_px << " / " << o.geometry.p95_px;
}

// A camera that clips the projectors' white (camera_clipping.h): realistic-screen (a gain screen) filmed brighter
// than the rig sets its camera (0.7). The lit edges' half level comes from each projector's grey where its white
// clips, so the camera's pose does not move outward with the clipped edges, and the phase patterns' clipped images
// are left out of each pixel's fit (phase_shift.h): at exposure 2.4 (the white about 2.5 times full scale) the
// geometry is close to what it is at 0.7 (before: refused; with that gate lifted, 0.30 / 0.69 px at 1.8), and
// 1.3 meets the goals (LightTheScreenThrowsBack... above). A white clipped beyond three times full scale is
// refused naming the exposure.
TEST(InstallErrors, ACameraClippingTheWhiteKeepsTheLitEdges) {
    rig::VirtualRig rig =
        scaled_rig(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/realistic-screen.toml"), 0.5, 0.5);
    const Outcome as_set = calibrate_rig(rig, AutocalOptions{}, "realistic-screen x0.5 at exposure 0.7");
    rig.camera.exposure = 2.4;
    const Outcome clipped = calibrate_rig(rig, AutocalOptions{}, "realistic-screen x0.5 at exposure 2.4");
    ASSERT_TRUE(meets_goals(as_set)) << as_set.refused;
    ASSERT_TRUE(meets_goals(clipped)) << clipped.refused;
    EXPECT_LT(clipped.geometry.mean_px, as_set.geometry.mean_px + 0.05);
    EXPECT_LT(clipped.geometry.p95_px, as_set.geometry.p95_px + 0.05);
    for (const double exposure : {3.5, 6.0}) {
        rig.camera.exposure = exposure;
        const Outcome refused = calibrate_rig(rig, AutocalOptions{}, "realistic-screen x0.5 overexposed");
        EXPECT_NE(refused.refused.find("camera exposure"), std::string::npos) << exposure << ": " << refused.refused;
    }
}

// The camera's timing (camera_timing.h): a camera whose first frame after each pattern change still holds 30 % of
// the previous pattern (rig camera.straddle; an exposure across the flip). The share is measured from the sequence
// itself; the calibration refuses it naming the dropped frames, and calibrates within the goals with one frame
// dropped after each change, as the site's camera source drops them. With its gate lifted the same rig must not
// meet the goals: it is refused for a cause that does not name the timing (each projector's white holds a ghost
// of the pattern before it, which passes the shadow mask and never decodes: "Gray-code decoding failed").
TEST(InstallErrors, FramesStraddlingTheFlipAreMeasuredRefusedAndDropped) {
    rig::VirtualRig rig = standard_half();
    std::vector<ImageSize> sizes;
    for (const DeviceModel& p : prior_from_rig(rig).projectors) sizes.push_back(p.resolution);
    {
        RigPatternSource clean(rig);
        int captures = 0;
        const FrameStraddle none = measure_frame_straddle(clean, sizes, 0.04, captures);
        EXPECT_LT(std::abs(none.share), 0.005) << "a camera that does not straddle";
        EXPECT_GT(none.pixels, 10000);
        EXPECT_EQ(captures, 4);
    }
    rig.camera.straddle = 0.3;
    {
        RigPatternSource straddled(rig);
        int captures = 0;
        EXPECT_NEAR(measure_frame_straddle(straddled, sizes, 0.04, captures).share, 0.3, 0.01);
    }
    const Outcome refused = calibrate_rig(rig, AutocalOptions{}, "straddle 30 %");
    EXPECT_NE(refused.refused.find("camera timing"), std::string::npos) << refused.refused;
    EXPECT_NE(refused.refused.find("--drop-frames"), std::string::npos) << refused.refused;
    AutocalOptions lifted;
    lifted.max_frame_straddle = 1.0;
    const Outcome unguarded = calibrate_rig(rig, lifted, "straddle 30 %, gate lifted");
    EXPECT_FALSE(meets_goals(unguarded)) << "straddled patterns calibrated within the goals: the gate is not needed";
    const Outcome dropped = calibrate_rig(rig, AutocalOptions{}, "straddle 30 %, one frame dropped", 1);
    EXPECT_TRUE(meets_goals(dropped)) << dropped.refused << " " << dropped.geometry.mean_px << " / "
                                      << dropped.geometry.p95_px;
    EXPECT_LT(std::abs(dropped.result.report.frame_straddle), 0.005);
}

}  // namespace
}  // namespace mogao::autocal
