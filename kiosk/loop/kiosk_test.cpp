// SPDX-License-Identifier: Apache-2.0
// The Kiosk's loop handlers (kiosk/loop/kiosk.h), one at a time, on real parts: headless outputs on
// surfaceless EGL (Mesa llvmpipe), the ideal 3-projector calibration, a real FrameInbox (slot +
// eventfd), timerfd and signalfd, the scripted visitor, KioskStats, PoseLog and the configuration
// made from kiosk.example.toml with overrides. The one stand-in is the link: the real LinkClient
// needs a farm over gRPC + mutual TLS (the end-to-end tests in tests/kiosk/ run it), so here a
// recording KioskLink keeps the view requests the loop submits and plays the link's counters.
#include "kiosk/loop/kiosk.h"

#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <fstream>

#include "common/jpeg_codec.h"
#include "drivers/egl/egl_test_support.h"
#include "drivers/headless/headless_output.h"
#include "kiosk/config/config_overrides.h"
#include "kiosk/loop/kiosk_setup.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;

constexpr ImageSize kContent{160, 90};

// Records what the loop asks of the link.
struct RecordingLink {
    std::vector<ViewRequest> requests;
    LinkClientStats stats;
    bool stopped = false;
    KioskLink port() {
        return {[this](ViewRequest r, std::string*) {
                    requests.push_back(r);
                    return std::uint64_t{100} + requests.size();
                },
                [this] { return stats; }, [this] { stopped = true; }};
    }
};

LinkFrame jpeg_frame(std::uint64_t request_id, std::uint8_t base) {
    Rgb8Image content(kContent);
    for (std::size_t k = 0; k < content.pixels.size(); ++k) {
        content.pixels[k] = static_cast<std::uint8_t>(base + k % 7);
    }
    LinkFrame frame;
    frame.frame_id = request_id;
    frame.request_id = request_id;
    frame.size = kContent;
    frame.jpeg = JpegEncoder().encode(content, 90);
    return frame;
}

// Blocks until `fd` is readable (the timerfd's next expiration): no sleeping, no timing assumptions.
void wait_readable(int fd) {
    pollfd p{fd, POLLIN, 0};
    ASSERT_EQ(::poll(&p, 1, -1), 1);
}

// Stand-in for KMS outputs whose page-flip events stop arriving (a hung display driver, a link
// lost mid-flip). KMS cannot run on this build machine (no DRM device), so the real headless
// backend draws and presents, and this wrapper withholds the completion once `withhold` is set.
class FlipNeverCompletes final : public OutputBackend {
public:
    explicit FlipNeverCompletes(std::unique_ptr<OutputBackend> inner)
        : inner_(std::move(inner)), in_flight_(inner_->outputs().size(), false) {}
    const std::vector<OutputInfo>& outputs() const override { return inner_->outputs(); }
    ProjectorRenderer& renderer() override { return inner_->renderer(); }
    Status begin_frame(std::size_t i) override { return inner_->begin_frame(i); }
    Status present(std::size_t i) override {
        Status s = inner_->present(i);
        if (s && withhold) in_flight_.at(i) = true;
        return s;
    }
    bool ready(std::size_t i) const override { return !in_flight_.at(i) && inner_->ready(i); }
    int event_fd() const override { return -1; }
    Result<std::vector<std::size_t>> dispatch_events() override { return std::vector<std::size_t>{}; }

    bool withhold = false;

private:
    std::unique_ptr<OutputBackend> inner_;
    std::vector<bool> in_flight_;
};

class KioskTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("mogao-kiosk-test-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "pki");
        for (const char* f : {"pki/ca.pem", "pki/a.pem", "pki/a.key"}) std::ofstream(dir_ / f) << "x";
        config_ = parse_kiosk_config(
            apply_config_overrides(
                kiosk_example_toml(),
                {R"(farm.endpoint="[::1]:7443")", R"(farm.ca="pki/ca.pem")", R"(farm.cert="pki/a.pem")",
                 R"(farm.key="pki/a.key")", "display.rate_hz=240", R"(outputs.backend="headless")",
                 R"(calibration.source="ideal")", R"(calibration.output="96x72")", R"(quality.content="160x90")",
                 "navigation.path_frames=10", R"(stats.file="stats.json")"}),
            dir_ / "kiosk.toml");
        screen_ = load_calibration(config_);
        HeadlessOptions options;
        for (const auto& p : screen_.projectors) options.outputs.push_back(p.output);
        auto backend = HeadlessOutputBackend::create(options);
        if (!backend) {
            if (backend.code() == ENODEV) return mogao::testing::skip_or_fail_without_egl(backend.error().message);
            FAIL() << backend.error().message;
        }
        headless_ = backend->get();
        auto display = KioskDisplay::create(std::move(backend).value(), screen_, nullptr);
        ASSERT_TRUE(display) << display.error().message;
        display_.emplace(std::move(display).value());
        ASSERT_TRUE(display_->show_connecting_screen(config_.quality.content, config_.farm.endpoint));
        inbox_ = open_inbox();
        navigation_ = std::make_unique<KioskNavigation>(scripted_visitor(config_));
        auto signals = SignalFd::create({SIGUSR1});
        ASSERT_TRUE(signals) << signals.error().message;
        signals_.emplace(std::move(signals).value());
    }
    void TearDown() override {
        kiosk_.reset();
        display_.reset();  // joins a recorder's PNG writer, which may still be writing under dir_
        fs::remove_all(dir_);
    }

    Kiosk& kiosk(KioskRunOptions options = {}) {
        kiosk_.emplace(config_, KioskParts{*display_, *inbox_, link_.port(), *navigation_, *signals_, notifier_},
                       std::move(options));
        return *kiosk_;
    }
    // What the link does, then waits for the inbox's worker to decode it (the loop would be woken).
    void deliver(LinkFrame&& frame) {
        inbox_->put(std::move(frame));
        inbox_->wait_decoded();
    }
    [[nodiscard]] std::vector<Rgb8Image> outputs() const {
        std::vector<Rgb8Image> out;
        for (std::size_t i = 0; i < headless_->outputs().size(); ++i) out.push_back(headless_->last_frame(i));
        return out;
    }

    fs::path dir_;
    KioskConfig config_;
    ScreenCalibration screen_;
    HeadlessOutputBackend* headless_ = nullptr;
    std::optional<KioskDisplay> display_;
    std::unique_ptr<FrameInbox> inbox_;
    std::unique_ptr<KioskNavigation> navigation_;
    std::optional<SignalFd> signals_;
    ServiceNotifier notifier_;
    RecordingLink link_;
    std::optional<Kiosk> kiosk_;
};

TEST_F(KioskTest, OnFrameShowsTheFrameInTheSlotOnEveryOutput) {
    Kiosk& k = kiosk();
    const std::vector<Rgb8Image> connecting = outputs();
    deliver(jpeg_frame(1, 120));
    k.on_frame();
    ASSERT_NE(k.current(), nullptr);
    EXPECT_EQ(k.current()->request_id, 1u);
    EXPECT_EQ(display_->frames_on_screen(), 1u);
    EXPECT_EQ(display_->stats().frames(), 1u);
    const std::vector<Rgb8Image> shown = outputs();
    ASSERT_EQ(shown.size(), 3u);
    for (std::size_t i = 0; i < shown.size(); ++i) {
        EXPECT_NE(shown[i].pixels, connecting[i].pixels) << "output " << i << " still shows the connecting screen";
    }
    // Middle of the middle projector (blend 1): content codes ~120..126 come out near them.
    EXPECT_NEAR(shown[1].at(48, 36)[0], 123, 8);
    k.on_frame();  // woken with nothing new: nothing changes
    EXPECT_EQ(display_->frames_on_screen(), 1u);
}

TEST_F(KioskTest, OnFrameShowsTheNewestFrameAndCountsTheReplacedOne) {
    Kiosk& k = kiosk();
    deliver(jpeg_frame(1, 40));
    deliver(jpeg_frame(2, 200));
    k.on_frame();
    EXPECT_EQ(k.current()->request_id, 2u);
    EXPECT_EQ(display_->frames_on_screen(), 1u);
    EXPECT_EQ(display_->stats().to_json()["frames_superseded"], 1);
}

