// SPDX-License-Identifier: Apache-2.0
// Self-recalibration wired into the kiosk (kiosk/live_calibration/selfcal_worker.h), end to end on real parts: a
// Kiosk on headless outputs (llvmpipe) showing the standard virtual rig's exact calibration (rig
// at half resolution), a SelfcalWorker at 2 Hz whose camera is the rig's simulated camera
// (appliance/rig CameraSimulator: the wall's calibration rendered through the TRUE projector poses),
// and the run-time calibration swap. A projector bumped by 1 degree must go drift_detected ->
// correcting -> calibrated, with the corrected calibration swapped onto the outputs (source
// "selfcal") and its ground-truth geometric error under 1 projector pixel; without a bump nothing
// may change. Hold and transition are 1 s each (as in appliance/selfcal's short scenarios).
#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <fstream>
#include <iostream>
#include <set>

#include <opencv2/core/utility.hpp>

#include "appliance/autocal/rig_bridge.h"
#include "appliance/rig/rig_file.h"
#include "appliance/selfcal/rig_simulation.h"
#include "common/jpeg_codec.h"
#include "common/srgb.h"
#include "drivers/egl/egl_test_support.h"
#include "drivers/headless/headless_output.h"
#include "kiosk/config/config_overrides.h"
#include "kiosk/live_calibration/selfcal_worker.h"
#include "kiosk/loop/kiosk.h"
#include "kiosk/loop/kiosk_setup.h"

#if defined(__SANITIZE_THREAD__)
// ThreadSanitizer cannot see the joins of OpenCV's parallel_for_ (TBB's workers, not instrumented):
// every later use of the loop body's stack or heap by the caller was reported as a race (the
// virtual rig's camera simulator). Under TSan OpenCV runs its loops in the calling thread; the
// kiosk's own threads, the self-calibration worker among them, are still checked.
[[maybe_unused]] static const bool kOpenCvSerialUnderTsan = (cv::setNumThreads(1), true);
#endif

