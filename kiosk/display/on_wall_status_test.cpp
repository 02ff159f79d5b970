// SPDX-License-Identifier: Apache-2.0
// The state on the wall (kiosk/display/on_wall_status.h) through the Kiosk's loop handlers on real parts:
// headless outputs on surfaceless EGL (Mesa llvmpipe), the ideal 3-projector calibration, a real
// FrameInbox, timerfd and signalfd (SIGUSR2 raised for real). The one stand-in is the link (as in
// kiosk_test.cpp): a KioskLink that accepts every request and plays "connected". What is judged is
// each output's last frame, the image the headless PNGs are written from.
#include "kiosk/display/on_wall_status.h"

#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <fstream>

#include "common/jpeg_codec.h"
#include "drivers/egl/egl_test_support.h"
#include "drivers/headless/headless_output.h"
#include "kiosk/config/config_overrides.h"
#include "kiosk/loop/kiosk.h"
#include "kiosk/loop/kiosk_setup.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;

constexpr ImageSize kContent{480, 270};

LinkFrame jpeg_frame(std::uint64_t request_id) {
    Rgb8Image content(kContent);
    for (int y = 0; y < kContent.height; ++y) {
        for (int x = 0; x < kContent.width; ++x) {
            std::uint8_t* p = content.at(x, y);
            p[0] = p[1] = p[2] = static_cast<std::uint8_t>(110 + (x / 8 + y / 8) % 2 * 40);  // a checkerboard
        }
    }
    LinkFrame frame;
    frame.frame_id = frame.request_id = request_id;
    frame.size = kContent;
    frame.jpeg = JpegEncoder().encode(content, 95);
    return frame;
}

// Output pixels (all channels) that differ by more than 40 codes: text and its box, not JPEG noise.
std::size_t changed(const std::vector<Rgb8Image>& a, const std::vector<Rgb8Image>& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        for (std::size_t k = 0; k < a[i].pixels.size(); ++k) n += std::abs(a[i].pixels[k] - b[i].pixels[k]) > 40;
    }
    return n;
}

class OnWallStatusTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("mogao-on-wall-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "pki");
        for (const char* f : {"pki/ca.pem", "pki/a.pem", "pki/a.key"}) std::ofstream(dir_ / f) << "x";
        auto signals = SignalFd::create({SIGUSR2});
        ASSERT_TRUE(signals) << signals.error().message;
        signals_.emplace(std::move(signals).value());
    }
    void TearDown() override {
        kiosk_.reset();
        fs::remove_all(dir_);
    }

    // The kiosk with `overrides` of the example, showing its first farm frame.
    void start(const std::vector<std::string>& overrides, std::vector<StartFallback> fallbacks = {}) {
        config_ = config_with(overrides);
        start_with_config(std::move(fallbacks));
    }
    // The example with the fixture's overrides and `overrides`, parsed (throws KioskConfigError).
    [[nodiscard]] KioskConfig config_with(const std::vector<std::string>& overrides) const {
        std::vector<std::string> all = {R"(farm.endpoint="[::1]:7443")",
                                        R"(farm.ca="pki/ca.pem")",
                                        R"(farm.cert="pki/a.pem")",
                                        R"(farm.key="pki/a.key")",
                                        "display.rate_hz=100",
                                        R"(outputs.backend="headless")",
                                        R"(calibration.source="ideal")",
                                        R"(calibration.output="192x144")",
                                        R"(quality.content="480x270")",
                                        "navigation.path_frames=10",
                                        "stats.file="};
        all.insert(all.end(), overrides.begin(), overrides.end());
        return parse_kiosk_config(apply_config_overrides(kiosk_example_toml(), all), dir_ / "kiosk.toml");
    }
    void start_with_config(std::vector<StartFallback> fallbacks) {
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
        navigation_ = std::make_unique<KioskNavigation>(scripted_visitor(config_));
        KioskLink link{[](ViewRequest, std::string*) { return std::uint64_t{1}; },
                       [this] {
                           LinkClientStats s;
                           s.connected = true;
                           s.certificates = link_certificates_;
                           return s;
                       },
                       [] {}};
        KioskRunOptions run;
        run.fallbacks = std::move(fallbacks);
        kiosk_.emplace(config_, KioskParts{*display_, *inbox_, link, *navigation_, *signals_, notifier_},
                       std::move(run));
        deliver(1);
    }
    void deliver(std::uint64_t id) {
        inbox_->put(jpeg_frame(id));
        inbox_->wait_decoded();
        kiosk_->on_frame();
    }
    void usr2() {
        ASSERT_EQ(::raise(SIGUSR2), 0);  // this thread: it blocks the signal, llvmpipe's threads may not
        kiosk_->on_signal();
    }
    // Runs display ticks until `done` (a hang guard of 20 s stops it; nothing is timed).
    template <typename Done>
    void ticks_until(Done done) {
        const auto guard = std::chrono::steady_clock::now() + std::chrono::seconds(20);
        while (!done() && std::chrono::steady_clock::now() < guard) {
            pollfd p{kiosk_->tick_fd(), POLLIN, 0};
            ASSERT_EQ(::poll(&p, 1, 1000), 1);
            kiosk_->on_tick();
        }
    }
    [[nodiscard]] std::vector<Rgb8Image> outputs() const {
        std::vector<Rgb8Image> out;
        for (std::size_t i = 0; i < headless_->outputs().size(); ++i) out.push_back(headless_->last_frame(i));
        return out;
    }

    fs::path dir_;
    KioskConfig config_;
    HeadlessOutputBackend* headless_ = nullptr;
    std::optional<KioskDisplay> display_;
    std::unique_ptr<FrameInbox> inbox_;
    std::unique_ptr<KioskNavigation> navigation_;
    std::optional<SignalFd> signals_;
    ServiceNotifier notifier_;
    std::optional<Kiosk> kiosk_;
    std::vector<CertificateExpiry> link_certificates_;  // what the stand-in link reports holding
};