TEST_F(KioskTest, ACorruptJpegKeepsTheLastGoodFrameOnEveryOutput) {
    Kiosk& k = kiosk();
    deliver(jpeg_frame(1, 90));
    k.on_frame();
    const std::vector<Rgb8Image> before = outputs();
    LinkFrame corrupt = jpeg_frame(2, 200);
    corrupt.jpeg.resize(corrupt.jpeg.size() * 2 / 3);
    deliver(std::move(corrupt));
    k.on_frame();
    EXPECT_EQ(k.current()->request_id, 1u);
    EXPECT_EQ(display_->frames_on_screen(), 1u);
    EXPECT_EQ(display_->stats().to_json()["frames_rejected"], 1);
    // The technician sees it in the status file without the journal.
    const KioskStatus status = k.status("showing");
    EXPECT_NE(status.last_error.find("frame dropped"), std::string::npos) << status.last_error;
    EXPECT_GT(status.last_error_ns, 0);
    const std::vector<Rgb8Image> after = outputs();
    for (std::size_t i = 0; i < after.size(); ++i) EXPECT_EQ(after[i].pixels, before[i].pixels) << "output " << i;
}

TEST_F(KioskTest, FramesOptionStopsOnceThatManyFramesAreOnScreen) {
    KioskRunOptions options;
    options.frames = 2;
    Kiosk& k = kiosk(std::move(options));
    deliver(jpeg_frame(1, 60));
    k.on_frame();
    EXPECT_FALSE(k.stopping());
    deliver(jpeg_frame(2, 70));
    k.on_frame();
    EXPECT_TRUE(k.stopping());
    EXPECT_EQ(k.exit_code(), 0);
}

TEST_F(KioskTest, OnTickSubmitsTheNavigationsPoseAndLogsIt) {
    KioskRunOptions options;
    options.pose_log.emplace(dir_ / "poses.jsonl");
    Kiosk& k = kiosk(std::move(options));
    ViewScript expected = scripted_visitor(config_);  // the same scripted visitor, stepped alongside
    for (int tick = 1; tick <= 3; ++tick) {
        wait_readable(k.tick_fd());
        k.on_tick();
        ASSERT_EQ(link_.requests.size(), static_cast<std::size_t>(tick));
        const ViewRequest want = expected.next();
        const ViewRequest& got = link_.requests.back();
        EXPECT_EQ(got.pose.eye, want.pose.eye) << "tick " << tick;
        EXPECT_DOUBLE_EQ(got.pose.yaw_deg, want.pose.yaw_deg);
        EXPECT_EQ(got.size, kContent);
    }
    EXPECT_EQ(k.ticks(), 3u);
    EXPECT_NE(link_.requests[0].pose.eye, link_.requests[2].pose.eye) << "the walk does not move";
    ASSERT_EQ(k.finish(), 0);
    std::ifstream log(dir_ / "poses.jsonl");
    std::string first;
    ASSERT_TRUE(std::getline(log, first));
    const auto line = nlohmann::json::parse(first);
    EXPECT_EQ(line["tick"], 1);
    EXPECT_EQ(line["request_id"], 101);  // what the link returned
}

// The idle repaint draws only what would change the wall: an unchanged frame is not drawn again
// (the late warp's turns: AYawOnlyTurnReachesTheWallWithinOneDisplayRoundWithoutANewFrame).
TEST_F(KioskTest, OnTickDoesNotRedrawAnUnchangedWall) {
    Kiosk& k = kiosk();
    const std::uint64_t rounds = display_->stats().rounds();  // the connecting screen
    wait_readable(k.tick_fd());
    k.on_tick();  // the connecting screen was shown since start: no repaint
    EXPECT_EQ(display_->stats().rounds(), rounds);
    wait_readable(k.tick_fd());
    k.on_tick();
    EXPECT_EQ(display_->stats().rounds(), rounds) << "nothing changed: the wall must not be drawn again";
    deliver(jpeg_frame(1, 80));
    k.on_frame();
    EXPECT_EQ(display_->stats().rounds(), rounds + 1);
    wait_readable(k.tick_fd());
    k.on_tick();
    EXPECT_EQ(display_->stats().rounds(), rounds + 1) << "a frame came: the tick must not repaint";
    wait_readable(k.tick_fd());
    k.on_tick();
    EXPECT_EQ(display_->stats().rounds(), rounds + 1) << "the same frame, unmoved: nothing to draw";
}

