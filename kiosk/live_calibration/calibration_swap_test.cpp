// SPDX-License-Identifier: Apache-2.0
// The run-time calibration swap end to end on real parts (docs/kiosk.md, "Calibration swap"): a
// Kiosk on headless outputs (surfaceless EGL, Mesa llvmpipe) started with an MPCDI file that a
// CalibrationWatcher (inotify) watches. Replacing the file with another calibration changes what
// every output presents to what the CPU reference compositor (appliance/warp/composite.h,
// render_output) computes for the new calibration; a corrupt file or one of another layout leaves
// the outputs as they were, logs an error naming the file, and is shown in CalibrationInUse.
#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <fstream>

#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/calibration/mpcdi_writer.h"
#include "appliance/warp/composite.h"
#include "appliance/warp/ideal_calibration.h"
#include "common/file_io.h"
#include "common/jpeg_codec.h"
#include "drivers/egl/egl_test_support.h"
#include "drivers/headless/headless_output.h"
#include "kiosk/config/config_overrides.h"
#include "kiosk/live_calibration/screen_calibration_source.h"
#include "kiosk/loop/kiosk.h"
#include "kiosk/loop/kiosk_setup.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;

constexpr ImageSize kContent{160, 90};
constexpr ImageSize kOutput{96, 72};
// GL (texelFetch + bilinear in the shader, 8-bit target) against the CPU reference in double:
// rounding and float precision only. drivers/egl's own test holds its draw to 2 codes of its CPU
// reference; the warp/blend upload paths add float-vs-double sampling differences.
constexpr int kToleranceCodes = 3;

ScreenCalibration ideal(double overlap, double gamma) {
    IdealCalibrationParams params;
    params.projectors = 3;
    params.overlap = overlap;
    params.output = kOutput;
    params.content = kContent;
    params.gamma = gamma;
    return make_ideal_calibration(params);
}

// A content frame with structure in both directions, so that a different warp shows.
LinkFrame gradient_frame(std::uint64_t request_id) {
    Rgb8Image content(kContent);
    for (int y = 0; y < kContent.height; ++y) {
        for (int x = 0; x < kContent.width; ++x) {
            std::uint8_t* px = content.at(x, y);
            px[0] = static_cast<std::uint8_t>(x * 255 / (kContent.width - 1));
            px[1] = static_cast<std::uint8_t>(y * 255 / (kContent.height - 1));
            px[2] = static_cast<std::uint8_t>((x / 16 + y / 16) % 2 == 0 ? 40 : 220);
        }
    }
    LinkFrame frame;
    frame.frame_id = request_id;
    frame.request_id = request_id;
    frame.size = kContent;
    frame.jpeg = JpegEncoder().encode(content, 95);
    return frame;
}