namespace mogao {
namespace {

namespace fs = std::filesystem;

constexpr ImageSize kContent{960, 540};

// Linear grey -> sRGB RGB8 (IEC 61966-2-1), what the farm would send.
Rgb8Image srgb_of(const cv::Mat1f& grey) {
    Rgb8Image out({grey.cols, grey.rows});
    for (int y = 0; y < grey.rows; ++y) {
        for (int x = 0; x < grey.cols; ++x) {
            const double l = std::clamp(static_cast<double>(grey(y, x)), 0.0, 1.0);
            const double e = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
            const auto code = static_cast<std::uint8_t>(std::lround(e * 255.0));
            std::uint8_t* p = out.at(x, y);
            p[0] = p[1] = p[2] = code;
        }
    }
    return out;
}

// Ground truth for projector k alone (as appliance/selfcal's scenarios measure it): where its
// pixels land on the screen against where their content belongs, mean in its own pixels.
double projector_error_px(const rig::VirtualRig& truth, const ScreenCalibration& wall, std::size_t k) {
    rig::VirtualRig one = truth;
    one.projectors = {truth.projectors[k]};
    ScreenCalibration c;
    c.content = wall.content;
    c.projectors = {wall.projectors[k]};
    return autocal::measure_geometry(one, c, 8).mean_px;
}

struct NullLink {
    KioskLink port() {
        return {[](ViewRequest, std::string*) { return std::uint64_t{1}; }, [] { return LinkClientStats{}; }, [] {}};
    }
};

class SelfcalKioskTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("mogao-selfcal-kiosk-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "pki");
        for (const char* f : {"pki/ca.pem", "pki/a.pem", "pki/a.key"}) std::ofstream(dir_ / f) << "x";
        config_ = parse_kiosk_config(
            apply_config_overrides(
                kiosk_example_toml(),
                {R"(farm.endpoint="[::1]:7443")", R"(farm.ca="pki/ca.pem")", R"(farm.cert="pki/a.pem")",
                 R"(farm.key="pki/a.key")", "display.rate_hz=20", R"(outputs.backend="headless")",
                 R"(calibration.source="ideal")", R"(quality.content="960x540")", "navigation.path_frames=10",
                 R"(stats.status_file="status.json")"}),
            dir_ / "kiosk.toml");
        truth_ = autocal::scaled_rig(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml"), 0.5, 0.5);
        model_ = selfcal::models_of_rig(truth_);
        options_.hold_s = 1.0;
        options_.transition_s = 1.0;
        options_.build.warp_step_px = 4;
        wall_ = autocal::calibration_from_models(model_.projectors, model_.screen, kContent, options_.build);
        HeadlessOptions outputs;
        for (const auto& p : wall_.projectors) outputs.outputs.push_back(p.output);
        auto backend = HeadlessOutputBackend::create(outputs);
        if (!backend) {
            if (backend.code() == ENODEV) return mogao::testing::skip_or_fail_without_egl(backend.error().message);
            FAIL() << backend.error().message;
        }
        auto display = KioskDisplay::create(std::move(backend).value(), wall_, nullptr);
        ASSERT_TRUE(display) << display.error().message;
        display_.emplace(std::move(display).value());
        inbox_ = open_inbox();
        calibration_ = open_calibration_inbox();
        navigation_ = std::make_unique<KioskNavigation>(scripted_visitor(config_));
        auto signals = SignalFd::create({SIGUSR1});
        ASSERT_TRUE(signals) << signals.error().message;
        signals_.emplace(std::move(signals).value());
    }
    void TearDown() override {
        kiosk_.reset();
        worker_.reset();
        fs::remove_all(dir_);
    }

    // Starts the worker on a camera that sees the wall through `truth` (bumped or not) and the kiosk
    // showing one content frame (textured unless said).
    void start(const rig::VirtualRig& truth, selfcal::ContentKind kind = selfcal::ContentKind::textured) {
        auto sim = std::make_shared<rig::CameraSimulator>(truth);
        SelfcalWorker::Camera camera = [sim](const cv::Mat1f& content, const ScreenCalibration& wall,
                                             std::uint64_t frame) {
            std::vector<cv::Mat> signals;
            for (const ProjectorCalibration& pc : wall.projectors)
                signals.emplace_back(selfcal::projector_signal(pc, content));
            return sim->capture(signals, frame + 1);
        };
        worker_ = std::make_unique<SelfcalWorker>(selfcal::SelfCalibrator(model_, wall_, options_), std::move(camera),
                                                  *calibration_, 2.0);
        KioskParts parts{*display_, *inbox_, link_.port(), *navigation_, *signals_, notifier_, calibration_.get()};
        parts.selfcal = worker_.get();
        kiosk_.emplace(config_, std::move(parts), KioskRunOptions{});
        LinkFrame frame;
        frame.frame_id = frame.request_id = 1;
        frame.size = kContent;
        frame.jpeg = JpegEncoder().encode(srgb_of(selfcal::make_content(kind, 0.0, false, 7)), 95);
        inbox_->put(std::move(frame));
        inbox_->wait_decoded();
        kiosk_->on_frame();
        ASSERT_NE(kiosk_->current(), nullptr);
    }

    // Runs the loop's tick and calibration handlers until `steps` monitored frames are done, or
    // `until` holds; records every self-calibration state seen. A hang guard of 120 s stops it.
    template <typename Until>
    void run_loop(std::uint64_t steps, Until until) {
        const auto guard = std::chrono::steady_clock::now() + std::chrono::seconds(120);
        while (worker_->steps() < steps && !until() && std::chrono::steady_clock::now() < guard) {
            std::array<pollfd, 2> fds{pollfd{kiosk_->tick_fd(), POLLIN, 0}, pollfd{calibration_->fd(), POLLIN, 0}};
            ASSERT_GE(::poll(fds.data(), fds.size(), 1000), 0);
            if (fds[1].revents != 0) kiosk_->on_calibration();
            if (fds[0].revents != 0) kiosk_->on_tick();
            states_.insert(worker_->status().state);
        }
    }
    [[nodiscard]] nlohmann::json status_file() const {
        std::ifstream in(dir_ / "status.json");
        return nlohmann::json::parse(in);
    }

    fs::path dir_;
    KioskConfig config_;
    rig::VirtualRig truth_;
    selfcal::SystemModel model_;
    selfcal::SelfcalOptions options_;
    ScreenCalibration wall_;
    std::optional<KioskDisplay> display_;
    std::unique_ptr<FrameInbox> inbox_;
    std::unique_ptr<CalibrationInbox> calibration_;
    std::unique_ptr<KioskNavigation> navigation_;
    std::optional<SignalFd> signals_;
    ServiceNotifier notifier_;
    NullLink link_;
    std::unique_ptr<SelfcalWorker> worker_;
    std::optional<Kiosk> kiosk_;
    std::set<selfcal::SelfcalState> states_;
};

TEST_F(SelfcalKioskTest, AProjectorBumpedOneDegreeIsCorrectedAndSwappedOntoTheOutputs) {
    rig::VirtualRig bumped = truth_;
    bumped.projectors[1].pose.yaw_deg += 1.0;  // proj1 knocked: the wall's calibration no longer fits
    const double before_px = projector_error_px(bumped, display_->calibration(), 1);
    ASSERT_GT(before_px, 5.0) << "the bump must be visible in the ground truth";
    start(bumped);
    run_loop(60, [&] {
        return kiosk_->calibration_in_use().swaps > 0 && states_.count(selfcal::SelfcalState::correcting) > 0 &&
               worker_->status().state == selfcal::SelfcalState::calibrated;
    });
    EXPECT_TRUE(states_.count(selfcal::SelfcalState::drift_detected)) << worker_->status().text();
    EXPECT_TRUE(states_.count(selfcal::SelfcalState::correcting)) << worker_->status().text();
    EXPECT_EQ(worker_->status().state, selfcal::SelfcalState::calibrated) << worker_->status().text();
    EXPECT_GT(kiosk_->calibration_in_use().swaps, 0u);
    EXPECT_EQ(kiosk_->calibration_in_use().source, "selfcal");
    EXPECT_GE(worker_->corrections(), 1u) << "a correction began (blended in over several swaps)";
    // Let the last step of the transition reach the wall, then judge it against the rig's ground truth.
    run_loop(worker_->steps() + 1, [] { return false; });
    const double after_px = projector_error_px(bumped, display_->calibration(), 1);
    EXPECT_LT(after_px, 1.0) << "before " << before_px << " px";
    std::cout << "proj1 mean geometric error (ground truth, its pixels): " << before_px << " px after the bump, "
              << after_px << " px after " << kiosk_->calibration_in_use().swaps << " swaps, " << worker_->steps()
              << " monitored frames\n";
    const nlohmann::json status = status_file();
    EXPECT_EQ(status["selfcal"]["enabled"], true);
    EXPECT_EQ(status["calibration"]["source"], "selfcal");
}

TEST_F(SelfcalKioskTest, WithoutABumpNothingIsCorrected) {
    start(truth_);
    run_loop(8, [] { return false; });
    EXPECT_EQ(worker_->steps(), 8u);
    EXPECT_EQ(states_, std::set<selfcal::SelfcalState>{selfcal::SelfcalState::calibrated});
    EXPECT_EQ(kiosk_->calibration_in_use().swaps, 0u);
    EXPECT_EQ(kiosk_->calibration_in_use().source, "ideal");
    EXPECT_EQ(worker_->corrections(), 0u);
}

// [selfcal] pattern = true on a plain wall: the content gives no evidence, so the worker asks for the
// fallback's pattern pair, the kiosk draws +a P and -a P on the held frame (kiosk.cpp,
// update_pattern_overlay), the camera sees them through the bumped rig, and the bump is corrected
// from the pair's difference. Without the kiosk showing the pattern the worker would only wait.
TEST_F(SelfcalKioskTest, OnAPlainWallThePatternPairIsShownAndABumpedProjectorCorrected) {
    options_.pattern.enabled = true;
    rig::VirtualRig bumped = truth_;
    bumped.projectors[1].pose.yaw_deg += 1.0;
    const double before_px = projector_error_px(bumped, display_->calibration(), 1);
    start(bumped, selfcal::ContentKind::plain);
    const Rgb8Image plain = kiosk_->current()->image;
    run_loop(80, [&] {
        return kiosk_->calibration_in_use().swaps > 0 && states_.count(selfcal::SelfcalState::correcting) > 0 &&
               worker_->status().state == selfcal::SelfcalState::calibrated;
    });
    EXPECT_GT(worker_->pattern_pairs(), 0u) << worker_->status().text();
    EXPECT_TRUE(states_.count(selfcal::SelfcalState::correcting)) << worker_->status().text();
    EXPECT_EQ(worker_->status().state, selfcal::SelfcalState::calibrated) << worker_->status().text();
    EXPECT_EQ(kiosk_->calibration_in_use().source, "selfcal");
    run_loop(worker_->steps() + 1, [] { return false; });
    const double after_px = projector_error_px(bumped, display_->calibration(), 1);
    EXPECT_LT(after_px, 1.0) << "before " << before_px << " px";
    std::cout << "plain wall, pattern pairs: proj1 " << before_px << " px after the bump, " << after_px << " px after "
              << kiosk_->calibration_in_use().swaps << " swaps; " << worker_->pattern_pairs() << " of "
              << worker_->steps() << " monitored frames were pattern pairs\n";
    EXPECT_EQ(kiosk_->current()->image.pixels, plain.pixels);  // the content itself never carries the pattern
}

TEST(WithPattern, AddsTheSignedPatternToLinearLightAndClamps) {
    Rgb8Image content({4, 2}, 0);
    for (int x = 0; x < 4; ++x)
        for (int c = 0; c < 3; ++c) content.at(x, 0)[c] = content.at(x, 1)[c] = static_cast<std::uint8_t>(60 * x);
    cv::Mat1f pattern(2, 4, 0.0f);
    pattern(0, 1) = 0.02f;   // +a on a mid grey
    pattern(1, 1) = -0.02f;  // -a on the same grey
    pattern(0, 0) = -0.5f;   // clamped at black
    pattern(0, 3) = 1.0f;    // clamped at white
    const Rgb8Image out = with_pattern(content, pattern);
    const auto& decode = srgb8_decode_table();
    const auto code_of = [](double linear) {
        return static_cast<int>(std::lround(255.0 * srgb_encode(std::clamp(linear, 0.0, 1.0))));
    };
    EXPECT_EQ(out.at(1, 0)[0], code_of(decode[60] + 0.02));
    EXPECT_EQ(out.at(1, 1)[1], code_of(decode[60] - 0.02));
    EXPECT_EQ(out.at(0, 0)[2], 0);
    EXPECT_EQ(out.at(3, 0)[0], 255);
    EXPECT_EQ(out.at(2, 1)[0], 120);  // no pattern: untouched
    // The pair averages back to the content within rounding (complementary).
    cv::Mat1f negated;
    pattern.convertTo(negated, CV_32F, -1.0);
    const Rgb8Image minus = with_pattern(content, negated);
    EXPECT_NEAR((decode[out.at(1, 0)[0]] + decode[minus.at(1, 0)[0]]) / 2.0, decode[60], 2e-3);
}

}  // namespace
}  // namespace mogao
