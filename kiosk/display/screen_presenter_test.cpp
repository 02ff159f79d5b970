// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/screen_presenter.h"

#include <gtest/gtest.h>

#include <utility>

#include "appliance/decode/last_good_frame.h"
#include "appliance/warp/ideal_calibration.h"
#include "common/jpeg_codec.h"
#include "drivers/egl/egl_test_support.h"
#include "drivers/headless/headless_output.h"
#include "kiosk/display/connecting_screen.h"

namespace mogao {
namespace {

using mogao::testing::skip_or_fail_without_egl;

constexpr ImageSize kContent{160, 90};

ScreenCalibration three_projectors() {
    IdealCalibrationParams p;
    p.projectors = 3;
    p.overlap = 0.15;
    p.output = {96, 72};
    p.content = kContent;
    p.response_entries = 256;
    return make_ideal_calibration(p);
}

std::unique_ptr<HeadlessOutputBackend> headless(const ScreenCalibration& screen) {
    HeadlessOptions options;
    for (const auto& p : screen.projectors) options.outputs.push_back(p.output);
    auto backend = HeadlessOutputBackend::create(options);
    if (!backend) {
        if (backend.code() == ENODEV) skip_or_fail_without_egl(backend.error().message);
        else ADD_FAILURE() << backend.error().message;
        return nullptr;
    }
    return std::move(backend).value();
}

Rgb8Image uniform(ImageSize size, std::uint8_t v) { return Rgb8Image(size, v); }

double mean(const Rgb8Image& image) {
    double sum = 0;
    for (const auto v : image.pixels) sum += v;
    return image.pixels.empty() ? 0 : sum / static_cast<double>(image.pixels.size());
}

// Simulates KMS rounds on top of the headless backend. stage(i) draws (reads back); commit_round()
// is one atomic commit: the first a blocking modeset (on screen at once); later ones are applied
// to every CRTC of the commit at once by latch() (the kernel's atomic update), and each output's
// flip event is delivered by event(i), in whatever order the test chooses. screen(i) is the commit
// output i scans out, which is what the test compares across outputs.
class RoundBackend final : public OutputBackend {
public:
    explicit RoundBackend(HeadlessOutputBackend& inner)
        : inner_(inner),
          busy_(inner.outputs().size(), false),
          staged_(inner.outputs().size(), false),
          pending_(inner.outputs().size(), 0),
          screen_(inner.outputs().size(), 0),
          presented_(inner.outputs().size(), 0) {}
    const std::vector<OutputInfo>& outputs() const override { return inner_.outputs(); }
    ProjectorRenderer& renderer() override { return inner_.renderer(); }
    Status begin_frame(std::size_t i) override {
        if (!ready(i)) {
            ++refused_;
            return make_error(EBUSY, "flip pending");
        }
        return inner_.begin_frame(i);
    }
    Status present(std::size_t i) override {
        if (Status s = stage(i); !s) return s;
        return commit_round();
    }
    Status stage(std::size_t i) override {
        if (Status s = inner_.present(i); !s) return s;
        staged_.at(i) = true;
        return {};
    }
    Status commit_round() override {
        ++commits_;
        for (std::size_t i = 0; i < staged_.size(); ++i) {
            if (!staged_[i]) continue;
            staged_[i] = false;
            if (presented_[i]++ == 0) {
                screen_[i] = commits_;  // the blocking modeset
            } else {
                pending_[i] = commits_;
                busy_[i] = true;
            }
        }
        return {};
    }
    bool ready(std::size_t i) const override { return !busy_.at(i) && !staged_.at(i); }
    int event_fd() const override { return -1; }
    Result<std::vector<std::size_t>> dispatch_events() override { return std::exchange(events_, {}); }

    void latch() {
        for (std::size_t i = 0; i < busy_.size(); ++i) {
            if (busy_[i]) screen_[i] = pending_[i];
        }
    }
    void event(std::size_t i) {
        if (busy_.at(i)) {
            latch();  // an event comes after its commit was applied (to every CRTC)
            busy_[i] = false;
            events_.push_back(i);
        }
    }
    [[nodiscard]] bool busy(std::size_t i) const { return busy_.at(i); }
    [[nodiscard]] int screen(std::size_t i) const { return screen_.at(i); }
    [[nodiscard]] int presents(std::size_t i) const { return presented_.at(i); }
    [[nodiscard]] int commits() const { return commits_; }
    [[nodiscard]] int refused() const { return refused_; }

private:
    HeadlessOutputBackend& inner_;
    std::vector<bool> busy_;
    std::vector<bool> staged_;
    std::vector<int> pending_;
    std::vector<int> screen_;
    std::vector<int> presented_;
    std::vector<std::size_t> events_;
    int commits_ = 0;
    int refused_ = 0;
};

// Every output scans out the same commit, hence the same content frame.
::testing::AssertionResult same_frame_everywhere(const RoundBackend& backend) {
    for (std::size_t i = 1; i < backend.outputs().size(); ++i) {
        if (backend.screen(i) != backend.screen(0)) {
            return ::testing::AssertionFailure() << "output 0 shows commit " << backend.screen(0) << ", output " << i
                                                 << " commit " << backend.screen(i);
        }
    }
    return ::testing::AssertionSuccess();
}

TEST(ScreenPresenter, ShowsTheConnectingScreenThenFramesOnEveryOutput) {
    const ScreenCalibration screen = three_projectors();
    auto backend = headless(screen);
    if (!backend) return;
    auto presenter = ScreenPresenter::create(*backend, screen, nullptr);
    ASSERT_TRUE(presenter) << presenter.error().message;

    ASSERT_TRUE(presenter->show(make_connecting_screen(kContent, "FARM [::1]:7443"), 0));
    EXPECT_EQ(presenter->last_presents(), 3u);
    EXPECT_EQ(presenter->take_completed(), std::optional<std::uint64_t>(0));
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_GT(mean(backend->last_frame(i)), 20.0) << "output " << i << " is black while connecting";
    }