// IEC 61966-2-1 decoding, as the renderer's GL_SRGB8 texture does.
RgbFloatImage linear_of(const Rgb8Image& srgb) {
    RgbFloatImage out(srgb.size);
    for (std::size_t i = 0; i < srgb.pixels.size(); ++i) {
        const double c = srgb.pixels[i] / 255.0;
        out.pixels[i] = static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return out;
}

// Largest difference in codes between a presented output and the reference signal.
int max_code_diff(const Rgb8Image& presented, const RgbFloatImage& reference) {
    int worst = 0;
    for (std::size_t i = 0; i < presented.pixels.size(); ++i) {
        const int want = static_cast<int>(std::lround(std::clamp(reference.pixels[i], 0.0f, 1.0f) * 255.0f));
        worst = std::max(worst, std::abs(presented.pixels[i] - want));
    }
    return worst;
}

struct NullLink {
    KioskLink port() {
        return {[](ViewRequest, std::string*) { return std::uint64_t{1}; }, [] { return LinkClientStats{}; }, [] {}};
    }
};

class CalibrationSwapTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("mogao-calibration-swap-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "pki");
        for (const char* f : {"pki/ca.pem", "pki/a.pem", "pki/a.key"}) std::ofstream(dir_ / f) << "x";
        write_mpcdi(dir_ / "screen.mpcdi", to_mpcdi(ideal(0.15, 2.2)));
        config_ = parse_kiosk_config(
            apply_config_overrides(
                kiosk_example_toml(),
                {R"(farm.endpoint="[::1]:7443")", R"(farm.ca="pki/ca.pem")", R"(farm.cert="pki/a.pem")",
                 R"(farm.key="pki/a.key")", "display.rate_hz=240", R"(outputs.backend="headless")",
                 R"(calibration.source="screen.mpcdi")", R"(quality.content="160x90")", "navigation.path_frames=10",
                 R"(stats.status_file="status.json")", R"(stats.metrics_file="kiosk.prom")"}),
            dir_ / "kiosk.toml");
        const ScreenCalibration screen = load_calibration(config_);
        HeadlessOptions options;
        for (const auto& p : screen.projectors) options.outputs.push_back(p.output);
        auto backend = HeadlessOutputBackend::create(options);
        if (!backend) {
            if (backend.code() == ENODEV) return mogao::testing::skip_or_fail_without_egl(backend.error().message);
            FAIL() << backend.error().message;
        }
        headless_ = backend->get();
        auto display = KioskDisplay::create(std::move(backend).value(), screen, nullptr);
        ASSERT_TRUE(display) << display.error().message;
        display_.emplace(std::move(display).value());
        inbox_ = open_inbox();
        calibration_ = open_calibration_inbox();
        watcher_ = watch_calibration(config_, *calibration_);
        ASSERT_NE(watcher_, nullptr);
        navigation_ = std::make_unique<KioskNavigation>(scripted_visitor(config_));
        auto signals = SignalFd::create({SIGUSR1});
        ASSERT_TRUE(signals) << signals.error().message;
        signals_.emplace(std::move(signals).value());
        kiosk_.emplace(
            config_,
            KioskParts{*display_, *inbox_, link_.port(), *navigation_, *signals_, notifier_, calibration_.get()},
            KioskRunOptions{});
        inbox_->put(gradient_frame(1));
        inbox_->wait_decoded();
        kiosk_->on_frame();
        ASSERT_NE(kiosk_->current(), nullptr);
        log_ = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(64);
        spdlog::default_logger()->sinks().push_back(log_);
    }
    void TearDown() override {
        if (log_) spdlog::default_logger()->sinks().pop_back();
        kiosk_.reset();
        watcher_.reset();
        fs::remove_all(dir_);
    }

    // Waits (at most a minute: a hang guard, not a timing assertion) for the watcher's update, then
    // runs the loop's handler.
    void take_update() {
        pollfd p{calibration_->fd(), POLLIN, 0};
        ASSERT_EQ(::poll(&p, 1, 60'000), 1) << "the watcher reported no change of " << config_.calibration.mpcdi;
        kiosk_->on_calibration();
    }
    [[nodiscard]] std::vector<Rgb8Image> outputs() const {
        std::vector<Rgb8Image> out;
        for (std::size_t i = 0; i < headless_->outputs().size(); ++i) out.push_back(headless_->last_frame(i));
        return out;
    }
    [[nodiscard]] nlohmann::json status_file() const {
        std::ifstream in(dir_ / "status.json");
        return nlohmann::json::parse(in);
    }
    [[nodiscard]] std::string logged() const {
        std::string all;
        for (const auto& line : log_->last_formatted()) all += line;
        return all;
    }

    fs::path dir_;
    KioskConfig config_;
    HeadlessOutputBackend* headless_ = nullptr;
    std::optional<KioskDisplay> display_;
    std::unique_ptr<FrameInbox> inbox_;
    std::unique_ptr<CalibrationInbox> calibration_;
    std::unique_ptr<CalibrationWatcher> watcher_;
    std::unique_ptr<KioskNavigation> navigation_;
    std::optional<SignalFd> signals_;
    ServiceNotifier notifier_;
    NullLink link_;
    std::optional<Kiosk> kiosk_;
    std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> log_;
};

TEST_F(CalibrationSwapTest, AReplacedMpcdiFileIsSwappedInAndMatchesTheCpuReference) {
    const fs::path file = config_.calibration.mpcdi;
    write_mpcdi(file, to_mpcdi(ideal(0.35, 1.8)));  // wider overlaps, another response: every output changes
    // The reference is what the file holds (alpha maps quantised to 8 bits), read independently.
    const ScreenCalibration want = load_screen_calibration(config_.calibration, kContent, nullptr);
    const RgbFloatImage content = linear_of(kiosk_->current()->image);
    const std::vector<Rgb8Image> before = outputs();
    for (std::size_t i = 0; i < before.size(); ++i) {
        EXPECT_GT(max_code_diff(before[i], render_output(want.projectors[i], content)), 20)
            << "output " << i << " already matches the new calibration: the test could not fail";
    }
    take_update();
    EXPECT_EQ(kiosk_->calibration_in_use().swaps, 1u);
    EXPECT_EQ(kiosk_->calibration_in_use().source, file.string());
    EXPECT_TRUE(kiosk_->calibration_in_use().last_error.empty());
    const nlohmann::json status = status_file();  // rewritten at the swap
    EXPECT_EQ(status["calibration"]["source"], file.string());
    EXPECT_EQ(status["calibration"]["swaps"], 1);
    EXPECT_EQ(status["frames_shown"], 1);
    EXPECT_EQ(status["selfcal"]["enabled"], false);
    // The metrics file is rewritten with it (kiosk_metrics.h).
    std::ifstream prom(dir_ / "kiosk.prom");
    const std::string metrics((std::istreambuf_iterator<char>(prom)), std::istreambuf_iterator<char>());
    EXPECT_NE(metrics.find("\nmogao_kiosk_calibration_swaps_total{source=\"file\"} 1\n"), std::string::npos) << metrics;
    EXPECT_NE(metrics.find("\nmogao_kiosk_frames_shown_total 1\n"), std::string::npos) << metrics;
    EXPECT_NE(metrics.find("\nmogao_kiosk_up 1\n"), std::string::npos) << metrics;
    const std::vector<Rgb8Image> after = outputs();
    ASSERT_EQ(after.size(), want.projectors.size());
    for (std::size_t i = 0; i < after.size(); ++i) {
        EXPECT_LE(max_code_diff(after[i], render_output(want.projectors[i], content)), kToleranceCodes)
            << "output " << i << " vs the CPU reference compositor";
    }
}

TEST_F(CalibrationSwapTest, ACorruptFileKeepsTheLastGoodCalibrationAndLogsTheFile) {
    const fs::path file = config_.calibration.mpcdi;
    const std::vector<Rgb8Image> before = outputs();
    const std::string garbage = "PK\x03\x04 this is not an MPCDI archive";
    write_file_atomically(file, std::span(reinterpret_cast<const std::uint8_t*>(garbage.data()), garbage.size()));
    take_update();
    display_->repaint();  // whatever is on the wall now is drawn once more
    const std::vector<Rgb8Image> after = outputs();
    for (std::size_t i = 0; i < after.size(); ++i) EXPECT_EQ(after[i].pixels, before[i].pixels) << "output " << i;
    const CalibrationInUse& in_use = kiosk_->calibration_in_use();
    EXPECT_EQ(in_use.swaps, 0u);
    EXPECT_EQ(in_use.refused, 1u);
    EXPECT_NE(in_use.last_error.find(file.string()), std::string::npos) << in_use.last_error;
    EXPECT_NE(logged().find(file.string()), std::string::npos) << logged();
    EXPECT_NE(logged().find("keeping"), std::string::npos) << logged();
    const nlohmann::json status = status_file();
    EXPECT_EQ(status["calibration"]["refused"], 1);
    EXPECT_EQ(status["calibration"]["last_error"], in_use.last_error);
}

TEST_F(CalibrationSwapTest, ACalibrationOfAnotherLayoutIsRefusedNamingTheProjector) {
    IdealCalibrationParams params;
    params.projectors = 2;  // ids proj0, proj1: the third output's projector is missing
    params.output = kOutput;
    params.content = kContent;
    const std::vector<Rgb8Image> before = outputs();
    write_mpcdi(config_.calibration.mpcdi, to_mpcdi(make_ideal_calibration(params)));
    take_update();
    display_->repaint();
    const std::vector<Rgb8Image> after = outputs();
    for (std::size_t i = 0; i < after.size(); ++i) EXPECT_EQ(after[i].pixels, before[i].pixels) << "output " << i;
    EXPECT_EQ(kiosk_->calibration_in_use().refused, 1u);
    EXPECT_NE(kiosk_->calibration_in_use().last_error.find("restart"), std::string::npos)
        << kiosk_->calibration_in_use().last_error;
}

}  // namespace
}  // namespace mogao
