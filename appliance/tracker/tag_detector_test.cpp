// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/tag_detector.h"

#include <gtest/gtest.h>

#include <optional>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "appliance/tracker/lab/synthetic_view.h"

namespace mogao {
namespace {

// One detection of `id` in a view of the tag at `pose`; its corners against the truth.
struct Seen {
    bool found = false;
    double max_corner_error_px = 0.0;
};

Seen look(TagDetector& detector, int id, const TagPose& pose, const RenderEffects& fx = {}) {
    const CameraIntrinsics cam = ideal_camera();
    const double size = 0.1;
    const GrayImage image = render_target(tag_target(make_tag_bitmap(detector.family(), id), size), pose, cam, fx);
    const auto truth = project_tag_corners(pose, cam, size);
    Seen seen;
    for (const TagDetection& d : detector.detect(image)) {
        if (d.id != id) continue;
        seen.found = true;
        for (std::size_t k = 0; k < 4; ++k) {
            seen.max_corner_error_px = std::max(seen.max_corner_error_px, (d.corners[k] - truth[k]).norm());
        }
    }
    return seen;
}

TEST(TagDetector, GeneratedTagsDecodeToTheirIdInEveryFamilyLayout) {
    for (const auto& [family, id] : {std::pair<const char*, int>{"tag36h11", 0},
                                     {"tag36h11", 586},
                                     {"tag25h9", 3},
                                     {"tag16h5", 7},
                                     {"tagStandard41h12", 5}}) {
        DetectorSettings s;
        s.family = family;
        TagDetector detector(s);
        EXPECT_TRUE(look(detector, id, tag_pose_facing_camera(0.45, 10.0, -8.0, 20.0)).found) << family << " id " << id;
    }
}

// Corner order and pixel convention: AprilTag's corners, compared with the ground truth projected
// in the documented order and with pixel centres at +0.5, agree to a small fraction of a pixel at
// any roll. A wrong order (a roll by one corner) would be off by the tag's side, a wrong
// convention by 0.7 px.
TEST(TagDetector, CornersFollowAprilTagOrderAndHalfPixelConvention) {
    TagDetector detector;
    for (double roll : {0.0, 37.0, 90.0, -135.0}) {
        const Seen s = look(detector, 42, tag_pose_facing_camera(0.5, 12.0, 6.0, roll, 0.03, -0.02));
        ASSERT_TRUE(s.found) << "roll " << roll;
        EXPECT_LT(s.max_corner_error_px, 0.2) << "roll " << roll;
    }
}

TEST(TagDetector, SeventyDegreeTiltAndNoiseAreStillDetected) {
    TagDetector detector;
    EXPECT_TRUE(look(detector, 1, tag_pose_facing_camera(0.35, 70.0)).found);
    RenderEffects noisy;
    noisy.noise_sigma = 8.0;
    const Seen s = look(detector, 2, tag_pose_facing_camera(0.6, -20.0), noisy);
    EXPECT_TRUE(s.found);
    EXPECT_LT(s.max_corner_error_px, 0.6);
}

// AprilTag 3.3 blurs its input in place when it does not decimate; the detector must not let it
// (found when a benchmark's images changed between two runs).
TEST(TagDetector, NeverModifiesTheImage) {
    const GrayImage image = render_target(tag_target(make_tag_bitmap(TagFamily("tag36h11"), 9), 0.1),
                                          tag_pose_facing_camera(0.5, 10.0), ideal_camera());
    for (const float decimation : {1.0f, 2.0f}) {
        for (const float blur : {0.0f, 0.8f, -0.8f}) {
            DetectorSettings s;
            s.decimation = decimation;
            s.blur_sigma = blur;
            TagDetector detector(s);
            GrayImage copy = image;
            EXPECT_EQ(detector.detect(copy).size(), 1U) << decimation << " " << blur;
            EXPECT_EQ(copy.pixels, image.pixels) << "decimation " << decimation << " blur " << blur;
        }
    }
}

// set_quad_search switches decimation and blur on the same detector: each setting behaves as a
// detector built with it (the image is still never modified), and a bad value is refused, naming
// the field, with the settings left as they were.
TEST(TagDetector, QuadSearchCanBeSwitchedInPlace) {
    const GrayImage image = render_target(tag_target(make_tag_bitmap(TagFamily("tag36h11"), 9), 0.1),
                                          tag_pose_facing_camera(0.5, 10.0), ideal_camera());
    TagDetector switched;
    for (const float decimation : {2.0f, 1.0f, 3.0f}) {
        for (const float blur : {0.0f, 0.8f}) {
            switched.set_quad_search(decimation, blur);
            EXPECT_EQ(switched.settings().decimation, decimation);
            EXPECT_EQ(switched.settings().blur_sigma, blur);
            DetectorSettings s;
            s.decimation = decimation;
            s.blur_sigma = blur;
            TagDetector fresh(s);
            GrayImage copy = image;
            const auto a = switched.detect(copy);
            const auto b = fresh.detect(image);
            EXPECT_EQ(copy.pixels, image.pixels) << decimation << " " << blur;
            ASSERT_EQ(a.size(), 1U) << decimation << " " << blur;
            ASSERT_EQ(b.size(), 1U) << decimation << " " << blur;
            for (std::size_t k = 0; k < 4; ++k)
                EXPECT_EQ(a[0].corners[k], b[0].corners[k]) << decimation << " " << blur;
        }
    }
    try {
        switched.set_quad_search(9.0f, 0.0f);
        FAIL() << "expected invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()), "DetectorSettings.decimation = 9 outside [1, 8]");
    }
    EXPECT_THROW(switched.set_quad_search(1.0f, 6.0f), std::invalid_argument);
    EXPECT_EQ(switched.settings().decimation, 3.0f);
    EXPECT_EQ(switched.settings().blur_sigma, 0.8f);
}

TEST(TagDetector, NothingInAFlatImage) {
    TagDetector detector;
    EXPECT_TRUE(detector.detect(GrayImage(320, 240, 128)).empty());
}

static_assert(!std::is_copy_constructible_v<TagDetector> && std::is_nothrow_move_constructible_v<TagDetector> &&
              std::is_nothrow_move_assignable_v<TagDetector>);
static_assert(!std::is_copy_constructible_v<TagFamily> && std::is_nothrow_move_constructible_v<TagFamily> &&
              std::is_nothrow_move_assignable_v<TagFamily>);

TEST(TagDetector, MovedDetectorStillWorks) {
    DetectorSettings s;
    s.family = "tag25h9";
    TagDetector a(s);
    const TagFamily* family = &a.family();
    TagDetector b;     // tag36h11
    b = std::move(a);  // the old tag36h11 detector is destroyed before its family (ASan checks)
    EXPECT_EQ(b.family().name(), "tag25h9");
    EXPECT_EQ(&b.family(), family);  // the detector's family did not move in memory
    EXPECT_TRUE(look(b, 4, tag_pose_facing_camera(0.5, 0.0)).found);
    std::optional<TagDetector> c(std::move(b));
    TagDetector d = std::move(*c);
    c.reset();  // the moved-from detector releases nothing
    EXPECT_TRUE(look(d, 4, tag_pose_facing_camera(0.5, 0.0)).found);
}

TEST(TagFamily, MoveLeavesTheSourceEmptyAndKeepsTheTable) {
    std::optional<TagFamily> a(std::in_place, "tag25h9");
    apriltag_family* table = a->get();
    ASSERT_NE(table, nullptr);
    TagFamily b = std::move(*a);
    EXPECT_EQ(a->get(), nullptr);  // NOLINT(bugprone-use-after-move)
    EXPECT_EQ(b.get(), table);
    a.reset();  // destroys nothing
    EXPECT_EQ(b.code_count(), 35);
    TagFamily c("tag16h5");
    c = std::move(b);             // frees tag16h5's table, takes tag25h9's
    EXPECT_EQ(b.get(), nullptr);  // NOLINT(bugprone-use-after-move)
    EXPECT_EQ(c.get(), table);
    EXPECT_EQ(c.name(), "tag25h9");
    EXPECT_EQ(c.code_count(), 35);
}

TEST(TagDetector, BadSettingsAndImagesNameTheProblem) {
    DetectorSettings s;
    s.decimation = 0.5f;
    try {
        TagDetector d(s);
        FAIL() << "expected invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("DetectorSettings.decimation = 0.5 outside [1, 8]"), std::string::npos)
            << e.what();
    }
    s = {};
    s.max_hamming = 3;
    EXPECT_THROW(TagDetector{s}, std::invalid_argument);
    s = {};
    s.family = "tag37h11";
    EXPECT_THROW(TagDetector{s}, std::invalid_argument);
    s = {};
    s.coarse_pass_decimation = 1.0f;  // 0 (none) or [1.5, 8]
    EXPECT_THROW(TagDetector{s}, std::invalid_argument);
    s.coarse_pass_decimation = 0.0f;
    EXPECT_NO_THROW(TagDetector{s});
    s.max_line_fit_mse = 0.0f;
    EXPECT_THROW(TagDetector{s}, std::invalid_argument);
    s = {};
    s.upsample_pass_sharpening = 1.5;
    try {
        TagDetector d(s);
        FAIL() << "expected invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("DetectorSettings.upsample_pass_sharpening = 1.5 outside [0, 1]"),
                  std::string::npos)
            << e.what();
    }

