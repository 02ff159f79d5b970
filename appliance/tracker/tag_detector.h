// SPDX-License-Identifier: Apache-2.0
// TagDetector: AprilTag 3 detection of one family in grey images (Wang & Olson, "AprilTag 2:
// Efficient and robust fiducial detection", IROS 2016; AprilTag 3 is its successor library).
// Owns one apriltag_detector_t and its TagFamily (RAII, move-only); not thread-safe.
//
// Corner order (AprilTag's): the four corners wrap counter-clockwise as seen in the image (y
// down) when the tag is upright: corners[0] bottom-left, [1] bottom-right, [2] top-right,
// [3] top-left of the tag as printed (tag_bitmap.h), i.e. the homography maps the ideal tag
// corners (-1, 1), (1, 1), (1, -1), (-1, -1) (x right, y down) to corners[0..3].
//
// Pixel convention (AprilTag 3.3's, measured: tag_detector_test, tracker_bench): sub-pixel
// positions with the CENTRE of the top-left pixel at (0.5, 0.5), i.e. (0, 0) is the top-left
// corner of the image -- the same as mogao's frame convention (docs/architecture.md). OpenCV
// (and so the camera intrinsics) puts that centre at (0, 0): solve_tag_pose subtracts 0.5.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "appliance/tracker/detector_settings.h"
#include "appliance/tracker/tag_family.h"
#include "drivers/camera/camera_frame.h"

namespace mogao {

struct TagDetection {
    int id = 0;
    int hamming = 0;                         // bits corrected to decode
    float decision_margin = 0.0f;            // mean distance of the bit values from the threshold (AprilTag's)
    std::array<Eigen::Vector2d, 4> corners;  // pixels, AprilTag order, pixel centres at +0.5 (above)
    Eigen::Vector2d centre;                  // pixels, image of the tag centre (homography)
};

// The largest number of corrected bits (<= 2) at which a random bit pattern inside a candidate quad
// decodes to one of the family's codes, in any of 4 rotations, with probability at most 1 %:
// codes * 4 * sum_{k<=h} C(bits, k) / 2^bits (the false-positive analysis of Olson, "AprilTag: A
// robust and flexible visual fiducial system", ICRA 2011, Sec. IV). tag36h11: 2 (2.3e-5);
// tag25h9: 2 (1.4e-3); tag16h5: 0 (1.8e-3; 3.1 % at 1 bit, 25 % at 2). -1 when even an exact match
// is that likely.
[[nodiscard]] int safe_max_hamming(const TagFamily& family);

class TagDetector {
public:
    // How much of the quad search detect() runs: `full` adds DetectorSettings::coarse_pass_decimation's
    // second search when the first is at full resolution; `single` never does (a small window).
    enum class Passes { full, single };

    // Throws std::invalid_argument for bad settings (validate()) or an unknown family.
    explicit TagDetector(const DetectorSettings& settings = {});
    TagDetector(TagDetector&&) noexcept;
    TagDetector& operator=(TagDetector&&) noexcept;
    TagDetector(const TagDetector&) = delete;
    TagDetector& operator=(const TagDetector&) = delete;
    ~TagDetector();

    // Every tag of the family in `image`, sorted by id; `image` is not modified. Throws
    // std::invalid_argument for an image that is not valid() or wider/taller than
    // kMaxCaptureDimension.
    [[nodiscard]] std::vector<TagDetection> detect(const GrayImage& image, Passes passes = Passes::full);

    // Changes the quad search's decimation and blur (DetectorSettings::decimation, blur_sigma) for
    // the next detect() calls, keeping the decode tables (building those for max_hamming 2 costs
    // far more than a detection). Throws std::invalid_argument as validate(), naming the field.
    void set_quad_search(float decimation, float blur_sigma);

    [[nodiscard]] const DetectorSettings& settings() const { return settings_; }
    [[nodiscard]] const TagFamily& family() const;

private:
    std::vector<TagDetection> detect_once(const GrayImage& image);
    // detect_once with the quad search at `decimation`, no blur and `decode_sharpening`; the
    // settings' own are restored.
    std::vector<TagDetection> detect_with_quad_search(const GrayImage& image, float decimation,
                                                      double decode_sharpening);
    // The family and the detector that hangs its decode tables on it, together on the heap: the
    // family's address must not change while the detector uses it, and the detector must be
    // destroyed before the family (tag_detector.cpp). As one pointer they also move and are
    // replaced as one, so the moves are defaulted.
    struct Engine;
    DetectorSettings settings_;
    std::vector<std::uint8_t> scratch_;  // a copy of the image when AprilTag would blur it in place
    std::unique_ptr<Engine> engine_;
};

}  // namespace mogao
