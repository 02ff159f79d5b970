// SPDX-License-Identifier: Apache-2.0
// The on-site path end to end: patterns through the headless output backend and the renderer,
// frames through CameraFrame, connector identification, the calibration, the files. The camera is
// the virtual rig's filming the headless outputs (rig_camera.h): the one part this cannot test is a
// real camera looking at a real screen. At 1/4 resolution to stay fast; accuracy against the rig's
// ground truth, compared with the calibration of the same rig through autocal's own rig source
// (what `mogao-calibrate-sim rig` gives).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "appliance/autocal/rig_bridge.h"
#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/rig/rig_file.h"
#include "appliance/warp/ideal_calibration.h"
#include "drivers/egl/egl_test_support.h"
#include "kiosk/calibrate/on_site_job.h"
#include "kiosk/calibrate/rig_camera.h"

namespace mogao::calibrate {
namespace {

namespace fs = std::filesystem;
constexpr double kScale = 0.25;
const fs::path kStandard = MOGAO_SOURCE_DIR "/rigs/standard.toml";

std::string slurp(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

class OnSiteJobTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("mogao-calibrate-" + std::to_string(::getpid()) + "-" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
        job_.site = kStandard;
        job_.scale = kScale;
        job_.out = dir_ / "out";
        job_.content = {480, 270};
        job_.colour = false;
        job_.timing = {0, 0};  // the simulation has no latency to wait for
        job_.transfer = CameraTransfer::linear;
        rig_ = autocal::scaled_rig(rig::load_rig(kStandard), kScale, kScale);
        HeadlessOptions h;
        for (const auto& p : rig_.projectors) h.outputs.push_back(p.resolution);
        auto b = HeadlessOutputBackend::create(std::move(h));
        if (!b) return mogao::testing::skip_or_fail_without_egl(b.error().message);
        backend_ = std::move(b.value());
    }
    void TearDown() override { fs::remove_all(dir_); }
    // A last good calibration already in the output folder: a refusal must leave it as it is.
    void plant_last_good() {
        fs::create_directories(job_.out);
        std::ofstream(job_.out / "calibration.mpcdi") << "last good";
    }
    void expect_last_good_untouched() {
        EXPECT_EQ(slurp(job_.out / "calibration.mpcdi"), "last good");
        EXPECT_FALSE(fs::exists(job_.out / "report.json"));
        EXPECT_FALSE(fs::exists(job_.out / "calibration.models.json"));
        EXPECT_FALSE(fs::exists(job_.out / "calibration.mpcdi.last-good"));
    }

    fs::path dir_;
    OnSiteJob job_;
    rig::VirtualRig rig_;
    std::unique_ptr<HeadlessOutputBackend> backend_;
};

TEST_F(OnSiteJobTest, HeadlessOutputsFilmedThroughTheRigCalibrateAsWellAsTheRigItself) {
    // Cables swapped: rig projector k (left to right) is lit by output cables[k].
    const std::vector<std::size_t> cables{2, 0, 1};
    RigCamera camera(*backend_, rig_, cables);
    plant_last_good();
    const nlohmann::json before = {{"connectors",
                                    {{{"projector", "proj0"}, {"connector", "headless-0"}},
                                     {{"projector", "proj1"}, {"connector", "headless-1"}},
                                     {{"projector", "proj2"}, {"connector", "headless-2"}}}}};
    std::ofstream(job_.out / "report.json") << before.dump();
    int reports = 0;
    const nlohmann::json r = run_on_site(job_, *backend_, camera, [&](const CaptureProgress& p) {
        ++reports;
        EXPECT_LE(p.done, p.expected);
        EXPECT_GE(p.seconds_left, 0.0);
    });
    // Identified by what the camera sees, not by enumeration order.
    ASSERT_EQ(r["connectors"].size(), 3u);
    for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_EQ(r["connectors"][k]["connector"], "headless-" + std::to_string(cables[k])) << k;
    }
    EXPECT_EQ(r["captures"].get<int>(), reports);
    EXPECT_LE(r["captures"].get<int>(), r["budget"]["total"].get<int>());
    EXPECT_EQ(static_cast<int>(camera.frames()), reports);  // one frame per image (no frames dropped here)
    // Every output was left black.
    for (std::size_t i = 0; i < 3; ++i) {
        for (const std::uint8_t v : backend_->last_frame(i).pixels) ASSERT_EQ(v, 0);
    }
    // The MPCDI as the kiosk reads it, against the rig's ground truth, next to autocal's own rig source.
    const ScreenCalibration hw = to_screen_calibration(read_mpcdi(job_.out / "calibration.mpcdi"));
    const autocal::GeometryError g = autocal::measure_geometry(rig_, hw, 3);
    autocal::RigPatternSource rig_source(rig_);
    // The same camera noise frames as the on-site run, whose first 2 + N images identify the outputs.
    for (int i = 0; i < 5; ++i) (void)rig_source.show(std::vector<cv::Mat>(3));
    const autocal::AutocalResult ref =
        autocal::calibrate(rig_source, autocal::prior_from_rig(rig_), job_.content, job_.options);
    MpcdiExportOptions mo;  // through the same MPCDI round trip as the on-site files
    mo.alpha_bit_depth = job_.alpha_bits;
    const autocal::GeometryError want =
        autocal::measure_geometry(rig_, to_screen_calibration(to_mpcdi(ref.calibration, mo)), 3);
    std::printf(
        "on-site path (headless + rig camera, 1/4 scale): geometry mean %.3f p95 %.3f px; --rig: mean %.3f "
        "p95 %.3f px (projector pixels at 1/4 scale)\n",
        g.mean_px, g.p95_px, want.mean_px, want.p95_px);
    EXPECT_GT(g.samples, 5000);
    EXPECT_LE(g.missing, g.samples / 100);
    // The patterns reach the rig exactly through outputs, renderer and camera frames: the same result.
    EXPECT_NEAR(g.mean_px, want.mean_px, 0.01);
    EXPECT_NEAR(g.p95_px, want.p95_px, 0.02);
    EXPECT_LE(g.mean_px, 0.3);  // the geometry goal's bound (full-scale pixels; at 1/4 scale it is 4x as strict)
    // The on-site accuracy figure, from the camera images alone, against the ground truth measured here.
    const nlohmann::json& check = r["self_check"];
    std::printf("self-check (no ground truth): mean %.3f p95 %.3f px, %d of %d marks\n", check["mean_px"].get<double>(),
                check["p95_px"].get<double>(), check["marks_found"].get<int>(), check["marks_shown"].get<int>());
    EXPECT_NEAR(check["mean_px"].get<double>(), g.mean_px, 0.2);
    EXPECT_GE(check["marks_found"].get<int>(), 48);
    // The told heights' check reaches the technician's report as the rig route computes it.
    const nlohmann::json& heights = r["screen"]["heights_check"];
    ASSERT_TRUE(heights["tried"].get<bool>()) << r["screen"].dump();
    ASSERT_TRUE(ref.report.heights.tried);
    EXPECT_NEAR(heights["shift_mean_px"].get<double>(), ref.report.heights.shift_mean_px, 0.01);
    EXPECT_NEAR(heights["fitted_top_m"].get<double>(), ref.report.heights.fitted_top_m, 1e-4);
    EXPECT_LE(heights["shift_mean_px"].get<double>(), heights["gate_px"].get<double>());
    EXPECT_DOUBLE_EQ(heights["gate_px"].get<double>(), job_.options.max_heights_shift_px);
    EXPECT_DOUBLE_EQ(r["screen"]["top_m"].get<double>(), ref.screen.top_m);
    EXPECT_TRUE(fs::exists(job_.out / "calibration.models.json"));
    EXPECT_FALSE(cv::imread((job_.out / "camera-white.png").string()).empty());
    // The previous run's calibration is kept, and its cabling compared.
    EXPECT_EQ(slurp(job_.out / "calibration.mpcdi.last-good"), "last good");
    ASSERT_EQ(r["cabling_changes"].size(), 3u) << r["cabling_changes"].dump();
    EXPECT_NE(r["cabling_changes"][0].get<std::string>().find("'proj0' was on connector headless-0, is now on "
                                                              "headless-2"),
              std::string::npos)
        << r["cabling_changes"].dump();
}

TEST_F(OnSiteJobTest, CameraWhoseExposureIsNotLockedIsRefusedBeforeAnyPattern) {
    rig_.camera.auto_exposure = true;
    RigCamera camera(*backend_, rig_, {0, 1, 2});
    plant_last_good();
    try {
        (void)run_on_site(job_, *backend_, camera, nullptr);
        FAIL() << "an auto-exposure camera must be refused";
    } catch (const autocal::CalibrationRefused& e) {
        EXPECT_NE(std::string(e.what()).find("auto-exposure is not locked"), std::string::npos) << e.what();
    }
    for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(backend_->frame_count(i), 0u) << "output " << i << " lit";
    EXPECT_EQ(camera.frames(), 0u);
    expect_last_good_untouched();
}

TEST_F(OnSiteJobTest, CameraThatSeesNothingIsRefusedNamingTheProjector) {
    // A camera returning the same image whatever is shown: a recording of one frame, looped.
    const fs::path rec = dir_ / "recording";
    fs::create_directories(rec);
    const ImageSize cam = rig_.camera.resolution;
    ASSERT_TRUE(cv::imwrite((rec / "000000.png").string(), cv::Mat1b(cam.height, cam.width, uchar{90})));
    CameraSourceSpec spec;
    ASSERT_TRUE(parse_camera_source("replay:" + rec.string(), spec, nullptr));
    spec.loop = true;
    spec.replay_fps = 1000.0;
    auto camera = open_calibration_camera(spec);
    ASSERT_TRUE(camera) << camera.error().message;
    plant_last_good();
    try {
        (void)run_on_site(job_, *backend_, *camera.value(), nullptr);
        FAIL() << "a camera that sees nothing must be refused";
    } catch (const autocal::CalibrationRefused& e) {
        EXPECT_NE(std::string(e.what()).find("projector 0 'proj0' (connector headless-0): the camera sees nothing"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_GT(backend_->frame_count(0), 0u);  // the patterns were shown, and the wall is dark again
    for (std::size_t i = 0; i < 3; ++i) {
        for (const std::uint8_t v : backend_->last_frame(i).pixels) ASSERT_EQ(v, 0) << "output " << i;
    }
    expect_last_good_untouched();
}

TEST_F(OnSiteJobTest, CameraOfAnotherSizeIsAnErrorNamingBothSizes) {
    const fs::path rec = dir_ / "recording";
    fs::create_directories(rec);
    ASSERT_TRUE(cv::imwrite((rec / "000000.png").string(), cv::Mat1b(100, 100, uchar{90})));
    CameraSourceSpec spec;
    ASSERT_TRUE(parse_camera_source("replay:" + rec.string(), spec, nullptr));
    spec.loop = true;
    auto camera = open_calibration_camera(spec);
    ASSERT_TRUE(camera) << camera.error().message;
    plant_last_good();
    try {
        (void)run_on_site(job_, *backend_, *camera.value(), nullptr);
        FAIL() << "a camera of another size than the site file's must fail";
    } catch (const std::runtime_error& e) {
        const std::string cam =
            std::to_string(rig_.camera.resolution.width) + "x" + std::to_string(rig_.camera.resolution.height);
        EXPECT_NE(std::string(e.what()).find("delivers 100x100 frames, the calibration's camera is " + cam),
                  std::string::npos)
            << e.what();
    }
    expect_last_good_untouched();
}

// The install's files (write_calibration): the previous pair kept as *.last-good byte for byte, the
// new pair in place, readable and of one version, and no staging file or temporary left, also
// when an install cut short by a power cut left its staged files behind. (That a cut never leaves
// new models beside the old MPCDI is what image/test/qemu_powercut_test.py shows on ext4.)
TEST(WriteCalibrationTest, KeepsThePreviousPairAndLeavesNoStagingFiles) {
    const fs::path dir = fs::temp_directory_path() / ("mogao-write-calibration-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path mpcdi = dir / "screen.mpcdi";
    const rig::VirtualRig rig = autocal::scaled_rig(rig::load_rig(kStandard), kScale, kScale);
    const autocal::CalibrationPrior prior = autocal::prior_from_rig(rig);
    const autocal::CalibrationModels models{prior.screen, prior.camera, prior.projectors};
    IdealCalibrationParams ideal;
    ideal.output = prior.projectors[0].resolution;  // the rig's three projectors share one size
    ideal.content = {96, 54};
    const ScreenCalibration calibration = make_ideal_calibration(ideal);
    std::ofstream(mpcdi) << "old mpcdi";
    std::ofstream(dir / "screen.models.json") << "old models";
    std::ofstream(dir / "screen.mpcdi.staged") << "half";  // what a cut install left
    OnSiteJob job;
    job.colour = false;
    write_calibration(mpcdi, models, calibration, job);
    EXPECT_EQ(slurp(dir / "screen.mpcdi.last-good"), "old mpcdi");
    EXPECT_EQ(slurp(dir / "screen.models.json.last-good"), "old models");
    EXPECT_EQ(to_screen_calibration(read_mpcdi(mpcdi)).projectors.size(), 3u);
    autocal::check_models_match(autocal::read_models(dir / "screen.models.json"), calibration, "models");
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"screen.models.json", "screen.models.json.last-good", "screen.mpcdi",
                                               "screen.mpcdi.last-good"}));
    fs::remove_all(dir);
}

}  // namespace
}  // namespace mogao::calibrate