// A recording kiosk draws a wall left unchanged again only every png_every-th idle tick (so that a
// held frame is recorded), not at every tick: those rounds took the farm's cores for nothing.
TEST_F(KioskTest, WhileRecordingAnUnchangedWallIsDrawnAgainEveryKthIdleTick) {
    display_->record_to(HeadlessRecorder(*headless_, dir_ / "png", 3));
    Kiosk& k = kiosk();
    deliver(jpeg_frame(1, 80));
    k.on_frame();
    const std::uint64_t rounds = display_->stats().rounds();
    wait_readable(k.tick_fd());
    k.on_tick();  // a frame was shown since the previous tick: no repaint, no idle tick
    for (int idle = 1; idle <= 6; ++idle) {
        wait_readable(k.tick_fd());
        k.on_tick();
        EXPECT_EQ(display_->stats().rounds(), rounds + static_cast<std::uint64_t>(idle / 3)) << "idle tick " << idle;
    }
}

// A frame already decoded and waiting is shown next, with the tick's shift: a repaint of the old
// frame first would only delay it by a whole round.
TEST_F(KioskTest, OnTickDoesNotRepaintWhileADecodedFrameWaits) {
    Kiosk& k = kiosk();
    const std::uint64_t rounds = display_->stats().rounds();
    wait_readable(k.tick_fd());
    k.on_tick();  // the connecting screen was shown since start: no repaint
    deliver(jpeg_frame(1, 80));
    wait_readable(k.tick_fd());
    k.on_tick();  // nothing shown since the previous tick, but a frame waits
    EXPECT_EQ(display_->stats().rounds(), rounds) << "the waiting frame must not wait behind a repaint";
    k.on_frame();
    EXPECT_EQ(display_->stats().rounds(), rounds + 1);
    ASSERT_NE(k.current(), nullptr);
    EXPECT_EQ(k.current()->request_id, 1u);
    wait_readable(k.tick_fd());
    k.on_tick();  // a frame came: no repaint
    wait_readable(k.tick_fd());
    k.on_tick();  // nothing new and nothing waiting, but nothing moved either
    EXPECT_EQ(display_->stats().rounds(), rounds + 1);
}

TEST_F(KioskTest, OnTickRecordsLinkStateChanges) {
    Kiosk& k = kiosk();
    link_.stats.connected = true;
    wait_readable(k.tick_fd());
    k.on_tick();
    link_.stats.connected = false;
    wait_readable(k.tick_fd());
    k.on_tick();
    const auto events = display_->stats().to_json()["events"];
    ASSERT_EQ(events.size(), 2u) << events.dump();
    EXPECT_EQ(events[0]["event"], "connected");
    EXPECT_EQ(events[1]["event"], "disconnected");
}

TEST_F(KioskTest, OnSignalStopsTheLoop) {
    Kiosk& k = kiosk();
    k.on_signal();  // nothing pending
    EXPECT_FALSE(k.stopping());
    ASSERT_EQ(::raise(SIGUSR1), 0);
    k.on_signal();
    EXPECT_TRUE(k.stopping());
    EXPECT_EQ(k.exit_code(), 0);
}

TEST_F(KioskTest, AnOutputWhoseFlipNeverCompletesStopsTheKioskForARestart) {
    // The fixture's display is replaced by one whose flips can be made to hang.
    display_.reset();
    HeadlessOptions options;
    for (const auto& p : screen_.projectors) options.outputs.push_back(p.output);
    auto headless = HeadlessOutputBackend::create(options);
    ASSERT_TRUE(headless) << headless.error().message;
    auto wrapper = std::make_unique<FlipNeverCompletes>(std::move(headless).value());
    FlipNeverCompletes& backend = *wrapper;
    auto display = KioskDisplay::create(std::move(wrapper), screen_, nullptr);
    ASSERT_TRUE(display) << display.error().message;
    display_.emplace(std::move(display).value());
    KioskRunOptions run;
    run.flip_timeout = std::chrono::milliseconds(100);
    Kiosk& k = kiosk(std::move(run));

    // Flips complete: ticks well past the timeout change nothing.
    const auto start = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() - start < std::chrono::milliseconds(300)) {
        wait_readable(k.tick_fd());
        k.on_tick();
    }
    ASSERT_FALSE(k.stopping());

    // From now on no flip completes: the kiosk stops with a failure (systemd restarts it) after
    // the timeout, not before, and feeds the watchdog no more.
    backend.withhold = true;
    deliver(jpeg_frame(1, 150));
    k.on_frame();
    const auto hung = std::chrono::steady_clock::now();
    while (!k.stopping() && std::chrono::steady_clock::now() - hung < std::chrono::seconds(10)) {
        wait_readable(k.tick_fd());
        k.on_tick();
    }
    EXPECT_TRUE(k.stopping()) << "the kiosk runs on with a frozen output";
    EXPECT_GE(std::chrono::steady_clock::now() - hung, std::chrono::milliseconds(100));
    EXPECT_EQ(k.exit_code(), 1);
}

