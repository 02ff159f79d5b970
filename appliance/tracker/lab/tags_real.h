// SPDX-License-Identifier: Apache-2.0
// The real-photograph evaluation set (../shared/data/tags-real, its PROVENANCE.md): what is in
// each image and how a detector's output is scored against it. Used by tracking_eval and
// tags_real_test only; the images are never copied into the repository.
//
// Truth file (appliance/tracker/lab/tags_real_truth.json, written by `mogao_tracking_eval reference`
// from the hand-written manifest appliance/tracker/lab/tags_real_manifest.json):
//   {"images": [{"file", "family", "tags" (tags present, >= 1), "count_source", "ids" (the ids that
//     may be present, e.g. a whole printed grid of which only "tags" are in view), "ids_source",
//     "subset" ("core" for the 47 tags of the sw mapping and hallway, dt, jl and wpi images, the
//     set the detection-rate goal is stated on; else "extra"),
//     "reference": [{"id", "corners": [[x, y] x 4]}] (independent reference corners, tag_reference.h;
//     pixel centres at +0.5)}]}
//
// Scoring one image (score_image): a detection is a true positive when its id is in "ids", not
// already matched in this image, and (where a reference exists for the id) its centre lies within
// half a tag side of the reference's centre; every other detection is a false positive (a wrong
// id, a duplicate, or a tag where there is none). found = true positives, at most "tags". Corner
// errors: the four distances to the reference's corners (matched_corner_errors).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "appliance/tracker/lab/tag_reference.h"
#include "appliance/tracker/tag_detector.h"

namespace mogao {

struct RealReference {
    int id = 0;
    TagCorners corners;
};

struct RealImageTruth {
    std::string file;  // relative to the data folder
    std::string family = "tag36h11";
    int tags = 0;
    std::string count_source;
    std::vector<int> ids;
    std::string ids_source;
    std::string subset = "extra";
    std::vector<RealReference> reference;
};

// Throws std::runtime_error naming the file and the field (missing, wrong type, tags < 1, a
// reference without 4 corners).
[[nodiscard]] std::vector<RealImageTruth> read_real_truth(const std::filesystem::path& path);
void write_real_truth(const std::filesystem::path& path, const std::vector<RealImageTruth>& images);

struct ImageScore {
    int tags = 0;
    int found = 0;
    int false_positives = 0;
    std::vector<double> corner_errors_px;  // 4 per true positive with a reference
};
[[nodiscard]] ImageScore score_image(const RealImageTruth& truth, const std::vector<TagDetection>& detections);

struct SetScore {
    int tags = 0;
    int found = 0;
    int false_positives = 0;
    std::vector<double> corner_errors_px;
    void add(const ImageScore& s);
    // (found - false_positives) / tags: a false positive cancels a found tag.
    [[nodiscard]] double rate() const;
    [[nodiscard]] double median_corner_error_px() const;  // NaN without corner errors
};

// The folder of the real photographs: $MOGAO_TAGS_REAL_DIR if set, else `fallback` (the build's
// MOGAO_TAGS_REAL_DIR, <source>/../shared/data/tags-real).
[[nodiscard]] std::filesystem::path tags_real_dir(const std::filesystem::path& fallback);

}  // namespace mogao
