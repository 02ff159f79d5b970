// SPDX-License-Identifier: Apache-2.0
// Region-of-interest tracking in TagTracker against synthetic truth (synthetic_view.h) and against
// whole-frame detection of the same frames.
#include "appliance/tracker/tag_tracker.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "appliance/tracker/synthetic_view.h"
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

TEST(TagTrackerRoi, FollowsAMovingTagInTheWindowAndMatchesWholeFrameDetection) {
    TrackerConfig c = config(true);
    c.roi.full_search_every = 0;  // only when lost: every frame after the first must come from the window
    TagTracker roi(c);
    TagTracker full(config(false));
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
        EXPECT_LT(max_error(a.detection.corners, s.truth), 0.5) << "frame " << i;
        // The same full-resolution detector on a crop: the same corners up to AprilTag's own
        // crop-dependent thresholding (tiles of 4 px aligned to the crop's origin). Frame 0 comes
        // from the decimated whole-frame search: within the truth tolerance only.
        if (i > 0) {
            EXPECT_LT(max_error(a.detection.corners, b.detection.corners), 0.15) << "frame " << i;
        }
    }
    EXPECT_EQ(roi.full_searches(), 1);
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
}

}  // namespace
}  // namespace mogao
