// SPDX-License-Identifier: Apache-2.0
// The detector's defaults on the real photographs (../shared/data/tags-real): detection rate and
// corner error against tags_real_truth.json (counts from PROVENANCE.md and its ground-truth
// files; corners from the independent ArUco + edge-line reference, tag_reference.h). Skipped (exit
// 77) with a message when the photographs are absent.
#include "appliance/tracker/lab/tags_real.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "appliance/tracker/lab/code_ranking.h"
#include "appliance/tracker/tag_detector.h"
#include "drivers/camera/image_file.h"

namespace mogao {
namespace {

// The detection-rate goal on the core set's 47 tags (>= 95 %, i.e. 45): the defaults find 45 with no
// false positive (docs/tracking.md, "Real photographs"); the two left are a ~9 px sign and a
// ~20x10 px tag seen edge-on, which nothing decodes. On the whole set the defaults find 229 of 271
// (84.5 %, no false positive; AprilTag's stock settings find 215 with 2 false tags in the tag16h5
// photograph), less a margin of about six tags; the far half of the oblique sheet is what they
// miss there (the doc says which).
constexpr double kMinRateCoreSet = 0.95;
constexpr double kMinRateAll = 0.82;
constexpr double kMaxMedianCornerErrorPx = 0.6;

TEST(TagsReal, DefaultsFindTheTagsWithAccurateCorners) {
    const auto data = tags_real_dir(MOGAO_TAGS_REAL_DIR);
    if (!std::filesystem::exists(data))
        GTEST_SKIP() << "real tag photographs not found at " << data << " (../shared/data/tags-real)";
    const auto truth =
        read_real_truth(std::filesystem::path(MOGAO_SOURCE_DIR) / "appliance/tracker/lab/tags_real_truth.json");
    SetScore all, core;
    for (const auto& t : truth) {
        auto image = read_gray_image(data / t.file);
        ASSERT_TRUE(image) << image.error().message;
        DetectorSettings settings;  // the defaults, only the family set per image
        settings.family = t.family;
        TagDetector detector(settings);
        const ImageScore s = score_image(t, detector.detect(*image));
        all.add(s);
        if (t.subset == "core") core.add(s);
    }
    EXPECT_GE(core.rate(), kMinRateCoreSet)
        << core.found << " found, " << core.false_positives << " false positives of " << core.tags;
    EXPECT_GE(all.rate(), kMinRateAll) << all.found << " found, " << all.false_positives << " false positives of "
                                       << all.tags;
    EXPECT_EQ(all.false_positives, 0) << "a wrong or repeated id, or a tag where there is none";
    EXPECT_LE(all.median_corner_error_px(), kMaxMedianCornerErrorPx);
    EXPECT_LE(core.median_corner_error_px(), kMaxMedianCornerErrorPx);
    EXPECT_GT(all.corner_errors_px.size(), 400u);  // the reference covers most found tags
}

// The correlation check that confirmed the hand-labelled id of the dark-corner tag (code_ranking.h,
// tags_real_manifest.json) agrees with ArUco on the real tags ArUco finds: at the reference's
// corners, the referenced id ranks first (in some rotation: ArUco's first corner may differ from
// AprilTag's) and never mirrored, for every one of them.
TEST(TagsReal, CorrelationRanksArucosIdsFirst) {
    const auto data = tags_real_dir(MOGAO_TAGS_REAL_DIR);
    if (!std::filesystem::exists(data))
        GTEST_SKIP() << "real tag photographs not found at " << data << " (../shared/data/tags-real)";
    const auto truth =
        read_real_truth(std::filesystem::path(MOGAO_SOURCE_DIR) / "appliance/tracker/lab/tags_real_truth.json");
    int checked = 0;
    for (const auto& t : truth) {
        const auto image = read_gray_image(data / t.file);
        ASSERT_TRUE(image) << image.error().message;
        const TagFamily family(t.family);
        for (const auto& ref : t.reference) {
            const auto ranked = rank_codes(*image, ref.corners, family);
            EXPECT_EQ(ranked.front().id, ref.id) << t.file << " at (" << ref.corners[0].transpose() << ")";
            EXPECT_FALSE(ranked.front().mirrored) << t.file << " tag " << ref.id;
            ++checked;
        }
    }
    EXPECT_GT(checked, 100);
}

TEST(TagsReal, ScoringCountsWrongIdsAndDuplicatesAgainstTheDetector) {
    RealImageTruth t;
    t.tags = 2;
    t.ids = {3, 4};
    t.reference.push_back({3, {Eigen::Vector2d(10, 30), {30, 30}, {30, 10}, {10, 10}}});
    TagDetection good;
    good.id = 3;
    good.corners = {Eigen::Vector2d(10.5, 30), {30, 30}, {30, 10}, {10, 10}};
    good.centre = {20, 20};
    TagDetection misplaced = good;  // the right id where the reference says there is no tag
    misplaced.centre = {80, 80};
    TagDetection wrong = good;
    wrong.id = 7;
    const ImageScore s = score_image(t, {good, good, wrong, misplaced});
    EXPECT_EQ(s.found, 1);
    EXPECT_EQ(s.false_positives, 3);
    ASSERT_EQ(s.corner_errors_px.size(), 4u);
    EXPECT_NEAR(s.corner_errors_px[0], 0.5, 1e-12);
    SetScore set;
    set.add(s);
    EXPECT_DOUBLE_EQ(set.rate(), (1.0 - 3.0) / 2.0);
}

}  // namespace
}  // namespace mogao
