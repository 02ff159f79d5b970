// SPDX-License-Identifier: Apache-2.0
#include "appliance/navigation/navigator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "appliance/navigation/test_poses.h"

namespace mogao {
namespace {

using test::kMs;
using test::tag_sample;

constexpr std::int64_t kCameraPeriod = 33'333'333;   // 30 Hz
constexpr std::int64_t kDisplayPeriod = 16'666'667;  // 60 Hz

// Feeds camera samples (30 Hz, from `sample(t_ns)`) and display frames (60 Hz) to a Navigator in
// time order, continuing where the previous call stopped; `on_frame` runs after each display frame.
struct Clock {
    Navigator& nav;
    std::int64_t next_display = 0;
    std::int64_t next_camera = 0;

    void run_until(std::int64_t end, const std::function<TagSample(std::int64_t)>& sample,
                   const std::function<void(std::int64_t, const ViewerPose&)>& on_frame = {}) {
        for (; next_display <= end; next_display += kDisplayPeriod) {
            for (; next_camera <= next_display; next_camera += kCameraPeriod) nav.observe(sample(next_camera));
            const ViewerPose pose = nav.advance(next_display);
            if (on_frame) on_frame(next_display, pose);
        }
    }
};

TagSample lost(std::int64_t t) {
    TagSample s;
    s.time_ns = t;
    return s;
}

TEST(Navigator, GeneratedPoseSequenceGivesTheMappedVelocities) {
    const NavigationParams p;
    Navigator nav(p, ViewerPose{});
    Clock nav_clock{nav};
    // 1 s at rest: nothing moves.
    nav_clock.run_until(1000 * kMs, [](std::int64_t t) { return tag_sample(t, 0.5, 0.5); });
    EXPECT_EQ(nav.velocity().turn_deg_s, 0.0);
    EXPECT_EQ(nav.velocity().forward_m_s, 0.0);
    EXPECT_NEAR(nav.pose().eye.z(), 0.0, 1e-12);

    // Tag turned 20 deg left and pushed 10 cm toward the camera for 3 s.
    double previous_yaw = nav.pose().yaw_deg;
    nav_clock.run_until(
        4000 * kMs, [](std::int64_t t) { return tag_sample(t, 20.0, 0.4); },
        [&](std::int64_t, const ViewerPose& pose) {
            EXPECT_GE(pose.yaw_deg, previous_yaw);  // turning left only
            previous_yaw = pose.yaw_deg;
            EXPECT_EQ(pose.eye.y(), p.eye_height_m);  // fixed eye height
        });
    const double expected_turn = 45.0 * (20.0 - 4.0) / (30.0 - 4.0);
    const double expected_forward = 1.0 * (0.10 - 0.03) / (0.15 - 0.03);
    EXPECT_NEAR(nav.commanded().turn_deg_s, expected_turn, 0.05);
    EXPECT_NEAR(nav.velocity().turn_deg_s, expected_turn, 0.05);
    EXPECT_NEAR(nav.velocity().forward_m_s, expected_forward, 0.002);
    EXPECT_NEAR(nav.velocity().strafe_m_s, 0.0, 1e-12);  // strafe is off by default
    EXPECT_GT(nav.pose().yaw_deg, 60.0);                 // ~3 s at up to 27.7 deg/s
    EXPECT_EQ(nav.pose().pitch_deg, 0.0);
    EXPECT_TRUE(nav.tracking());
    // Walking forward while turning left: from yaw 0 (-z) toward -x.
    EXPECT_LT(nav.pose().eye.z(), -0.5);
    EXPECT_LT(nav.pose().eye.x(), -0.1);
}

TEST(Navigator, LostTagDeceleratesSmoothlyToAStop) {
    const NavigationParams p;
    Navigator nav(p, ViewerPose{});
    Clock nav_clock{nav};
    nav_clock.run_until(3000 * kMs, [](std::int64_t t) { return tag_sample(t, 40.0, 0.3); });
    ASSERT_NEAR(nav.velocity().turn_deg_s, 45.0, 1e-9);
    ASSERT_NEAR(nav.velocity().forward_m_s, 1.0, 1e-9);

    Velocity before = nav.velocity();
    ViewerPose pose_before = nav.pose();
    int frames = 0;
    nav_clock.run_until(5000 * kMs, lost, [&](std::int64_t, const ViewerPose& pose) {
        const Velocity& v = nav.velocity();
        const double dt = static_cast<double>(kDisplayPeriod) * 1e-9;
        // Never speeds up, never changes by more than the acceleration limit in one frame.
        EXPECT_LE(v.turn_deg_s, before.turn_deg_s);
        EXPECT_GE(v.turn_deg_s, 0.0);
        EXPECT_LE(before.turn_deg_s - v.turn_deg_s, p.max_angular_accel_deg_s2 * dt + 1e-9);
        EXPECT_LE(before.forward_m_s - v.forward_m_s, p.max_linear_accel_m_s2 * dt + 1e-9);
        // The view never jumps: each frame moves at most what the speed allows.
        EXPECT_LE(pose.yaw_deg - pose_before.yaw_deg, 45.0 * dt + 1e-9);
        EXPECT_LE((pose.eye - pose_before.eye).norm(), 1.0 * dt + 1e-9);
        before = v;
        pose_before = pose;
        ++frames;
    });
    EXPECT_GT(frames, 100);
    EXPECT_FALSE(nav.tracking());
    EXPECT_EQ(nav.velocity().turn_deg_s, 0.0);
    EXPECT_EQ(nav.velocity().forward_m_s, 0.0);
    // Stopped: the pose no longer changes.
    const ViewerPose stopped = nav.pose();
    nav_clock.run_until(5500 * kMs, lost);
    EXPECT_EQ(nav.pose().yaw_deg, stopped.yaw_deg);
    EXPECT_EQ(nav.pose().eye, stopped.eye);
}

TEST(Navigator, ShortDropoutKeepsTheCommand) {
    Navigator nav(NavigationParams{}, ViewerPose{});
    Clock nav_clock{nav};
    nav_clock.run_until(2000 * kMs, [](std::int64_t t) { return tag_sample(t, 40.0); });
    // One camera frame without the tag (100 ms < hold_s): no deceleration.
    nav_clock.run_until(2100 * kMs, lost);
    EXPECT_TRUE(nav.tracking());
    EXPECT_NEAR(nav.velocity().turn_deg_s, 45.0, 1e-9);
}

TEST(Navigator, FlippedPoseIsRejected) {
    Navigator nav(NavigationParams{}, ViewerPose{});
    Clock nav_clock{nav};
    // The tag held turned 15 deg left; frame 40 is the mirrored IPPE solution (-15 deg).
    int frame = 0;
    double min_turn = 1e9;
    double last_yaw = 0.0;
    nav_clock.run_until(
        2000 * kMs, [&](std::int64_t t) { return tag_sample(t, frame++ == 40 ? -15.0 : 15.0); },
        [&](std::int64_t t, const ViewerPose& pose) {
            if (t > 1000 * kMs) min_turn = std::min(min_turn, nav.commanded().turn_deg_s);
            EXPECT_GE(pose.yaw_deg, last_yaw);
            last_yaw = pose.yaw_deg;
        });
    EXPECT_EQ(nav.rejected_samples(), 1);
    EXPECT_GT(min_turn, 15.0);  // 45 * 11 / 26 = 19 deg/s, never reversed or dipping
}

TEST(Navigator, PitchIsOptional) {
    NavigationParams p;
    Navigator level(p, ViewerPose{});
    Clock level_clock{level};
    level_clock.run_until(2000 * kMs, [](std::int64_t t) { return tag_sample(t, 0.0, 0.5, 15.0); });
    EXPECT_EQ(level.pose().pitch_deg, 0.0);

    p.pitch.enabled = true;
    Navigator tilting(p, ViewerPose{});
    Clock tilting_clock{tilting};
    tilting_clock.run_until(3000 * kMs, [](std::int64_t t) { return tag_sample(t, 0.0, 0.5, 15.0); });
    EXPECT_NEAR(tilting.pose().pitch_deg, 12.0, 0.05);  // 15 - dead zone 3
    tilting_clock.run_until(4000 * kMs, lost);
    EXPECT_EQ(tilting.pose().pitch_deg, 0.0);  // eases back to level when the tag is lost
}

TEST(Navigator, LongDisplayStallIsClamped) {
    Navigator nav(NavigationParams{}, ViewerPose{});
    Clock nav_clock{nav};
    nav_clock.run_until(2000 * kMs, [](std::int64_t t) { return tag_sample(t, 40.0); });
    const double yaw = nav.pose().yaw_deg;
    nav.observe(tag_sample(4000 * kMs, 40.0));
    (void)nav.advance(4000 * kMs);  // 2 s later: integrated as max_dt_s = 0.1 s
    EXPECT_LE(nav.pose().yaw_deg - yaw, 45.0 * 0.1 + 1e-9);
    EXPECT_GT(nav.pose().yaw_deg - yaw, 0.0);
}

TEST(Navigator, BadParametersAndStart) {
    NavigationParams p;
    p.hold_s = 1.0;
    p.forget_s = 0.5;
    EXPECT_THROW(Navigator(p, ViewerPose{}), std::invalid_argument);
    p = {};
    p.turn.full_scale = 1.0;  // below its dead zone of 4
    try {
        Navigator nav(p, ViewerPose{});
        FAIL() << "expected invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("NavigationParams.turn.full_scale"), std::string::npos) << e.what();
    }
    ViewerPose bad;
    bad.yaw_deg = std::nan("");
    EXPECT_THROW(Navigator(NavigationParams{}, bad), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