// [screen].guard_deg: requests carry the band (arc and width widened alike), and a frame is shown
// shifted by the yaw turned since its request (appliance/warp/late_warp.h).
TEST_F(KioskTest, GuardBandWidensTheRequestAndTheFrameIsShiftedByTheYawSinceItsRequest) {
    config_.guard_deg = 10;  // 160 columns over 150 degrees: 11 columns = 10.3125 degrees each side
    Kiosk& k = kiosk();
    wait_readable(k.tick_fd());
    k.on_tick();
    ASSERT_EQ(link_.requests.size(), 1u);
    const ViewRequest& request = link_.requests.back();
    EXPECT_EQ(request.size, (ImageSize{182, 90}));
    ASSERT_TRUE(std::holds_alternative<CylinderScreen>(request.camera));
    EXPECT_DOUBLE_EQ(std::get<CylinderScreen>(request.camera).arc_deg, 150.0 * 182 / 160);

    LinkFrame frame = jpeg_frame(101, 90);
    Rgb8Image wide({182, 90}, 90);
    frame.size = wide.size;
    frame.jpeg = JpegEncoder().encode(wide, 90);
    frame.pose = request.pose;
    frame.pose.yaw_deg -= 2.0;  // the visitor turned 2 degrees left since this frame's request
    deliver(std::move(frame));
    k.on_frame();
    ASSERT_NE(k.current(), nullptr);
    const ContentTransform t = display_->content_transform();
    const double guarded_arc = 150.0 * 182 / 160;
    EXPECT_NEAR(t.scale_u, 150.0 / guarded_arc, 1e-6);
    EXPECT_NEAR(t.offset_u, (10.3125 - 2.0) / guarded_arc, 1e-6);
    EXPECT_FLOAT_EQ(t.scale_v, 1.0f);
    EXPECT_FLOAT_EQ(t.offset_v, 0.0f);
    EXPECT_EQ(k.late_warp_clamped(), 0u);
}

// A grey content frame of the guarded width whose column u is the pattern's column u - shift: a
// frame rendered after the view turned by `shift` columns' worth of yaw (late_warp.h: a left turn
// moves the world right). Grey keeps both chroma planes at 128, and a shift by whole 8-column JPEG
// blocks keeps every luma block's pixels, so both frames decode to the same columns, shifted.
LinkFrame striped_frame(std::uint64_t request_id, ImageSize size, int shift, const ViewerPose& pose) {
    Rgb8Image content(size);
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            const int u = x - shift;
            const auto v = static_cast<std::uint8_t>(30 + ((u + 64) * 53) % 190);
            for (int c = 0; c < 3; ++c) content.at(x, y)[c] = v;
        }
    }
    LinkFrame frame;
    frame.frame_id = request_id;
    frame.request_id = request_id;
    frame.size = size;
    frame.jpeg = JpegEncoder().encode(content, 95);
    frame.pose = pose;
    return frame;
}

int max_abs_difference(const std::vector<Rgb8Image>& a, const std::vector<Rgb8Image>& b) {
    int worst = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        for (std::size_t k = 0; k < a[i].pixels.size(); ++k)
            worst = std::max(worst, std::abs(a[i].pixels[k] - b[i].pixels[k]));
    }
    return worst;
}