    ASSERT_TRUE(presenter->show(uniform(kContent, 128), 5));
    EXPECT_EQ(presenter->take_completed(), std::optional<std::uint64_t>(5));
    EXPECT_FALSE(presenter->take_completed().has_value());
    // Middle of the middle projector (blend 1): sRGB 128 -> linear 0.216 -> gamma 2.2 LUT -> 127.
    const Rgb8Image& mid = backend->last_frame(1);
    EXPECT_NEAR(mid.at(48, 36)[0], 127, 3);
    EXPECT_FALSE(presenter->show(uniform(kContent, 10), 4)) << "tags must not go back";
}

// A mode other than the calibrated size (the projector runs 192x144, calibrated at 96x72): the
// whole output shows the picture, resampled; no corner is left black.
TEST(ScreenPresenter, OutputModeLargerThanTheCalibrationIsFilled) {
    const ScreenCalibration screen = three_projectors();
    HeadlessOptions options;
    for (const auto& p : screen.projectors) options.outputs.push_back({p.output.width * 2, p.output.height * 2});
    auto created = HeadlessOutputBackend::create(options);
    if (!created) {
        if (created.code() == ENODEV) skip_or_fail_without_egl(created.error().message);
        else ADD_FAILURE() << created.error().message;
        return;
    }
    auto& backend = *created;
    auto presenter = ScreenPresenter::create(*backend, screen, nullptr);
    ASSERT_TRUE(presenter) << presenter.error().message;
    ASSERT_TRUE(presenter->show(uniform(kContent, 128), 1));
    const Rgb8Image& mid = backend->last_frame(1);
    ASSERT_EQ(mid.size, (ImageSize{192, 144}));
    // Middle projector, blend 1 away from its overlaps: every quadrant shows sRGB 128 -> 127.
    for (const auto& [x, y] : {std::pair{48, 36}, std::pair{144, 36}, std::pair{48, 108}, std::pair{144, 108}}) {
        EXPECT_NEAR(mid.at(x, y)[0], 127, 3) << "at (" << x << ", " << y << ")";
    }
}

TEST(ScreenPresenter, OutputsKeepTheLastGoodFrameWhenACorruptJpegArrives) {
    const ScreenCalibration screen = three_projectors();
    auto backend = headless(screen);
    if (!backend) return;
    auto presenter = ScreenPresenter::create(*backend, screen, nullptr);
    ASSERT_TRUE(presenter);
    JpegEncoder encoder;
    LastGoodFrame last;
    LinkFrame good;
    good.request_id = 1;
    good.size = kContent;
    Rgb8Image content(kContent);
    for (std::size_t k = 0; k < content.pixels.size(); ++k) content.pixels[k] = static_cast<std::uint8_t>(40 + k % 150);
    good.jpeg = encoder.encode(content, 90);
    ASSERT_EQ(last.accept(good), "");
    ASSERT_TRUE(presenter->show(last.current()->image, last.current()->request_id));
    std::vector<Rgb8Image> before;
    for (std::size_t i = 0; i < 3; ++i) before.push_back(backend->last_frame(i));

    LinkFrame corrupt = good;
    corrupt.request_id = 2;
    corrupt.jpeg.resize(corrupt.jpeg.size() * 2 / 3);
    ASSERT_NE(last.accept(corrupt), "");
    // What the kiosk does next: repaint what is current.
    ASSERT_TRUE(presenter->show(last.current()->image, last.current()->request_id));
    ASSERT_TRUE(presenter->repaint());
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(backend->last_frame(i).pixels, before[i].pixels) << "output " << i << " changed";
        EXPECT_GT(mean(backend->last_frame(i)), 20.0);
    }
}

