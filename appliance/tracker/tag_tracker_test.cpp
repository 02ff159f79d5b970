// SPDX-License-Identifier: Apache-2.0
// Region-of-interest tracking in TagTracker against synthetic truth (synthetic_view.h) and against
// whole-frame detection of the same frames (its accuracy against the same truth).
#include "appliance/tracker/tag_tracker.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "appliance/tracker/lab/synthetic_view.h"
#include "appliance/tracker/tag_bitmap.h"

namespace mogao {
namespace {

constexpr double kTagSize = 0.1;

struct Shot {
    CameraFrame frame;
    bool visible = true;
    std::array<Eigen::Vector2d, 4> truth{};
};

// The tag at (x_m, y_m, distance) turned by yaw, in a cluttered room with sensor noise; hidden =
// the card is painted the background's grey (the tag left the view).
Shot shot(int index, double x_m, double y_m, double distance_m, double yaw_deg, bool hidden = false) {
    const CameraIntrinsics cam = ideal_camera();
    const TagPose pose = tag_pose_facing_camera(distance_m, yaw_deg, 5.0, 3.0, x_m, y_m);
    RenderEffects fx;
    fx.clutter_seed = 7;
    fx.noise_sigma = 2.0;
    fx.seed = static_cast<std::uint64_t>(index) + 1;
    fx.supersample = 4;
    if (hidden) fx.black = fx.white = fx.background;
    static const TagFamily family("tag36h11");
    Shot s;
    s.frame.image = render_target(tag_target(make_tag_bitmap(family, 5), kTagSize), pose, cam, fx);
    s.frame.timestamp_ns = static_cast<std::int64_t>(index) * 33'333'333;
    s.visible = !hidden;
    s.truth = project_tag_corners(pose, cam, kTagSize);
    return s;
}

TrackerConfig config(bool roi) {
    TrackerConfig c;
    c.camera = ideal_camera();
    c.tag_size_m = kTagSize;
    c.roi.enabled = roi;
    return c;
}

double max_error(const std::array<Eigen::Vector2d, 4>& a, const std::array<Eigen::Vector2d, 4>& b) {
    double e = 0.0;
    for (std::size_t k = 0; k < 4; ++k) e = std::max(e, (a[k] - b[k]).norm());
    return e;
}

double rms(const std::vector<double>& v) {
    double sum = 0.0;
    for (const double x : v) sum += x * x;
    return std::sqrt(sum / static_cast<double>(v.size()));
}

TEST(TagTrackerRoi, FollowsAMovingTagInTheWindowAsAccuratelyAsWholeFrameDetection) {
    TrackerConfig c = config(true);
    c.roi.full_search_every = 0;  // only when lost: every frame after the first must come from the window
    TagTracker roi(c);
    TagTracker full(config(false));  // full resolution on the whole frame: the accuracy to match
    std::vector<double> roi_errors, full_errors;
    for (int i = 0; i < 24; ++i) {
        // Accelerating sideways and turning: up to ~14 px per frame, so the prediction matters.
        const double t = i / 23.0;
        const Shot s = shot(i, -0.12 + 0.24 * t * t, 0.02 * t, 0.55, -20.0 + 40.0 * t);
        const TrackedTag a = roi.track(s.frame);
        const TrackedTag b = full.track(s.frame);
        ASSERT_TRUE(a.visible) << "frame " << i;
        ASSERT_TRUE(b.visible) << "frame " << i;
        EXPECT_EQ(a.id, 5);
        EXPECT_EQ(a.from_window, i > 0) << "frame " << i;
        // A ~125 px tag (0.1 m at 0.55 m, f = 700 px), foreshortened by the turn: the window is
        // searched decimated by 2 or 3 (floor(shortest side / window_tag_px 40)); the corners are
        // still fitted at full resolution.
        if (i > 0) {
            EXPECT_GE(roi.last_window_decimation(), 2) << "frame " << i;
        }
        EXPECT_LT(max_error(a.detection.corners, s.truth), 0.5) << "frame " << i;
        for (std::size_t k = 0; k < 4; ++k) {
            roi_errors.push_back((a.detection.corners[k] - s.truth[k]).norm());
            full_errors.push_back((b.detection.corners[k] - s.truth[k]).norm());
        }
    }
    EXPECT_EQ(roi.full_searches(), 1);
    // Against the truth, not against each other: no worse than full resolution on the whole frame
    // (measured: 0.078 px RMS whole frame, 0.081 px in the decimated window).
    EXPECT_LT(rms(roi_errors), 1.2 * rms(full_errors) + 0.01)
        << "full frame RMS " << rms(full_errors) << " window " << rms(roi_errors);
}

// The window's decimation follows the tag's apparent size: full resolution for a far tag, the cap
// for a near one; corners within 0.5 px of the truth at every size.
TEST(TagTrackerRoi, WindowDecimationFollowsTheTagSize) {
    struct Case {
        double distance_m;
        int decimation;  // expected: floor(side / 40) within [1, 4]; side = 70 px / distance
    };
    for (const Case& k : {Case{2.0, 1}, Case{1.0, 1}, Case{0.6, 2}, Case{0.4, 4}, Case{0.25, 4}}) {
        TagTracker tracker(config(true));
        for (int i = 0; i < 4; ++i) {
            const Shot s = shot(i, 0.01 * i * k.distance_m, 0.0, k.distance_m, 10.0);
            const TrackedTag tag = tracker.track(s.frame);
            ASSERT_TRUE(tag.visible) << k.distance_m << " m, frame " << i;
            EXPECT_EQ(tag.from_window, i > 0) << k.distance_m << " m, frame " << i;
            if (i > 0) {
                EXPECT_EQ(tracker.last_window_decimation(), k.decimation) << k.distance_m << " m";
            }
            EXPECT_LT(max_error(tag.detection.corners, s.truth), 0.5) << k.distance_m << " m, frame " << i;
        }
    }
    // window_tag_px = 0: the window at the detector's own settings (full resolution).
    TrackerConfig c = config(true);
    c.roi.window_tag_px = 0.0;
    TagTracker tracker(c);
    for (int i = 0; i < 2; ++i) ASSERT_TRUE(tracker.track(shot(i, 0.0, 0.0, 0.4, 0.0).frame).visible);
    EXPECT_EQ(tracker.last_window_decimation(), 1);
    // A detector decimating by itself is never searched finer in the window.
    c = config(true);
    c.detector.decimation = 2.0f;
    c.detector.blur_sigma = 0.8f;
    TagTracker coarse(c);
    for (int i = 0; i < 2; ++i) ASSERT_TRUE(coarse.track(shot(i, 0.0, 0.0, 2.0, 0.0).frame).visible);
    EXPECT_EQ(coarse.last_window_decimation(), 2);
}

TEST(TagTrackerRoi, FindsTheTagAgainAfterItWasLost) {
    TagTracker tracker(config(true));
    int index = 0;
    for (int i = 0; i < 5; ++i) ASSERT_TRUE(tracker.track(shot(index++, -0.1, 0.0, 0.5, 0.0).frame).visible);
    const long searches_before = tracker.full_searches();
    for (int i = 0; i < 4; ++i) {
        const TrackedTag gone = tracker.track(shot(index++, -0.1, 0.0, 0.5, 0.0, true).frame);
        EXPECT_FALSE(gone.visible) << "hidden frame " << i;
    }
    // Every frame without the tag searched the whole frame (the window found nothing).
    EXPECT_GE(tracker.full_searches() - searches_before, 4);
    // Back on the other side of the view, far outside the old window.
    const Shot back = shot(index++, 0.12, -0.05, 0.6, 15.0);
    const TrackedTag found = tracker.track(back.frame);
    ASSERT_TRUE(found.visible);
    EXPECT_FALSE(found.from_window);
    EXPECT_LT(max_error(found.detection.corners, back.truth), 0.5);
    const Shot next = shot(index++, 0.125, -0.05, 0.6, 15.0);
    const TrackedTag followed = tracker.track(next.frame);
    ASSERT_TRUE(followed.visible);
    EXPECT_TRUE(followed.from_window);
    EXPECT_LT(max_error(followed.detection.corners, next.truth), 0.5);
}

TEST(TagTrackerRoi, SearchesTheWholeFrameOnItsCadence) {
    TrackerConfig c = config(true);
    c.roi.full_search_every = 4;
    TagTracker tracker(c);
    for (int i = 0; i < 12; ++i) ASSERT_TRUE(tracker.track(shot(i, 0.0, 0.0, 0.5, 0.0).frame).visible);
    EXPECT_EQ(tracker.full_searches(), 3);  // frames 0, 4 and 8
}

// An empty view: the whole frame is searched in every frame for idle_after_s (1 s), then once per
// idle_search_period_s (0.1 s); a tag coming into view is found within that period, and then
// followed in every frame.
TEST(TagTrackerRoi, IdleSearchIsThrottledAndStillFindsATagComingIntoView) {
    TagTracker tracker(config(true));
    Shot empty = shot(0, 0.0, 0.0, 0.5, 0.0, true);
    const auto at = [](int index) { return static_cast<std::int64_t>(index) * 33'333'333; };  // 30 fps
    int index = 0;
    for (; index < 30; ++index) {  // up to 0.97 s: not idle yet
        empty.frame.timestamp_ns = at(index);
        ASSERT_FALSE(tracker.track(empty.frame).visible);
    }
    EXPECT_EQ(tracker.full_searches(), 30);
    for (; index < 90; ++index) {  // 1 s .. 3 s idle: a search every 0.1 s, 20 +- 1 of 60 frames
        empty.frame.timestamp_ns = at(index);
        ASSERT_FALSE(tracker.track(empty.frame).visible);
    }
    EXPECT_GE(tracker.full_searches(), 30 + 19);
    EXPECT_LE(tracker.full_searches(), 30 + 21);
    Shot tag = shot(90, 0.0, 0.0, 0.5, 0.0);
    int found_at = -1;
    for (; index < 94 && found_at < 0; ++index) {
        tag.frame.timestamp_ns = at(index);
        if (tracker.track(tag.frame).visible) found_at = index;
    }
    ASSERT_GE(found_at, 90) << "not found within 4 frames (0.13 s)";
    for (int i = 0; i < 5; ++i) {  // followed again: every frame sees it
        tag.frame.timestamp_ns = at(index++);
        EXPECT_TRUE(tracker.track(tag.frame).visible);
    }
    // Off: every frame is searched.
    TrackerConfig c = config(true);
    c.roi.idle_search_period_s = 0.0;
    TagTracker eager(c);
    for (int i = 0; i < 45; ++i) {
        empty.frame.timestamp_ns = at(i);
        (void)eager.track(empty.frame);
    }
    EXPECT_EQ(eager.full_searches(), 45);
}

TEST(TagTrackerRoi, RejectsBadSettingsNamingTheField) {
    const auto message = [](TrackerConfig c) {
        try {
            TagTracker t(c);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    TrackerConfig c = config(true);
    c.roi.margin = 0.0;
    EXPECT_EQ(message(c), "RoiSettings.margin = 0 outside (0, 5]");
    c = config(true);
    c.roi.search_decimation = 9.0f;
    EXPECT_EQ(message(c), "RoiSettings.search_decimation = 9 outside [1, 8]");
    c = config(true);
    c.roi.full_search_every = -1;
    EXPECT_EQ(message(c), "RoiSettings.full_search_every = -1 outside [0, 100000]");
    c = config(true);
    c.roi.window_tag_px = 2.0;
    EXPECT_EQ(message(c), "RoiSettings.window_tag_px = 2 outside [4, 1000]");
    c = config(true);
    c.roi.window_max_decimation = 9;
    EXPECT_EQ(message(c), "RoiSettings.window_max_decimation = 9 outside [1, 8]");
    c = config(true);
    c.roi.window_blur_sigma = 6.0f;
    EXPECT_EQ(message(c), "RoiSettings.window_blur_sigma = 6 outside [-5, 5]");
    c = config(true);
    c.roi.idle_search_period_s = -1.0;
    EXPECT_EQ(message(c), "RoiSettings.idle_search_period_s = -1 outside [0, 3600]");
}

}  // namespace
}  // namespace mogao
