// SPDX-License-Identifier: Apache-2.0
// AprilTag 3 detector settings, with the defaults mogao uses for an 800x600 camera.
//
// The defaults come from the speed/accuracy sweep of tracker_bench (docs/tracking.md, "Detector
// settings"): decimation 2 runs the quad search on a quarter of the pixels; a 0.8 px blur before
// it keeps tags of ~20 px detectable (without it, aliasing of the decimated image loses about one
// in six of them), and refine_edges fits the corners on the full-resolution image afterwards, so
// the corners are as accurate as at full resolution. Together: about half the time of full
// resolution, with the same detection rate and corner error.
#pragma once

#include <string>

namespace mogao {

struct DetectorSettings {
    std::string family = "tag36h11";  // see tag_family.h
    // apriltag_detector_t::quad_decimate: the quad search runs on an image decimated by this factor
    // (1 = full resolution). [1, 8]. The decoded bits and refined corners still use full resolution.
    float decimation = 2.0f;
    // quad_sigma: Gaussian blur (pixels, standard deviation) before the quad search; 0 = none,
    // negative = sharpen (AprilTag's convention). [-5, 5].
    float blur_sigma = 0.8f;
    // refine_edges: snap each quad edge to the strongest full-resolution gradient. Needed for
    // accurate corners when decimation > 1.
    bool refine_edges = true;
    // qtp.min_white_black_diff: the adaptive threshold ignores tiles whose max - min grey is below
    // this (flat regions). Lower finds low-contrast tags, at more candidate quads. [0, 255].
    int min_white_black_diff = 5;
    // decode_sharpening: sharpening of the sampled bit values, helps small tags. [0, 1].
    double decode_sharpening = 0.25;
    // Bits corrected when decoding; 2 tolerates a finger over two data cells of tag36h11 (minimum
    // Hamming distance 11) at no measurable false-positive rate. [0, 2]: AprilTag's decode table
    // for 3 bits takes hundreds of megabytes.
    int max_hamming = 2;
    // Worker threads of the detector. 1 on the appliance (the other core renders). [1, 64].
    int threads = 1;
};

// Throws std::invalid_argument naming the field, its value and its limit (the ranges above).
void validate(const DetectorSettings& settings);

}  // namespace mogao
