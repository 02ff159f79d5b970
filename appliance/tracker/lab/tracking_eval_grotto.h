// SPDX-License-Identifier: Apache-2.0
// The rendered grotto set's description, SETDIR/set.json, as bench/tracking-grotto/make-grotto-set
// writes it (docs/tracking.md, "Rendered grotto set"): the camera, the tag, and per frame its
// ray-traced sub-frames and the exact corners of the tag's black square. Evaluation only.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "appliance/tracker/camera_intrinsics.h"

namespace mogao::eval {

struct GrottoFrame {
    std::string variant;                           // "room" or "dim" (the room's light, or the dimmed hall)
    int index = 0;                                 // within the variant's sequence
    double time_s = 0.0;                           // of the sequence, mid-exposure
    std::vector<std::filesystem::path> subframes;  // absolute paths of the sub-frames' PPMs
    // The black square's corners at mid-exposure: pixels, pixel centres at +0.5 (the renderer's
    // pinhole and AprilTag's convention), AprilTag order.
    std::array<Eigen::Vector2d, 4> corners;
    double gain = 1.0;  // the camera's gain applied in the develop step
    std::uint64_t noise_seed = 0;
    double blur_px = 0.0;     // the tag centre's image motion over the exposure
    double distance_m = 0.0;  // of the tag's centre along the optical axis
    double exposure_ms = 0.0;
};

struct GrottoSet {
    std::filesystem::path folder;
    CameraIntrinsics camera;  // OpenCV convention (pixel centre at 0), no distortion
    double tag_size_m = 0.10;
    int tag_id = 0;
    std::string family;
    double fps = 10.0;
    std::vector<GrottoFrame> frames;
    // SETDIR/frames/<variant>-NNNN.jpg: the developed frame (run_grotto_develop writes it).
    [[nodiscard]] std::filesystem::path developed(const GrottoFrame& frame) const;
};

struct GrottoSetError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Throws GrottoSetError naming the file and the field.
[[nodiscard]] GrottoSet read_grotto_set(const std::filesystem::path& folder);

}  // namespace mogao::eval