TEST_F(OnWallStatusTest, Sigusr2TogglesThePanelOnEveryOutput) {
    start({});  // on_wall = "on_demand" (the example's)
    if (!kiosk_) return;
    const std::vector<Rgb8Image> picture = outputs();
    EXPECT_TRUE(kiosk_->on_wall().empty());
    usr2();
    ASSERT_FALSE(kiosk_->on_wall().empty());
    EXPECT_EQ(kiosk_->on_wall()[0], "SELFCAL OFF");
    const std::vector<Rgb8Image> panel = outputs();
    for (std::size_t i = 0; i < panel.size(); ++i) {
        EXPECT_GT(changed({picture[i]}, {panel[i]}), 200u) << "output " << i << " shows no panel";
    }
    EXPECT_EQ(display_->frames_on_screen(), 1u) << "the panel is not a new farm frame";
    usr2();
    EXPECT_TRUE(kiosk_->on_wall().empty());
    EXPECT_EQ(changed(picture, outputs()), 0u) << "the panel was taken off";
}

TEST_F(OnWallStatusTest, OffNeverShowsItAndAlwaysShowsItFromTheFirstFrame) {
    start({R"(status.on_wall="off")"});
    if (!kiosk_) return;
    const std::vector<Rgb8Image> picture = outputs();
    usr2();
    EXPECT_TRUE(kiosk_->on_wall().empty());
    EXPECT_EQ(changed(picture, outputs()), 0u);
    kiosk_.reset();
    display_.reset();
    start({R"(status.on_wall="always")"});
    if (!kiosk_) return;
    EXPECT_FALSE(kiosk_->on_wall().empty());
    EXPECT_GT(changed(picture, outputs()), 600u);
}

TEST_F(OnWallStatusTest, TheTriggerFileShowsThePanelWhileItExists) {
    start({R"(status.trigger_file="show-status")"});
    if (!kiosk_) return;
    const std::vector<Rgb8Image> picture = outputs();
    std::ofstream(dir_ / "show-status") << "";
    ticks_until([&] { return !kiosk_->on_wall().empty(); });
    EXPECT_GT(changed(picture, outputs()), 600u);
    fs::remove(dir_ / "show-status");
    ticks_until([&] { return kiosk_->on_wall().empty(); });
    EXPECT_EQ(changed(picture, outputs()), 0u);
}

