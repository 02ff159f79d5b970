// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate-sim rig`: the camera-based calibration of a virtual rig (rigs/*.toml) from
// patterns to files (docs/calibration.md, "The calibrate command"): writes into the output folder
//   calibration.mpcdi  the ScreenCalibration as a 2d-profile MPCDI file (appliance/calibration's
//                      writer, atomic; 16-bit alpha by default; with the colour step, 16-bit RGB
//                      beta maps and the ResponseLUT extension entries),
//   calibration.models.json  the fitted screen, camera and projector models (model_store.h),
//                      written atomically just before the MPCDI: self-recalibration's starting point,
//   report.json        the knobs (max_gray_bits, frames_per_pattern, warp_step_px), captures
//                      (geometry_captures: the geometric step's alone), timing (compute_s: the
//                      calibration's wall seconds without the rig's camera simulation), per projector: decoded bits,
//                      correspondences, reprojection rms (the fit's own residual), view angle, camera coverage, the
//                      blend's predicted seam (max |sum of weights - 1| over the overlaps from the fitted models), and
//                      the accuracy against the rig's ground truth (geometry in projector pixels, luminance), clearly
//                      apart; with the colour step, the measured responses, blacks and gains ("colour") and the seams
//                      before and after it at black, dark, mid-grey and white content
//                      (ground_truth.seams_before_colour, .seams),
//                      "self_check": the on-site figure without ground truth (self_check.h: the marks' error
//                      in projector pixels, mean / p95 / max, in mm, through the calibration's own camera, marks
//                      found, shown and too steep, the frame fit) beside "ground_truth" (the rig's truth,
//                      computed apart and never given to the check),
//   preview.png        the screen as a viewer sees it (ground-truth light paths, the rig's
//                      responses and black levels, mean of the channels): a white field with a
//                      content grid every 1/16 of the frame (lines two preview pixels or three of the
//                      coarsest projector's wide, each projector pixel showing the content's mean over its
//                      extent), linear light -> gamma 2.2, 8 bits.
//   self-check.png     the self-check's marks as the camera saw them (grey), each found mark's centroid
//                      (green) and where its content belongs through the check's camera (red cross), 2x.
// A refused calibration (CalibrationRefused, the self-check's gate included) writes nothing: whatever the
// folder held stays.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "appliance/autocal/calibration_settings.h"

namespace mogao::autocal {

// The settings (calibration_settings.h: scale, content, alpha bits, options, colour, self-check) and where.
struct CalibrateJob : CalibrationSettings {
    std::filesystem::path rig;  // rigs/*.toml
    std::filesystem::path out;  // folder, created if missing
    // The rig camera's frames dropped after each pattern change (RigPatternSource), [0, 30]: a rig whose camera
    // straddles the flips (camera.straddle) is refused at 0 and calibrates with 1, as a site's camera with its
    // settle time and dropped frames.
    int drop_frames = 0;
    // The ground truth's seams with the rig's projector defocus (projector_footprint.h: each pixel's light spread
    // by its aperture and the lens's blur_px), as the screen shows it and the rig's camera films it; false: each
    // projector pixel's light as a sharp step, a screen no defocused rig has (--sharp-truth, for comparison).
    bool defocused_truth = true;
    // The seam figures at each content level (report.json's ground_truth.seams) on a grid of a point per projector
    // pixel (pixel_dense_seam_grid), which a line one pixel wide cannot fall between; false: the 401 x 101 grid, 8 to
    // 16 projector pixels apart on a wide rig (about a minute faster on a full-resolution defocused rig, blind to
    // such a line; --coarse-seams).
    bool dense_seams = true;
    // Per projector (the rig file's order), its lens measured on the bench where the rig names a procam file
    // (projectors[k].procam; kiosk/calibrate/procam_command.h reads them): the prior's intrinsics then
    // (with_bench_lenses). Empty: the data sheets'.
    std::vector<std::optional<BenchLens>> bench_lenses;
};

// Runs the job; returns the report (also written as report.json). Throws rig::RigError,
// CalibrationRefused (nothing written), MpcdiError or std::runtime_error naming the file.
nlohmann::json run_calibrate_job(const CalibrateJob& job);

}  // namespace mogao::autocal
