// SPDX-License-Identifier: Apache-2.0
// Self-recalibration on the virtual rig, judged against the rig's GROUND TRUTH (the wall's
// calibration rendered through the true, bumped poses: autocal::measure_geometry), never against
// the monitor's own estimate. Shorter versions of docs/calibration.md's scenarios: a monitor at
// 2 Hz, hold 1 s, transition 1 s, projectors and camera at half resolution (errors in those
// projector pixels).
#include "appliance/selfcal/rig_simulation.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "appliance/autocal/colour_truth.h"
#include "appliance/autocal/model_store.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/rig/rig_file.h"
#include "appliance/selfcal/calibration_store.h"

namespace mogao::selfcal {
namespace {

rig::VirtualRig standard() { return rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml"); }

SimulationOptions quick(int frames) {
    SimulationOptions o;
    o.frames = frames;
    o.rate_hz = 2.0;
    o.selfcal.hold_s = 1.0;
    o.selfcal.transition_s = 1.0;
    o.selfcal.build.warp_step_px = 4;
    return o;
}

int frames_in(const SimulationReport& r, SelfcalState s) {
    return static_cast<int>(
        std::count_if(r.frames.begin(), r.frames.end(), [&](const auto& f) { return f.state == s; }));
}

std::string journal(const SimulationReport& r) {
    std::string out;
    for (const std::string& l : r.journal) out += l + "\n";
    return out;
}

// Started from an estimate and bumped at `bump_s`: no state change on the estimate alone, then the bump
// detected within 2 s and corrected once, below 1 px against the ground truth.
void expect_one_correction_after(const SimulationReport& r, double bump_s) {
    for (const SimulationFrame& f : r.frames) {
        if (f.t_s < bump_s) {
            EXPECT_EQ(f.state, SelfcalState::calibrated) << "t=" << f.t_s << "\n" << journal(r);
        }
    }
    ASSERT_TRUE(r.detected_after_s.has_value()) << journal(r);
    EXPECT_LE(*r.detected_after_s, 2.0);
    ASSERT_TRUE(r.corrected_after_s.has_value()) << journal(r);
    EXPECT_EQ(r.corrections, 1) << journal(r);
    EXPECT_LT(r.final_error_px, 1.0);
    EXPECT_EQ(r.final_state, SelfcalState::calibrated);
}

TEST(SelfcalRig, ProjectorBumpedOneDegreeIsDetectedAndCorrectedBelowOnePixel) {
    const rig::VirtualRig rig = standard();
    SimulationOptions o = quick(12);
    Bump b = parse_bump(rig, "proj1:yaw=1deg");
    b.at_s = 0.5;
    o.bumps = {b};
    const SimulationReport r = simulate(rig, o);
    EXPECT_GT(r.error_before_px, 5.0) << "the bump must be visible in the ground truth";
    ASSERT_TRUE(r.detected_after_s.has_value()) << journal(r);
    EXPECT_LE(*r.detected_after_s, 2.0);
    ASSERT_TRUE(r.corrected_after_s.has_value()) << journal(r);
    EXPECT_LE(*r.corrected_after_s, 5.0);  // 10 monitored frames
    EXPECT_EQ(r.corrections, 1) << journal(r);
    EXPECT_LT(r.final_error_px, 1.0);
    EXPECT_LT(r.final_p95_px, 1.5);
    EXPECT_EQ(r.final_state, SelfcalState::calibrated);
}

// A full calibration is never exact. Starting from autocal's estimate on the same rig (its own
// residual in every ground-truth figure), the monitor must neither take that residual for a drift
// before the bump nor fail to correct the bump below 1 px against the ground truth.
TEST(SelfcalRig, StartingFromAFullCalibrationsEstimateABumpIsStillCorrected) {
    SimulationOptions o = quick(16);
    const rig::VirtualRig scaled = autocal::scaled_rig(standard(), o.projector_scale, o.camera_scale);
    autocal::RigPatternSource source(scaled);
    const autocal::AutocalResult est = autocal::calibrate(source, autocal::prior_from_rig(scaled), {1920, 1080});
    o.start_model = SystemModel{est.screen, est.camera, est.projectors};
    Bump b = parse_bump(scaled, "proj1:yaw=1deg");
    b.at_s = 2.0;  // four monitored frames on the estimate alone first
    o.bumps = {b};
    const SimulationReport r = simulate(standard(), o);
    EXPECT_GT(r.start_error_px, 0.05) << "an estimate, not the rig's exact models";
    EXPECT_LT(r.start_error_px, 0.5);
    expect_one_correction_after(r, b.at_s);

    // Models of another rig's devices are refused, naming what differs.
    SimulationOptions wrong = quick(1);
    wrong.start_model = models_of_rig(standard());  // full resolution, the simulation's at half
    try {
        (void)simulate(standard(), wrong);
        FAIL() << "models at another resolution accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("calibrate at the same"), std::string::npos) << e.what();
    }
}

// Every projection lens distorts. On rigs/realistic-lens.toml (projector k1 up to 0.04, the rig's [prior]
// errors) the full calibration keeps each projector's distortion; the monitor starts from its models file
// as the kiosk does (written, read back), fits poses on undistorted rays and must correct a bump as on
// pinholes, and must not take the lens for a drift before it.
TEST(SelfcalRig, StartingFromAnEstimateWithProjectorLensDistortionABumpIsCorrected) {
    SimulationOptions o = quick(16);
    const rig::VirtualRig rig = rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/realistic-lens.toml");
    const rig::VirtualRig scaled = autocal::scaled_rig(rig, o.projector_scale, o.camera_scale);
    autocal::RigPatternSource source(scaled);
    const autocal::AutocalResult est = autocal::calibrate(source, autocal::prior_from_rig(scaled), {1920, 1080});
    int distorting = 0;
    for (const autocal::DeviceModel& d : est.projectors) distorting += std::abs(d.distortion[0]) > 0.01 ? 1 : 0;
    ASSERT_GE(distorting, 2) << "the estimate should keep the projectors' lens distortion";
    const std::filesystem::path file =
        std::filesystem::temp_directory_path() / ("selfcal-lens-" + std::to_string(::getpid()) + ".models.json");
    autocal::write_models(file, {est.screen, est.camera, est.projectors});
    const autocal::CalibrationModels read = autocal::read_models(file);
    std::filesystem::remove(file);
    o.start_model = SystemModel{read.screen, read.camera, read.projectors};
    Bump b = parse_bump(scaled, "proj1:yaw=1deg");
    b.at_s = 2.0;
    o.bumps = {b};
    const SimulationReport r = simulate(rig, o);
    EXPECT_LT(r.start_error_px, 0.5);
    expect_one_correction_after(r, b.at_s);
}

// The shift goal: a 10 mm shift (about 3 projector pixels at half resolution) is
// detected and corrected to under 1 px against the ground truth; a shift and a rotation look
// alike in the image, so this checks the correction's shift is not lost to the position prior.
TEST(SelfcalRig, ProjectorShiftedTenMillimetresIsCorrectedBelowOnePixel) {
    const rig::VirtualRig rig = standard();
    SimulationOptions o = quick(14);
    Bump b = parse_bump(rig, "proj1:x=10mm");
    b.at_s = 0.5;
    o.bumps = {b};
    const SimulationReport r = simulate(rig, o);
    EXPECT_GT(r.error_before_px, 2.0) << "the shift must be visible in the ground truth";
    ASSERT_TRUE(r.detected_after_s.has_value()) << journal(r);
    EXPECT_LE(*r.detected_after_s, 2.0);
    ASSERT_TRUE(r.corrected_after_s.has_value()) << journal(r);
    EXPECT_LT(r.final_error_px, 1.0) << journal(r);
    EXPECT_EQ(r.final_state, SelfcalState::calibrated) << journal(r);
}

TEST(SelfcalRig, NoFalseCorrectionWithNoiseExposureChangesAndVisitors) {
    SimulationOptions o = quick(12);
    o.exposure_jitter = 0.3;
    o.occlusion = 0.1;
    o.occlusion_max = 0.4;
    const SimulationReport r = simulate(standard(), o);
    EXPECT_EQ(r.corrections, 0) << journal(r);
    EXPECT_EQ(frames_in(r, SelfcalState::calibrated), 12) << journal(r);
    EXPECT_LT(r.final_error_px, 0.1);
}

// The same on rigs/realistic-lens.toml (projector lens distortion, a camera integrating over its pixels),
// nothing moved: with visitors hiding most of one projector, a frame's few matches put that projector
// 0.7 px off in the filter, which rejected every later frame saying "no change"; it was corrected at 5.5 s
// and the wall went from 0.02 to 0.66 px against the ground truth. A drift contested by a rejected "no
// change" is not corrected, and a fresh one must be seen in two measured frames in a row.
TEST(SelfcalRig, NoFalseCorrectionOnALensRigWithVisitors) {
    SimulationOptions o = quick(16);
    o.exposure_jitter = 0.3;
    o.occlusion = 0.1;
    o.occlusion_max = 0.4;
    o.selfcal.hold_s = 2.0;  // the defaults: the false correction needed its hold of 2 s
    o.selfcal.transition_s = 3.0;
    const SimulationReport r = simulate(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/realistic-lens.toml"), o);
    EXPECT_EQ(r.corrections, 0) << journal(r);
    EXPECT_LT(r.final_error_px, 0.1);
}

// Heavy visitors (20-50 % of the camera view, standing in front of the screen and showing the
// content displaced) and exposure changes of +-30 %, nothing moved. Without the occluder mask
// (MonitorOptions::occluder_ratio = 0) this realisation made a false correction at 8 s
// (proj "moved" by visitor-displaced features agreeing for three frames), 8 px against the
// ground truth; the visitors' matches must never reach the fits.
SimulationOptions heavy_visitors(int frames) {
    SimulationOptions o = quick(frames);
    o.projector_scale = 0.25;
    o.exposure_jitter = 0.3;
    o.occlusion = 0.2;
    o.occlusion_max = 0.5;
    o.truth_every = 10;
    o.seed = 2;
    return o;
}

TEST(SelfcalRig, HeavyVisitorsMakeNoFalseDetectionOrCorrection) {
    const SimulationReport r = simulate(standard(), heavy_visitors(20));
    EXPECT_EQ(r.detections, 0) << journal(r);
    EXPECT_EQ(r.corrections, 0) << journal(r);
    EXPECT_EQ(journal(r).find("camera moved"), std::string::npos) << journal(r);
    EXPECT_LT(r.final_error_px, 0.1) << journal(r);
}

// The same visitors must not hide a real bump: proj1 yawed 1 degree among visitors hiding 10-40 %
// is detected within 5 s (the goal is 10 s) and corrected below 1 px (the table's row took 25 s to detect and never
// corrected before the occluder mask).
TEST(SelfcalRig, BumpAmongVisitorsIsStillCorrectedBelowOnePixel) {
    const rig::VirtualRig rig = standard();
    SimulationOptions o = heavy_visitors(16);
    o.occlusion = 0.1;
    o.occlusion_max = 0.4;
    o.truth_every = 1;
    Bump b = parse_bump(rig, "proj1:yaw=1deg");
    b.at_s = 0.5;
    o.bumps = {b};
    const SimulationReport r = simulate(rig, o);
    EXPECT_GT(r.error_before_px, 2.0) << "the bump must be visible in the ground truth";
    ASSERT_TRUE(r.detected_after_s.has_value()) << journal(r);
    EXPECT_LE(*r.detected_after_s, 5.0) << journal(r);
    ASSERT_TRUE(r.corrected_after_s.has_value()) << journal(r);
    EXPECT_LT(r.final_error_px, 1.0) << journal(r);
    EXPECT_EQ(r.final_state, SelfcalState::calibrated) << journal(r);
}

// The visitor mask on its own: a clean camera frame of the wall (exposure 0.7) loses nothing; with
// a dark band over a third of the screen's width, showing the content displaced as a visitor
// would, the mask covers about that share (grown by a cell) and drops the matches on it.
TEST(SelfcalRig, OccluderMaskFindsADarkBandAndNothingInACleanFrame) {
    const rig::VirtualRig rig = autocal::scaled_rig(standard(), 0.25, 0.5);
    const SystemModel model = models_of_rig(rig);
    autocal::AutocalOptions build;
    build.warp_step_px = 8;
    const ScreenCalibration wall = autocal::calibration_from_models(model.projectors, model.screen, {960, 540}, build);
    const cv::Mat1f content = make_content(ContentKind::textured, 0.0, false, 3);
    std::vector<cv::Mat> signals;
    for (const ProjectorCalibration& pc : wall.projectors) signals.emplace_back(projector_signal(pc, content));
    cv::Mat1f clean;
    rig::CameraSimulator(rig).capture(signals, 1).convertTo(clean, CV_32F, 0.7);
    const Monitor monitor(model, wall);
    const FrameMeasurement a = monitor.measure(content, clean);
    EXPECT_LT(a.occluded_fraction, 0.02);
    EXPECT_EQ(a.occluded_matches, 0);
    cv::Mat1f hidden = clean.clone();
    const cv::Rect band(clean.cols / 3, 0, clean.cols / 6, clean.rows);
    cv::Mat1f shifted;
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 25, 0, 1, 0);
    cv::warpAffine(clean, shifted, shift, clean.size());
    cv::Mat1f inside = hidden(band);
    shifted(band).convertTo(inside, CV_32F, 0.4, 0.01);  // in place: same size and type
    const FrameMeasurement b = monitor.measure(content, hidden);
    EXPECT_GT(b.occluded_fraction, 0.15);
    EXPECT_LT(b.occluded_fraction, 0.5);
    EXPECT_GT(b.occluded_matches, 0);
    EXPECT_GT(b.matches, a.matches / 3);
}

// Self-recalibration with the colour calibration: the wall carries the measured colour of
// rigs/colour.toml (projectors of different brightness, colour temperature, per-channel gamma and
// black level: per-channel LUTs, beta maps, blends scaled by s). After proj1 is yawed 1 degree and
// corrected, the wall must still show one black and one colour everywhere, judged on the bumped
// rig's GROUND TRUTH light (colour_truth.h), and keep the projectors' responses. Before the fix a
// correction rebuilt gamma 2.2 LUTs and no beta maps: seam black off by about a third, grey seams
// about 10 Delta E76 (docs/calibration.md's "before" column).
TEST(SelfcalRig, ACorrectionKeepsTheMeasuredColour) {
    const rig::VirtualRig rig = rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/colour.toml");
    SimulationOptions o = quick(12);
    o.measured_colour = true;
    Bump b = parse_bump(rig, "proj1:yaw=1deg");
    b.at_s = 0.5;
    o.bumps = {b};
    const SimulationReport r = simulate(rig, o);
    EXPECT_GT(r.error_before_px, 5.0);
    ASSERT_TRUE(r.corrected_after_s.has_value()) << journal(r);
    EXPECT_EQ(r.corrections, 1) << journal(r);
    EXPECT_LT(r.final_error_px, 1.0) << journal(r);
    const ScreenCalibration& before = r.initial_calibration;
    const ScreenCalibration& after = r.final_calibration;
    ASSERT_EQ(after.projectors.size(), 3U);
    for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_TRUE(after.projectors[k].response.lut == before.projectors[k].response.lut)
            << "the projector's own response";
        EXPECT_FALSE(after.projectors[k].beta.rgb.empty()) << k;
    }
    // Re-derived for the new overlaps, not copied: proj1's black-level map moved with its image.
    EXPECT_NE(after.projectors[1].beta.rgb, before.projectors[1].beta.rgb);
    for (const double level : {0.0, 0.05, 0.5}) {
        const autocal::SeamColour c = autocal::measure_seam_colour(r.final_rig, after, level);
        std::printf("after the correction, content %.2f: seam luminance p95 %.2f %%, seam Delta E76 p95 %.2f\n", level,
                    100.0 * c.seam_luminance_p95, c.seam_delta_e_p95);
        EXPECT_LT(c.seam_luminance_p95, 0.02) << level;  // the colour test holds 1-1.5 % at quarter scale
        EXPECT_LT(c.seam_delta_e_p95, 0.6) << level;
    }
}

// measured_colour recovers what apply_measured_colour applied (responses, blacks), also after the
// MPCDI round trip the kiosk's store makes (16-bit alpha and beta maps), and refuses beta maps that
// are not a black-level compensation of the models' overlaps.
TEST(SelfcalRig, MeasuredColourIsRecoveredFromACalibrationAndItsFile) {
    const rig::VirtualRig rig =
        autocal::scaled_rig(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/colour.toml"), 0.25, 0.25);
    const SystemModel model = models_of_rig(rig);
    autocal::AutocalOptions build;
    build.warp_step_px = 8;
    const autocal::MeasuredColour truth = colour_of_rig(rig);
    ScreenCalibration wall = autocal::calibration_from_models(model.projectors, model.screen, {960, 540}, build);
    const double s = autocal::apply_measured_colour(truth, model.projectors, model.screen, wall);
    EXPECT_GT(s, 0.98);
    EXPECT_LT(s, 1.0);
    const std::filesystem::path file =
        std::filesystem::temp_directory_path() / ("mogao-selfcal-colour-" + std::to_string(::getpid()) + ".mpcdi");
    save_calibration(file, wall);
    const ScreenCalibration read = load_calibration(file);
    std::filesystem::remove(file);
    for (const ScreenCalibration* c : {static_cast<const ScreenCalibration*>(&wall), &read}) {
        const autocal::MeasuredColour got = autocal::measured_colour(*c, model.projectors, model.screen);
        for (std::size_t k = 0; k < 3; ++k) {
            EXPECT_TRUE(got.responses[k].lut == truth.responses[k].lut) << k;
            for (std::size_t ch = 0; ch < 3; ++ch) {
                EXPECT_NEAR(got.black[k][ch], truth.black[k][ch], 0.01 * truth.black[k][ch]) << k << " " << ch;
            }
        }
    }
    const ScreenCalibration plain = autocal::calibration_from_models(model.projectors, model.screen, {960, 540}, build);
    const autocal::MeasuredColour none = autocal::measured_colour(plain, model.projectors, model.screen);
    EXPECT_EQ(none.black[1][0], 0.0);
    ScreenCalibration foreign = wall;
    cv::RNG rng(3);
    for (float& v : foreign.projectors[1].beta.rgb) v = static_cast<float>(rng.uniform(0.0, 0.01));
    try {
        (void)autocal::measured_colour(foreign, model.projectors, model.screen);
        FAIL() << "explained random beta maps";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("cannot be re-derived"), std::string::npos) << e.what();
    }
    // The self-calibrator still runs on such a calibration, keeping those maps, and says so once.
    SelfCalibrator sc(model, foreign);
    const cv::Mat1f content = make_content(ContentKind::plain, 0.0, false, 1);
    const cv::Mat1f camera(rig.camera.resolution.height, rig.camera.resolution.width, 0.2f);
    const StepResult first = sc.step(content, camera, 0.0);
    ASSERT_EQ(first.journal.size(), 1U);
    EXPECT_NE(first.journal[0].find("corrections keep those maps as they are"), std::string::npos) << first.journal[0];
    EXPECT_TRUE(sc.step(content, camera, 0.5).journal.empty());
}

TEST(SelfcalRig, BumpedCameraIsNotTakenForEveryProjectorMoving) {
    const rig::VirtualRig rig = standard();
    SimulationOptions o = quick(8);
    Bump b = parse_bump(rig, "camera:yaw=1deg,pitch=0.5deg,x=10mm");
    b.at_s = 0.5;
    o.bumps = {b};
    const SimulationReport r = simulate(rig, o);
    EXPECT_EQ(r.corrections, 0) << journal(r);
    EXPECT_EQ(frames_in(r, SelfcalState::calibrated), 8) << journal(r);
    EXPECT_NE(journal(r).find("camera moved"), std::string::npos) << journal(r);
    EXPECT_LT(r.final_error_px, 0.1);
}

// Two of three projectors bumped by the same yaw move two thirds of the matched content as a
// camera yaw would, so the camera fit's RANSAC consensus follows them. Before the check against
// the screen's edges the camera was re-based (1.2 deg, 28 mm), the unmoved proj1 "corrected" by
// 1 degree and the wall ended 18.8 px off. The screen's edges in the frame stay put: the camera is
// not re-based and both projectors are corrected.
TEST(SelfcalRig, TwoProjectorsBumpedAlikeAreNotTakenForTheCamera) {
    const rig::VirtualRig rig = standard();
    SimulationOptions o = quick(16);
    for (const char* text : {"proj0:yaw=1deg", "proj2:yaw=1deg"}) {
        Bump b = parse_bump(rig, text);
        b.at_s = 1.0;
        o.bumps.push_back(b);
    }
    const SimulationReport r = simulate(rig, o);
    EXPECT_GT(r.error_before_px, 5.0);
    EXPECT_EQ(journal(r).find("camera moved"), std::string::npos) << journal(r);
    ASSERT_TRUE(r.corrected_after_s.has_value()) << journal(r);
    EXPECT_LT(r.final_error_px, 1.0) << journal(r);
    EXPECT_EQ(r.final_state, SelfcalState::calibrated) << journal(r);
}

// The camera and two projectors bumped at once: proj0's yaw moves its part of the image about as
// the camera's yaw does, so the consensus of matches takes proj0 for unmoved and the camera for
// still, and "corrected" the two projectors that look moved (before: the wall ended about 22 px
// off and the state said calibrated). The screen's edges show the camera moved; the camera fitted
// to proj1's matches alone moves them as the frame shows (Monitor::camera_from_one_projector).
TEST(SelfcalRig, CameraAndTwoProjectorsBumpedAtOnceAreToldApart) {
    const rig::VirtualRig rig = standard();
    SimulationOptions o = quick(24);
    for (const char* text : {"camera:yaw=1deg", "proj0:yaw=1deg", "proj2:pitch=1deg"}) {
        Bump b = parse_bump(rig, text);
        b.at_s = 1.0;
        o.bumps.push_back(b);
    }
    const SimulationReport r = simulate(rig, o);
    EXPECT_GT(r.error_before_px, 5.0);
    EXPECT_NE(journal(r).find("camera moved"), std::string::npos) << journal(r);
    ASSERT_TRUE(r.corrected_after_s.has_value()) << journal(r);
    EXPECT_LT(r.final_error_px, 1.0) << journal(r);
    EXPECT_EQ(r.final_state, SelfcalState::calibrated) << journal(r);
}

TEST(SelfcalRig, TooLittleTextureWaitsAndNeverCorrects) {
    const rig::VirtualRig rig = standard();
    // Plain content, and a dark scene: the textured frame at 4 % of its light, its texture near
    // the camera's noise (as in a dim cave).
    for (const ContentKind kind : {ContentKind::plain, ContentKind::dark}) {
        SimulationOptions o = quick(6);
        o.content = kind;
        Bump b = parse_bump(rig, "proj1:yaw=1deg");
        b.at_s = 0.5;
        o.bumps = {b};
        const SimulationReport r = simulate(rig, o);
        EXPECT_EQ(r.waiting_frames, 6) << static_cast<int>(kind);
        EXPECT_EQ(r.corrections, 0) << journal(r);
        EXPECT_EQ(frames_in(r, SelfcalState::calibrated), 6) << static_cast<int>(kind);
    }
}

// The content-independent fallback: plain content gives no features; with the pattern pair
// configured (amplitude 0.02 of full white, about 4 codes at the content's grey) the bump is
// corrected from the difference of the two camera frames (the test above: without it, it waits).
TEST(SelfcalRig, TooLittleTextureWithThePatternFallbackIsCorrectedBelowOnePixel) {
    const rig::VirtualRig rig = standard();
    SimulationOptions o = quick(14);
    o.content = ContentKind::plain;
    o.selfcal.pattern.enabled = true;
    Bump b = parse_bump(rig, "proj1:yaw=1deg");
    b.at_s = 0.5;
    o.bumps = {b};
    const SimulationReport r = simulate(rig, o);
    EXPECT_GT(r.error_before_px, 5.0);
    EXPECT_NE(journal(r).find("pattern pair"), std::string::npos) << journal(r);
    ASSERT_TRUE(r.corrected_after_s.has_value()) << journal(r);
    EXPECT_EQ(r.corrections, 1) << journal(r);
    EXPECT_LT(r.final_error_px, 1.0) << journal(r);
    EXPECT_EQ(r.final_state, SelfcalState::calibrated);
}

// The pattern alone must not make evidence out of nothing: unbumped, plain content with the
// fallback on never detects or corrects.
TEST(SelfcalRig, ThePatternFallbackMakesNoFalseCorrection) {
    SimulationOptions o = quick(8);
    o.content = ContentKind::plain;
    o.selfcal.pattern.enabled = true;
    o.exposure_jitter = 0.1;
    const SimulationReport r = simulate(standard(), o);
    EXPECT_EQ(r.corrections, 0) << journal(r);
    EXPECT_EQ(r.detections, 0) << journal(r);
    EXPECT_LT(r.final_error_px, 0.1);
}

TEST(SelfcalRig, PatternForRefreshIsOffByDefaultAndComplementary) {
    const rig::VirtualRig rig = autocal::scaled_rig(standard(), 0.25, 0.25);
    const SystemModel model = models_of_rig(rig);
    autocal::AutocalOptions build;
    build.warp_step_px = 8;
    const ScreenCalibration wall = autocal::calibration_from_models(model.projectors, model.screen, {960, 540}, build);
    const cv::Mat1f content = make_content(ContentKind::plain, 0.0, false, 1);
    const cv::Mat1f camera(rig.camera.resolution.height, rig.camera.resolution.width, 0.2f);
    SelfCalibrator off(model, wall);
    (void)off.step(content, camera, 0.0);
    EXPECT_FALSE(off.pattern_for_refresh(0, content.size()).has_value());
    EXPECT_THROW((void)off.step_pattern(content, camera, camera, 1.0), std::invalid_argument);
    SelfcalOptions with;
    with.pattern.enabled = true;
    SelfCalibrator on(model, wall, with);
    EXPECT_FALSE(on.pattern_for_refresh(0, content.size()).has_value()) << "nothing asked before any waiting";
    const StepResult r = on.step(content, camera, 0.0);
    EXPECT_TRUE(r.status.waiting);
    const auto plus = on.pattern_for_refresh(0, content.size());
    const auto minus = on.pattern_for_refresh(1, content.size());
    ASSERT_TRUE(plus.has_value() && minus.has_value());
    EXPECT_EQ(plus->size(), content.size());
    cv::Mat1f sum;
    cv::add(*plus, *minus, sum);
    EXPECT_EQ(cv::norm(sum, cv::NORM_INF), 0.0);
    double lo = 0.0;
    double hi = 0.0;
    cv::minMaxLoc(*plus, &lo, &hi);
    EXPECT_GE(lo, 0.0);
    EXPECT_LE(hi, with.pattern.amplitude + 1e-6);
    EXPECT_GT(hi, 0.5 * with.pattern.amplitude);
    EXPECT_THROW((void)on.step_pattern(content, camera, cv::Mat1f(10, 10, 0.0f), 1.0), std::invalid_argument);
    SelfcalOptions bad = with;
    bad.pattern.amplitude = 0.0;
    EXPECT_THROW(SelfCalibrator(model, wall, bad), std::invalid_argument);
}

TEST(SelfcalRig, ProjectorPushedOffTheScreenCannotBeCorrected) {
    const rig::VirtualRig rig = standard();
    SimulationOptions o = quick(6);
    Bump b = parse_bump(rig, "proj2:yaw=-20deg");
    b.at_s = 0.5;
    o.bumps = {b};
    const SimulationReport r = simulate(rig, o);
    EXPECT_EQ(r.corrections, 0) << journal(r);
    EXPECT_EQ(r.final_state, SelfcalState::cannot_correct) << journal(r);
}

TEST(SelfcalRig, ParseBumpNamesTheBadPart) {
    const rig::VirtualRig rig = standard();
    const Bump b = parse_bump(rig, "proj0:pitch=0.5deg,x=5mm,z=0.01m");
    EXPECT_EQ(b.device, 0);
    EXPECT_DOUBLE_EQ(b.pitch_deg, 0.5);
    EXPECT_DOUBLE_EQ(b.shift_m.x(), 0.005);
    EXPECT_DOUBLE_EQ(b.shift_m.z(), 0.01);
    EXPECT_EQ(parse_bump(rig, "camera:roll=1deg").device, -1);
    EXPECT_THROW((void)parse_bump(rig, "proj9:yaw=1deg"), std::invalid_argument);
    EXPECT_THROW((void)parse_bump(rig, "proj1:yaw=abc"), std::invalid_argument);
    EXPECT_THROW((void)parse_bump(rig, "proj1:spin=1deg"), std::invalid_argument);
}

TEST(SelfcalRig, StepRefusesTimeGoingBackAndWrongFrames) {
    const rig::VirtualRig rig = autocal::scaled_rig(standard(), 0.25, 0.25);
    const SystemModel model = models_of_rig(rig);
    autocal::AutocalOptions build;
    build.warp_step_px = 8;
    const ScreenCalibration wall = autocal::calibration_from_models(model.projectors, model.screen, {960, 540}, build);
    SelfCalibrator sc(model, wall);
    const cv::Mat1f content = make_content(ContentKind::plain, 0.0, false, 1);
    const cv::Mat1f camera(rig.camera.resolution.height, rig.camera.resolution.width, 0.2f);
    const StepResult r = sc.step(content, camera, 1.0);
    EXPECT_TRUE(r.status.waiting);  // a uniform frame has no features
    EXPECT_FALSE(r.calibration.has_value());
    const std::string text = r.status.text();
    EXPECT_NE(text.find("state=calibrated"), std::string::npos) << text;
    EXPECT_NE(text.find("insufficient evidence"), std::string::npos) << text;
    EXPECT_NE(text.find("proj2"), std::string::npos) << text;
    EXPECT_THROW((void)sc.step(content, camera, 0.5), std::invalid_argument);
    EXPECT_THROW((void)sc.step(content, cv::Mat1f(10, 10, 0.0f), 2.0), std::invalid_argument);
    SelfcalOptions bad;
    bad.drift_threshold_px = 0.0;
    EXPECT_THROW(SelfCalibrator(model, wall, bad), std::invalid_argument);
}

TEST(SelfcalRig, InterpolatedCalibrationGoesFromBeforeToAfter) {
    const rig::VirtualRig rig = autocal::scaled_rig(standard(), 0.25, 0.25);
    SystemModel model = models_of_rig(rig);
    autocal::AutocalOptions build;
    build.warp_step_px = 8;
    const ScreenCalibration a = autocal::calibration_from_models(model.projectors, model.screen, {960, 540}, build);
    Pose6 d = Pose6::Zero();
    d(1) = 0.01;
    model.projectors[1] = apply_delta(model.projectors[1], d);
    const ScreenCalibration b = autocal::calibration_from_models(model.projectors, model.screen, {960, 540}, build);
    const ScreenCalibration h = interpolate_calibration(a, b, 0.5);
    const std::size_t i = 2 * (static_cast<std::size_t>(a.projectors[1].warp.size.width) * 10 + 20);
    EXPECT_NEAR(h.projectors[1].warp.uv[i], 0.5f * (a.projectors[1].warp.uv[i] + b.projectors[1].warp.uv[i]), 1e-6f);
    EXPECT_EQ(interpolate_calibration(a, b, 0.0).projectors[1].warp.uv, a.projectors[1].warp.uv);
    EXPECT_EQ(interpolate_calibration(a, b, 1.0).projectors[1].warp.uv, b.projectors[1].warp.uv);
    EXPECT_NE(a.projectors[1].warp.uv[i], b.projectors[1].warp.uv[i]);
}

}  // namespace
}  // namespace mogao::selfcal