TEST_F(OnWallStatusTest, AFarmLostIndicatorAppearsOverTheHeldFrameAndGoesWithTheNextFrame) {
    start({"status.farm_lost_after_s=0.3"});
    if (!kiosk_) return;
    const std::vector<Rgb8Image> picture = outputs();
    EXPECT_TRUE(kiosk_->on_wall().empty());
    ticks_until([&] { return !kiosk_->on_wall().empty(); });  // no frame for 0.3 s
    ASSERT_EQ(kiosk_->on_wall().size(), 1u);
    EXPECT_EQ(kiosk_->on_wall()[0].rfind("FARM LOST ", 0), 0u) << kiosk_->on_wall()[0];
    const std::size_t marked = changed(picture, outputs());
    EXPECT_GT(marked, 100u);
    EXPECT_EQ(kiosk_->current()->request_id, 1u) << "the last frame is held";
    deliver(2);  // the farm is back
    EXPECT_TRUE(kiosk_->on_wall().empty());
    EXPECT_EQ(changed(picture, outputs()), 0u) << "the indicator went away with the new frame";
}

TEST_F(OnWallStatusTest, AStartOnALastGoodFileSaysSoOnTheWallAndInTheStatus) {
    start({}, {{"CALIBRATION ERROR - LAST GOOD IN USE", "screen.mpcdi: bad; running on screen.mpcdi.last-loaded"}});
    if (!kiosk_) return;
    ASSERT_EQ(kiosk_->on_wall(), std::vector<std::string>{"CALIBRATION ERROR - LAST GOOD IN USE"});
    const nlohmann::json status = kiosk_status_json(kiosk_->status("showing"));
    EXPECT_EQ(status["fallbacks"][0], "screen.mpcdi: bad; running on screen.mpcdi.last-loaded");
    EXPECT_EQ(status["on_wall"][0], "CALIBRATION ERROR - LAST GOOD IN USE");
}