TEST(ScreenPresenter, OutputsShowTheSameFrameAndARoundWaitsForEveryFlip) {
    const ScreenCalibration screen = three_projectors();
    auto inner = headless(screen);
    if (!inner) return;
    RoundBackend backend(*inner);
    auto created = ScreenPresenter::create(backend, screen, nullptr);
    ASSERT_TRUE(created);
    ScreenPresenter& p = *created;
    int presented_calls = 0;
    p.on_output_presented([&presented_calls] { ++presented_calls; });

    ASSERT_TRUE(p.show(uniform(kContent, 50), 1));  // modeset: on screen at once
    EXPECT_EQ(presented_calls, 3) << "one progress call per output presented";
    EXPECT_EQ(backend.commits(), 1) << "one commit for all outputs";
    EXPECT_EQ(p.take_completed(), std::optional<std::uint64_t>(1));
    EXPECT_TRUE(same_frame_everywhere(backend));
    ASSERT_TRUE(p.show(uniform(kContent, 60), 2));  // one round, flips pending on all three
    EXPECT_EQ(p.last_presents(), 3u);
    EXPECT_EQ(backend.commits(), 2);
    EXPECT_FALSE(p.take_completed().has_value());
    ASSERT_TRUE(p.show(uniform(kContent, 70), 3));  // the round is in flight: waits
    EXPECT_EQ(p.last_presents(), 0u);
    ASSERT_TRUE(p.repaint());
    EXPECT_EQ(p.last_presents(), 0u);

    backend.latch();  // the commit applies to every CRTC at once
    EXPECT_TRUE(same_frame_everywhere(backend));
    backend.event(0);
    backend.event(1);
    ASSERT_TRUE(p.on_ready(*backend.dispatch_events()));
    EXPECT_EQ(p.last_presents(), 0u) << "no new round while output 2's flip is pending";
    EXPECT_TRUE(same_frame_everywhere(backend));
    EXPECT_FALSE(p.take_completed().has_value()) << "output 2's flip event has not come";
    backend.event(2);
    ASSERT_TRUE(p.on_ready(*backend.dispatch_events()));
    EXPECT_EQ(p.take_completed(), std::optional<std::uint64_t>(2));
    EXPECT_EQ(p.last_presents(), 3u) << "frame 3 starts on all outputs together";
    backend.latch();
    for (std::size_t i = 0; i < 3; ++i) backend.event(i);
    ASSERT_TRUE(p.on_ready(*backend.dispatch_events()));
    EXPECT_EQ(p.take_completed(), std::optional<std::uint64_t>(3));
    EXPECT_TRUE(same_frame_everywhere(backend));
    EXPECT_EQ(backend.commits(), 3) << "frame 2 and 3, one commit each after the modeset";
    EXPECT_EQ(backend.presents(0), 3);
    EXPECT_EQ(backend.presents(2), 3);
    EXPECT_EQ(backend.refused(), 0) << "never began a frame on a busy output";
    EXPECT_EQ(presented_calls, 9) << "one per output of each round";
    EXPECT_NEAR(inner->last_frame(1).at(48, 36)[0], 70, 12);  // the newest content, not 60
}

// New frames, repaints and flip events in a scrambled order (fixed seed): at every step every output
// scans out the same commit, completed tags only increase, and a busy output is never drawn on.
TEST(ScreenPresenter, OutputsNeverShowDifferentFramesWhateverTheEventOrder) {
    const ScreenCalibration screen = three_projectors();
    auto inner = headless(screen);
    if (!inner) return;
    RoundBackend backend(*inner);
    auto created = ScreenPresenter::create(backend, screen, nullptr);
    ASSERT_TRUE(created);
    ScreenPresenter& p = *created;
    std::uint32_t state = 12345;
    const auto next = [&state] {
        state = state * 1664525u + 1013904223u;  // Numerical Recipes LCG
        return (state >> 16) % 6;
    };
    std::uint64_t tag = 0;
    std::uint64_t completed = 0;
    std::uint64_t rounds_completed = 0;
    for (int step = 0; step < 120; ++step) {
        const auto action = next();
        if (action <= 1) {
            ++tag;
            ASSERT_TRUE(p.show(uniform(kContent, static_cast<std::uint8_t>(20 + tag % 200)), tag));
        } else if (action == 2) {
            ASSERT_TRUE(p.repaint());
        } else if (action == 3) {
            backend.latch();
        } else {
            // The flip events of one output, maybe of all: the others come in later steps.
            const std::size_t first = next() % 3;
            for (std::size_t i = first; i < (action == 4 ? first + 1 : 3); ++i) backend.event(i);
            ASSERT_TRUE(p.on_ready(*backend.dispatch_events()));
        }
        ASSERT_TRUE(same_frame_everywhere(backend)) << "step " << step;
        if (const auto done = p.take_completed()) {
            EXPECT_GT(*done, completed);
            completed = *done;
            ++rounds_completed;
        }
    }
    EXPECT_EQ(backend.refused(), 0);
    EXPECT_GT(rounds_completed, 5u) << "the sequence exercises completed rounds";
}

}  // namespace
}  // namespace mogao
