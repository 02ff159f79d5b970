// SPDX-License-Identifier: Apache-2.0
// An independent check of a decoded id on real photographs: how well each code of the family
// explains the cells of a tag, by correlation rather than by AprilTag's bit decoding. Used only to
// label the evaluation set (tags_real_manifest.json: ids a human confirmed with it) and to audit
// detections, never on the appliance.
//
// Method: the image is rectified through the homography that takes the tag's four corners to the
// corners of its black square (OpenCV getPerspectiveTransform / warpPerspective, bilinear), at
// kRankCellPx pixels per cell; the mean grey of the central half of each data cell (inside the black
// ring: (border_width_cells - 2)^2 cells, 36 for tag36h11) is taken; each hypothesis -- every code,
// in each of four rotations and mirrored or not -- is scored by the Pearson correlation of those
// means with its cells (white 1, black 0). Correlation is invariant to the tag's brightness and
// contrast, so a dark tag scores like a bright one; it weighs every cell by its measured
// contrast, where AprilTag thresholds each bit against a fitted white/black model and counts the
// bits that flip. A printed tag can never appear mirrored, so the mirrored hypotheses show the
// scores that chance alone reaches on these cells; the best of them is the null reference.
//
// Frames: corners in pixels, pixel centres at +0.5, AprilTag order (tag_detector.h). With the
// corners the detector gives for a true tag, the right code scores at rotation 0, not mirrored.
#pragma once

#include <vector>

#include "appliance/tracker/lab/tag_reference.h"
#include "appliance/tracker/tag_family.h"
#include "drivers/camera/camera_frame.h"

namespace mogao {

inline constexpr int kRankCellPx = 16;

struct CodeMatch {
    int id = 0;
    int rotation = 0;  // quarter turns of the code's cells (0 with a detection's own corner order)
    bool mirrored = false;
    double correlation = 0.0;  // Pearson, [-1, 1]
};

// Every hypothesis (codes x 4 rotations x 2 mirrorings), best first. Throws std::invalid_argument
// for an invalid image, corners that are not finite or a quad of under 4 px on a side.
[[nodiscard]] std::vector<CodeMatch> rank_codes(const GrayImage& image, const TagCorners& corners,
                                                const TagFamily& family);

}  // namespace mogao