// The link's certificates reach the status file and the panel: the appliance's expires in 29 days
// (now by the real clock: the margins are hours), the CA's in years.
TEST_F(OnWallStatusTest, ACertificateNearItsEndIsOnThePanelAndInTheStatusFile) {
    const std::int64_t now_s = realtime_ns() / 1'000'000'000;
    link_certificates_ = {{"ca", "mogao farm CA", now_s + 3000 * 86'400},
                          {"appliance", "museum-1", now_s + 29 * 86'400 + 3600}};
    start({R"(status.on_wall="always")"});
    if (!kiosk_) return;
    const auto& wall = kiosk_->on_wall();
    EXPECT_NE(std::find(wall.begin(), wall.end(), "APPLIANCE CERT EXPIRES IN 29 DAYS"), wall.end());
    const nlohmann::json status = kiosk_status_json(kiosk_->status("showing"));
    ASSERT_EQ(status["certificates"].size(), 2u);
    EXPECT_EQ(status["certificates"][1]["name"], "museum-1");
    EXPECT_EQ(status["certificates"][1]["not_after_s"], link_certificates_[1].not_after_s);
    EXPECT_EQ(status["certificates"][1]["days_left"], 29);
    EXPECT_EQ(status["certificates"][1]["expires_soon"], true);
    EXPECT_EQ(status["certificates"][0]["expires_soon"], false);
}

// [status].certificate_warning_days sets the period; a value outside [0, 3650] is refused by name.
TEST_F(OnWallStatusTest, TheWarningPeriodIsConfigurable) {
    const std::int64_t now_s = realtime_ns() / 1'000'000'000;
    link_certificates_ = {{"appliance", "museum-1", now_s + 29 * 86'400 + 3600}};
    start({R"(status.on_wall="always")", "status.certificate_warning_days=28"});
    if (!kiosk_) return;
    EXPECT_EQ(kiosk_->on_wall().back(), "CERTIFICATES OK - 29 DAYS LEFT");
    EXPECT_EQ(kiosk_status_json(kiosk_->status("showing"))["certificates"][0]["expires_soon"], false);
    try {
        static_cast<void>(config_with({"status.certificate_warning_days=-1"}));
        ADD_FAILURE() << "a negative warning period was accepted";
    } catch (const KioskConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("[status].certificate_warning_days"), std::string::npos) << e.what();
    }
}

// The warning period on an injected clock (KioskStatus::written_ns): shown at 29 days, not at 31.
TEST(OnWallStatusLines, WarnOfACertificateThirtyDaysBeforeItExpires) {
    constexpr std::int64_t kNow = 1'800'000'000, kDay = 86'400;
    KioskStatus s;
    s.written_ns = kNow * 1'000'000'000;
    s.certificates = {{"ca", "mogao farm CA", kNow + 3000 * kDay}, {"appliance", "museum-1", kNow + 31 * kDay}};
    std::vector<std::string> lines = status_panel_lines(s);
    ASSERT_EQ(lines.size(), 5u);
    EXPECT_EQ(lines[4], "CERTIFICATES OK - 31 DAYS LEFT");
    s.certificates[1].not_after_s = kNow + 29 * kDay + 3600;
    lines = status_panel_lines(s);
    ASSERT_EQ(lines.size(), 5u);
    EXPECT_EQ(lines[4], "APPLIANCE CERT EXPIRES IN 29 DAYS");
    s.certificates[0].not_after_s = kNow - 3 * kDay;
    lines = status_panel_lines(s);
    ASSERT_EQ(lines.size(), 6u);
    EXPECT_EQ(lines[4], "FARM CA CERT EXPIRED 3 DAYS AGO");
    s.certificate_warning_days = 0;  // [status].certificate_warning_days = 0: no warning, but expired is said
    lines = status_panel_lines(s);
    ASSERT_EQ(lines.size(), 5u);
    EXPECT_EQ(lines[4], "FARM CA CERT EXPIRED 3 DAYS AGO");
    s.certificate_warning_days = 45;  // configurable: 31 days is within 45
    s.certificates = {{"appliance", "museum-1", kNow + 31 * kDay}};
    EXPECT_EQ(status_panel_lines(s).back(), "APPLIANCE CERT EXPIRES IN 31 DAYS");
    for (const auto& l : status_panel_lines(s)) EXPECT_LE(l.size(), 36u);
}

TEST(OnWallStatusLines, NameTheSelfcalStateTheFarmAndTheLastCalibrationError) {
    KioskStatus s;
    s.endpoint = "[2001:db8::5]:7443";
    s.connected = false;
    s.calibration.source = "/etc/mogao/screen.mpcdi";
    s.calibration.swaps = 2;
    s.calibration.last_error = "read_mpcdi 'x': region proj1: bad (alpha) map";
    selfcal::SelfcalStatus sc;
    sc.state = selfcal::SelfcalState::cannot_correct;
    s.selfcal = sc;
    const std::vector<std::string> lines = status_panel_lines(s);
    ASSERT_EQ(lines.size(), 4u);
    EXPECT_EQ(lines[0], "SELFCAL CANNOT CORRECT - RECALIBRATE");
    EXPECT_EQ(lines[1], "FARM DOWN [2001:DB8::5]:7443");
    EXPECT_EQ(lines[2], "CALIBRATION SCREEN.MPCDI - 2 SWAPS");
    EXPECT_EQ(lines[3], "LAST ERROR: READ_MPCDI  X : REGIO...");
    for (const auto& l : lines) EXPECT_LE(l.size(), 36u);
    s.selfcal->state = selfcal::SelfcalState::drift_detected;
    s.selfcal->projectors = {{"proj0", 100, true, 0.2, 0.0, 0.0}, {"proj1", 100, true, 3.25, 0.0, 0.0}};
    EXPECT_EQ(status_panel_lines(s)[0], "SELFCAL DRIFT DETECTED - 3.25 PX");
    s.selfcal->waiting = true;
    s.selfcal->reason = "too few features";
    EXPECT_EQ(status_panel_lines(s)[0], "SELFCAL WAITING - TOO FEW FEATURES");
    EXPECT_EQ(farm_lost_line(12.7), "FARM LOST 12 S - LAST FRAME");
}

}  // namespace
}  // namespace mogao
