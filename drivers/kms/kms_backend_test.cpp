// SPDX-License-Identifier: Apache-2.0
// Lights every connected output of the first usable /dev/dri/card* with the test pattern through
// WarpBlendRenderer: a blocking modeset, then page flips driven by the event fd. Skipped where
// there is no DRM device; the image test (image_qemu_boot) runs it inside QEMU with virtio-gpu.
#include "drivers/kms/kms_backend.h"

#include <poll.h>
#include <time.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <vector>

#include "drivers/egl/test_pattern.h"

namespace mogao {
namespace {

constexpr int kFlipsPerOutput = 3;
constexpr int kPollMs = 2000;  // liveness only: a flip that never completes fails, a slow one does not

std::int64_t realtime_now_ns() {
    timespec ts{};
    clock_gettime(CLOCK_REALTIME, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

int max_abs_diff(const Rgb8Image& a, const Rgb8Image& b) {
    if (!(a.size == b.size)) return 256;
    int d = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) d = std::max(d, std::abs(int{a.pixels[i]} - int{b.pixels[i]}));
    return d;
}

TEST(KmsOutputBackend, LightsEveryConnectedOutput) {
    if (list_drm_cards().empty())
        GTEST_SKIP() << "no DRM device; the image test (image_qemu_boot) runs this inside QEMU with virtio-gpu";
    auto created = KmsOutputBackend::create({});
    if (!created && (created.code() == ENODEV || created.code() == EACCES)) {
        GTEST_SKIP() << created.error().message;  // no connected output, or a compositor owns the card
    }
    ASSERT_TRUE(created) << created.error().message;
    KmsOutputBackend& backend = **created;
    ASSERT_FALSE(backend.outputs().empty());
    ASSERT_GE(backend.event_fd(), 0);
    WarpBlendRenderer& renderer = backend.renderer();

    std::vector<Rgb8Image> patterns;
    for (const auto& out : backend.outputs()) {
        auto p = renderer.add_projector(identity_calibration(out.name, out.size));
        ASSERT_TRUE(p) << p.error().message;
        patterns.push_back(make_test_pattern(out.size));
        // The GL of this card renders the pattern exactly (FBO readback, no display involved).
        ASSERT_TRUE(renderer.set_content(patterns.back()).ok());
        auto image = renderer.render(*p);
        ASSERT_TRUE(image) << image.error().message;
        EXPECT_LE(max_abs_diff(*image, patterns.back()), 1) << out.name;
    }

    std::vector<int> flips(backend.outputs().size(), 0);
    for (std::size_t i = 0; i < backend.outputs().size(); ++i) {
        ASSERT_TRUE(backend.ready(i));
        ASSERT_TRUE(renderer.set_content(patterns[i]).ok());
        ASSERT_TRUE(backend.begin_frame(i).ok());
        ASSERT_TRUE(renderer.draw(i).ok());
        const Status s = backend.present(i);  // the blocking modeset
        ASSERT_TRUE(s.ok()) << s.error().message;
        EXPECT_TRUE(backend.ready(i)) << "ready again right after the modeset";
    }
    auto done = [&] { return std::all_of(flips.begin(), flips.end(), [](int f) { return f >= kFlipsPerOutput; }); };
    while (!done()) {
        for (std::size_t i = 0; i < backend.outputs().size(); ++i) {
            if (!backend.ready(i) || flips[i] >= kFlipsPerOutput) continue;
            ASSERT_TRUE(renderer.set_content(patterns[i]).ok());
            ASSERT_TRUE(backend.begin_frame(i).ok());
            ASSERT_TRUE(renderer.draw(i).ok());
            const Status s = backend.present(i);
            ASSERT_TRUE(s.ok()) << s.error().message;
            EXPECT_FALSE(backend.ready(i)) << "a flip is pending";
            EXPECT_EQ(backend.begin_frame(i).code(), EBUSY);
        }
        pollfd pfd{backend.event_fd(), POLLIN, 0};
        ASSERT_EQ(::poll(&pfd, 1, kPollMs), 1) << "no page-flip event";
        auto completed = backend.dispatch_events();
        ASSERT_TRUE(completed) << completed.error().message;
        for (std::size_t i : *completed) {
            ++flips[i];
            EXPECT_TRUE(backend.ready(i));
        }
    }
    // What the kernel scans out after the last flip is the pattern (scanout_reader.h); a driver that
    // cannot map its scanout buffers says so (EOPNOTSUPP/EACCES/ENODEV/EINVAL from MAP_DUMB) and is
    // not checked.
    for (std::size_t i = 0; i < backend.outputs().size(); ++i) {
        auto shown = backend.read_scanout(i);
        if (!shown) {
            std::printf("read_scanout(%zu): %s (not checked)\n", i, shown.error().message.c_str());
            continue;
        }
        EXPECT_LE(max_abs_diff(*shown, patterns[i]), 1) << backend.outputs()[i].name << " scanout";
    }
}

// Rounds (drivers/output.h): every output staged, then ONE atomic commit for all CRTCs; the next
// round only after every output's flip event, whose timestamp becomes presented_ns.
TEST(KmsOutputBackend, OneCommitPerRoundForEveryOutput) {
    if (list_drm_cards().empty())
        GTEST_SKIP() << "no DRM device; the image test (image_qemu_boot) runs this inside QEMU with virtio-gpu";
    auto created = KmsOutputBackend::create({});
    if (!created && (created.code() == ENODEV || created.code() == EACCES)) GTEST_SKIP() << created.error().message;
    ASSERT_TRUE(created) << created.error().message;
    KmsOutputBackend& backend = **created;
    WarpBlendRenderer& renderer = backend.renderer();
    const std::size_t n = backend.outputs().size();
    for (const auto& out : backend.outputs())
        ASSERT_TRUE(renderer.add_projector(identity_calibration(out.name, out.size)));
    ASSERT_TRUE(renderer.set_content(make_test_pattern(backend.outputs().front().size)).ok());
    std::optional<std::int64_t> previous;
    for (int round = 0; round < 1 + kFlipsPerOutput; ++round) {
        for (std::size_t i = 0; i < n; ++i) {
            ASSERT_TRUE(backend.ready(i)) << "round " << round << " output " << i;
            ASSERT_TRUE(backend.begin_frame(i).ok());
            ASSERT_TRUE(renderer.draw(i).ok());
            const Status s = backend.stage(i);
            ASSERT_TRUE(s.ok()) << s.error().message;
            EXPECT_FALSE(backend.ready(i)) << "staged: not ready until the round completes";
        }
        const std::int64_t committed = realtime_now_ns();
        const Status s = backend.commit_round();  // round 0: the blocking modeset of every output
        ASSERT_TRUE(s.ok()) << s.error().message;
        std::vector<bool> flipped(n, round == 0);
        while (!std::all_of(flipped.begin(), flipped.end(), [](bool f) { return f; })) {
            pollfd pfd{backend.event_fd(), POLLIN, 0};
            ASSERT_EQ(::poll(&pfd, 1, kPollMs), 1) << "no page-flip event in round " << round;
            auto completed = backend.dispatch_events();
            ASSERT_TRUE(completed) << completed.error().message;
            for (std::size_t i : *completed) flipped.at(i) = true;
        }
        for (std::size_t i = 0; i < n; ++i) {
            ASSERT_TRUE(backend.ready(i));
            const auto t = backend.presented_ns(i);
            ASSERT_TRUE(t.has_value()) << "output " << i;
            // The flip's kernel timestamp: after the commit was made (1 ms slack for clock conversion).
            EXPECT_GE(*t, committed - 1'000'000) << "output " << i << " round " << round;
            if (previous) {
                EXPECT_GT(*t, *previous);
            }
        }
        previous = backend.presented_ns(0);
    }
}

}  // namespace
}  // namespace mogao