    TagDetector detector;
    GrayImage broken(10, 10);
    broken.pixels.resize(5);
    EXPECT_THROW((void)detector.detect(broken), std::invalid_argument);
    EXPECT_THROW((void)detector.detect(GrayImage{}), std::invalid_argument);
}

// Olson 2011's false-accept probability of a random pattern, at most 1 %: tag16h5 (30 codes of 16
// bits) affords no corrected bit (3.1 % at 1), tag36h11 (587 codes of 36 bits) and tag25h9 the 2
// that max_hamming allows.
TEST(TagDetector, SafeHammingFollowsTheFamilysSize) {
    EXPECT_EQ(safe_max_hamming(TagFamily("tag16h5")), 0);
    EXPECT_EQ(safe_max_hamming(TagFamily("tag25h9")), 2);
    EXPECT_EQ(safe_max_hamming(TagFamily("tag36h11")), 2);
}

// The coarse pass adds tags, never removes or repeats one: on a clean synthetic tag both passes
// find it once, at the same corners.
TEST(TagDetector, CoarsePassAddsNoDuplicate) {
    TagDetector detector;
    const GrayImage image = render_target(tag_target(make_tag_bitmap(detector.family(), 36), 0.1),
                                          tag_pose_facing_camera(0.5, 15.0, -5.0, 10.0), ideal_camera(), {});
    const auto both = detector.detect(image);
    const auto single = detector.detect(image, TagDetector::Passes::single);
    ASSERT_EQ(both.size(), 1u);
    ASSERT_EQ(single.size(), 1u);
    for (std::size_t k = 0; k < 4; ++k) EXPECT_LT((both[0].corners[k] - single[0].corners[k]).norm(), 1e-9);
}

// The up-sampled search (DetectorSettings::upsample_pass_factor) finds tags of about 10 px that the
// full-resolution and coarse searches miss, with the right id and corners scaled back to the image
// (against the projected truth); it adds nothing wrong, and it does not run on images over
// upsample_pass_max_pixels.
TEST(TagDetector, UpsampledPassFindsTinyTagsTheOtherPassesMiss) {
    DetectorSettings without;
    without.upsample_pass_factor = 0;
    DetectorSettings too_big;  // the pass is on, but the frame has more pixels than it allows
    too_big.upsample_pass_max_pixels = 640 * 480 - 1;
    TagDetector with_pass, without_pass(without), limited(too_big);
    const CameraIntrinsics camera = ideal_camera(640, 480, 500.0);
    int found_with = 0, found_without = 0, found_limited = 0;
    for (int i = 0; i < 8; ++i) {
        const int id = 11 + 37 * i;
        RenderEffects fx;
        fx.clutter_seed = 5 + static_cast<std::uint64_t>(i);
        fx.noise_sigma = 2.0;
        fx.seed = 100 + static_cast<std::uint64_t>(i);
        fx.motion_blur_px = 1.0;
        fx.motion_blur_deg = 30.0 * i;
        // 0.1 m at 5 m and f = 500 px: 10 px across, turned 20 degrees.
        const TagPose pose = tag_pose_facing_camera(5.0, 20.0, -10.0, 40.0 * i, 0.3 * (i % 3 - 1), 0.2 * (i % 2));
        const GrayImage image =
            render_target(tag_target(make_tag_bitmap(with_pass.family(), id), 0.1), pose, camera, fx);
        const auto truth = project_tag_corners(pose, camera, 0.1);
        for (const auto& d : with_pass.detect(image)) {
            ASSERT_EQ(d.id, id) << "frame " << i;
            for (std::size_t k = 0; k < 4; ++k) EXPECT_LT((d.corners[k] - truth[k]).norm(), 1.0) << "frame " << i;
            ++found_with;
        }
        for (const auto& d : without_pass.detect(image)) found_without += d.id == id ? 1 : 100;
        for (const auto& d : limited.detect(image)) found_limited += d.id == id ? 1 : 100;
    }
    EXPECT_GE(found_with, found_without + 3) << "with " << found_with << ", without " << found_without;
    EXPECT_EQ(found_limited, found_without);
}

// The up-sampled search decodes with its own sharpening, then gives the detector its own back: a
// single pass after a full detect() decodes exactly as on a fresh detector (decision margins depend
// on the sharpening).
TEST(TagDetector, UpsampledPassRestoresTheDecodeSharpening) {
    DetectorSettings s;
    s.decode_sharpening = 0.0;
    s.upsample_pass_sharpening = 1.0;
    TagDetector used(s), fresh(s);
    const CameraIntrinsics camera = ideal_camera(640, 480, 500.0);
    RenderEffects fx;
    fx.noise_sigma = 2.0;
    const GrayImage image = render_target(tag_target(make_tag_bitmap(used.family(), 5), 0.1),
                                          tag_pose_facing_camera(1.5, 20.0, -10.0, 0.0, 0.0, 0.0), camera, fx);
    ASSERT_FALSE(used.detect(image).empty());
    const auto after = used.detect(image, TagDetector::Passes::single);
    const auto reference = fresh.detect(image, TagDetector::Passes::single);
    ASSERT_EQ(after.size(), 1u);
    ASSERT_EQ(reference.size(), 1u);
    EXPECT_EQ(after[0].decision_margin, reference[0].decision_margin);
}

}  // namespace
}  // namespace mogao
