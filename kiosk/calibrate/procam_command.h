// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate procam`: projector intrinsics on the bench from real captures of a chessboard lit
// by Gray code (appliance/procam/procam_job.h; docs/calibration.md, "Projector intrinsics on the
// bench"), and the bridge that hands its projector intrinsics to the on-site calibration as the
// projector's prior.
//
//   mogao-calibrate procam --pose-images DIR [DIR...] --projector-size WxH --board COLSxROWS --square-mm S
//                          --out FILE.json [--half-window-px PX] [--projector-distortion]
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "appliance/autocal/autocal.h"
#include "appliance/procam/procam_calibration.h"

namespace mogao::calibrate {

struct ProcamCommand {
    CLI::App* app = nullptr;
    std::vector<std::filesystem::path> images;
    std::string projector;
    std::string board;
    double square_mm = 0.0;
    std::filesystem::path out;
    int window_px = 24;
    bool projector_distortion = false;  // free k1, k2 (for many, varied poses; default: a pinhole)
};

// Adds the subcommand and its options to `parent`.
void add_procam_command(CLI::App& parent, ProcamCommand& cmd);

// Runs a parsed subcommand: 0 written, 1 the job failed (the message names the folder or file and
// the reason), 2 a malformed --projector-size or --board.
[[nodiscard]] int run_procam_command(const ProcamCommand& cmd);

// The on-site calibration's projector prior (appliance/autocal: CalibrationPrior::projectors, the
// data-sheet intrinsics autocal starts its projector fits from) from a procam file's projector:
// fx, fy and the principal point, moved from OpenCV's pixel centres (integer) to autocal's (+0.5)
// and scaled to the device's resolution when it is a uniform scale of the bench's (a projector run
// at half resolution). autocal models projectors as pinholes: the lens distortion is not carried
// (its effect at the image corners is in the procam report). Throws std::invalid_argument if the
// device's aspect differs from the bench's.
[[nodiscard]] autocal::DeviceModel projector_prior_from_procam(autocal::DeviceModel device,
                                                               const procam::Intrinsics& bench);

}  // namespace mogao::calibrate
