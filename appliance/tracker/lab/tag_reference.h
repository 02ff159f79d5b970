// SPDX-License-Identifier: Apache-2.0
// An independent reference for tag corners on real photographs, where no ground truth exists:
// used only to evaluate the detector (tracking_eval, tags_real_test), never on the appliance.
//
// Two steps, neither of them AprilTag's:
//  1. Candidates from OpenCV's ArUco detector (opencv_contrib 4.6, cv::aruco::detectMarkers with
//     the DICT_APRILTAG_* dictionary of the family; Garrido-Jurado et al., "Automatic generation
//     and detection of highly reliable fiducial markers under occlusion", Pattern Recognition
//     2014): adaptive threshold, contour polygons, bit decoding -- a different quad search and
//     decoder from AprilTag's.
//  2. Sub-pixel corners by edge-line fits on the full-resolution image (refine_by_edge_lines):
//     along each side of the quad, every ~1 px the intensity profile across the edge is sampled
//     (bilinear) within +/- 0.6 cell and the edge is placed where the profile crosses the mean of
//     its dark and bright ends (the 50 % point of a blurred step: unbiased for any symmetric blur,
//     unlike a gradient maximum on a noisy profile); a least-squares line through those points,
//     two iterations re-centred on the line; corners = intersections of adjacent lines.
//
// Frames: pixel positions with pixel centres at +0.5, AprilTag corner order (tag_detector.h), so
// references compare directly with TagDetection::corners. The black square's side is
// TagFamily::border_width_cells() cells (8 for tag36h11); sampling stays within that border cell
// so the data bits inside do not pull the edge.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "appliance/tracker/tag_detector.h"
#include "drivers/camera/camera_frame.h"

namespace mogao {

using TagCorners = std::array<Eigen::Vector2d, 4>;

// ArUco candidates (step 1) with their corners refined (step 2); sorted by id. A candidate whose
// refinement fails (an edge with too few usable profiles, e.g. cut by the image border) keeps
// ArUco's own corners and has refined = false. Throws std::invalid_argument for an invalid image
// or a family ArUco has no dictionary for (only tag16h5, tag25h9, tag36h10, tag36h11).
struct ReferenceTag {
    int id = 0;
    TagCorners corners;  // pixel centres at +0.5, AprilTag order
    bool refined = false;
};
[[nodiscard]] std::vector<ReferenceTag> reference_tags(const GrayImage& image, const std::string& family);

// Step 2 alone: refines approximate corners (AprilTag order, +0.5 convention, within ~1 cell of
// the truth) of a tag whose black square is `border_cells` cells wide. nullopt when an edge has
// fewer than 4 usable profiles or two adjacent lines are nearly parallel.
[[nodiscard]] std::optional<TagCorners> refine_by_edge_lines(const GrayImage& image, const TagCorners& approx,
                                                             int border_cells);

// The four corner distances (px) between `a` and `b`, after the cyclic shift of `b` that
// minimises their sum (ArUco and AprilTag agree on ids, not necessarily on which corner is first;
// a wrong shift would be an error of a whole tag side, so the choice cannot hide a small error).
[[nodiscard]] std::array<double, 4> matched_corner_errors(const TagCorners& a, const TagCorners& b);

}  // namespace mogao