// The late rotational warp: a yaw-only turn is on the wall within one display round whatever the farm's latency.
// No new farm frame comes after the turn, yet the outputs of the next round are those a frame
// rendered at the new yaw gives (checked against such a frame, through the same GL outputs), and a
// turn right after a frame was shown is on the wall one round later.
TEST_F(KioskTest, AYawOnlyTurnReachesTheWallWithinOneDisplayRoundWithoutANewFrame) {
    config_.guard_deg = 10;          // 11 columns of 150/160 degrees each side: 182 columns in all
    constexpr int kTurnColumns = 8;  // 7.5 degrees, inside the band
    ViewerPose ahead;
    ViewerPose turned = ahead;
    turned.yaw_deg += kTurnColumns * 150.0 / 160.0;
    // The visitor's pose at ticks 1..5: still, still, turned left, back, back.
    navigation_ =
        std::make_unique<KioskNavigation>(ViewScript({ahead, ahead, turned, ahead, ahead}, view_template(config_)));
    Kiosk& k = kiosk();
    const ImageSize guarded{182, 90};

    wait_readable(k.tick_fd());
    k.on_tick();  // tick 1, request 101 looking ahead
    deliver(striped_frame(101, guarded, 0, link_.requests.back().pose));
    k.on_frame();
    const std::vector<Rgb8Image> before = outputs();
    const std::uint64_t rounds = display_->stats().rounds();
    wait_readable(k.tick_fd());
    k.on_tick();  // tick 2, still: a frame came since tick 1, nothing to repaint
    ASSERT_EQ(display_->stats().rounds(), rounds);

    wait_readable(k.tick_fd());
    k.on_tick();  // tick 3: the visitor turned; the farm has not answered
    ASSERT_EQ(link_.requests.size(), 3u);
    EXPECT_EQ(display_->stats().rounds(), rounds + 1) << "the turn must reach the wall in this round";
    const std::vector<Rgb8Image> on_wall = outputs();
    EXPECT_GT(max_abs_difference(on_wall, before), 60) << "the wall did not move with the turn";
    EXPECT_EQ(k.late_warp_clamped(), 0u);

    // What the farm's frame for the turned view shows (request 103, no shift left to apply).
    deliver(striped_frame(103, guarded, kTurnColumns, link_.requests.back().pose));
    k.on_frame();
    const std::vector<Rgb8Image> rendered_turned = outputs();
    EXPECT_LE(max_abs_difference(on_wall, rendered_turned), 1)
        << "the late warp's shift differs from a frame rendered at the new yaw";

    // Turning back right after that frame was shown: tick 4 has nothing to repaint (a frame came),
    // so the turn is on the wall at tick 5, one round later, again without a new frame.
    wait_readable(k.tick_fd());
    k.on_tick();
    EXPECT_EQ(display_->stats().rounds(), rounds + 2);
    wait_readable(k.tick_fd());
    k.on_tick();
    EXPECT_EQ(display_->stats().rounds(), rounds + 3);
    // 2 codes: the right edge of the screen now falls in the turned frame's last JPEG block, a partial
    // one (182 columns), which decodes a little differently from the full block it repeats.
    EXPECT_LE(max_abs_difference(outputs(), before), 2) << "turning back must show the view ahead again";
}

TEST_F(KioskTest, RunShowsFramesUntilASignalThenWritesTheStatistics) {
    Kiosk& k = kiosk();
    deliver(jpeg_frame(7, 100));
    ASSERT_EQ(::raise(SIGUSR1), 0);
    link_.stats.sessions_opened = 1;
    EXPECT_EQ(k.run(), 0);
    EXPECT_TRUE(link_.stopped);
    std::ifstream in(dir_ / "stats.json");
    ASSERT_TRUE(in) << "no statistics written";
    const auto stats = nlohmann::json::parse(in);
    EXPECT_EQ(stats["exit_code"], 0);
    EXPECT_EQ(stats["endpoint"], "[::1]:7443");
    EXPECT_EQ(stats["content"], nlohmann::json::array({160, 90}));
    EXPECT_EQ(stats["navigation"]["source"], "path");
    EXPECT_EQ(stats["link"]["sessions_opened"], 1);
    EXPECT_EQ(stats["jpeg_quality"], config_.quality.jpeg_quality);
}

}  // namespace
}  // namespace mogao
