// SPDX-License-Identifier: Apache-2.0
// The calibration from a folder of captured images (`mogao-calibrate --site FILE --images DIR`):
// autocal's PatternSource (appliance/autocal/autocal.h) answered from files instead of a live
// camera. Each time the calibration shows a pattern, the source finds it in the pattern set
// (pattern_catalogue.h, by the signature of what it shows) and returns the camera image captured of
// it, as linear camera values (calibration_camera.h's camera_image, `transfer` as for a live camera).
//
// DIR/captures.json (`mogao-calibrate patterns` writes it with every id and a suggested file name):
//   {
//     "format": "mogao-calibration-captures", "version": 1,
//     "pattern_set": "<16 hex digits>",     // patterns.json's: the set the captures are of
//     "phase_periods_px": [32],             // the periods the set was written with
//     "captures": { "black": "captures/black.png",               // pattern id -> file, relative to DIR
//                   "white": ["w-1.png", "w-2.png"], ... }      // or several frames of the same pattern
//   }
// A pattern with several frames hands them out in turn (options.frames_per_pattern > 1 averages them).
// Files: PNG (8 or 16 bit, grey or colour; read_png), JPEG (.jpg, .jpeg) or binary PPM; each of the
// camera's size in the site file (scaled by --scale). The camera must have filmed every pattern with
// the same, fixed exposure, gain and white balance and from the same place.
//
// Errors (std::runtime_error, nothing is calibrated or written): a manifest that cannot be read or is
// not JSON (naming the file and the parser's message); a missing or mistyped field (naming it); a
// pattern_set other than the one the site file, scale and periods give (naming both); an id that is
// not in the set, a pattern of the set without a capture, a file that does not exist (naming the id
// and file); on use, a file that cannot be decoded or is of another size (naming the file and both
// sizes).
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "appliance/autocal/autocal.h"
#include "common/image.h"
#include "kiosk/calibrate/calibration_camera.h"
#include "kiosk/calibrate/pattern_catalogue.h"

namespace mogao::calibrate {

struct CapturesManifest {
    std::filesystem::path file;  // DIR/captures.json
    std::string pattern_set;
    std::vector<double> phase_periods_px;
    std::map<std::string, std::vector<std::filesystem::path>> captures;  // id -> files, DIR prepended
};

// Reads and checks the form of DIR/captures.json (above).
[[nodiscard]] CapturesManifest read_captures_manifest(const std::filesystem::path& folder);

// Checks `m` against the set: its signature, every id known, every pattern captured, every file
// present and, where its PNG or JPEG header tells without decoding, of the camera's size (so that a
// wrong file is named at once, not after the calibration reached it).
void check_captures(const CapturesManifest& m, const PatternCatalogue& catalogue, ImageSize camera);

// A captured image as RGB8 (the decoders' conversions, common/png_io.h). Throws std::runtime_error
// naming the file for an unknown extension or a file that cannot be decoded.
[[nodiscard]] Rgb8Image read_capture(const std::filesystem::path& file);

class ImageFolderSource final : public autocal::PatternSource {
public:
    // `catalogue` must outlive the source; `m` must have passed check_captures.
    ImageFolderSource(const PatternCatalogue& catalogue, CapturesManifest m, ImageSize camera_size,
                      CameraTransfer transfer);

    [[nodiscard]] cv::Mat1f show(const std::vector<cv::Mat>& signals) override;
    [[nodiscard]] bool exposure_locked() const override { return true; }  // the captures' exposure is fixed
    // Throws autocal::CalibrationRefused: captured images cannot follow an exposure change (the colour step).
    void set_relative_exposure(double factor) override;

    [[nodiscard]] int images() const { return images_; }
    // The capture of every projector white (after the calibration showed it; empty before).
    [[nodiscard]] const cv::Mat1f& white() const { return white_; }

private:
    const PatternCatalogue* catalogue_;
    CapturesManifest manifest_;
    ImageSize camera_size_;
    CameraTransfer transfer_;
    std::map<std::string, std::size_t> next_frame_;  // per id: the next of its files to hand out
    int images_ = 0;
    cv::Mat1f white_;
};

}  // namespace mogao::calibrate
