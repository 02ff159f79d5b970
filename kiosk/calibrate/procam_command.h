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
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "appliance/autocal/autocal.h"
#include "appliance/procam/procam_calibration.h"
#include "appliance/rig/rig_model.h"

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

// A procam file's projector as the calibration's bench lens (appliance/autocal's BenchLens, which
// with_bench_lenses puts into the prior in place of the data sheet's): the principal point moved from OpenCV's
// pixel centres (integer) to autocal's (+0.5); focal lengths and distortion as measured, at the bench's size.
[[nodiscard]] autocal::BenchLens bench_lens_from_procam(const procam::Intrinsics& bench, std::string source);

// The bench lenses a rig or site file names (projectors[k].procam, already resolved by rig::load_rig), each read
// with procam::read_procam_projector: one entry per projector, empty where none is named. Throws
// std::runtime_error naming `file`'s field (projectors[k].procam) and the procam file's own error.
[[nodiscard]] std::vector<std::optional<autocal::BenchLens>> bench_lenses_of(const rig::VirtualRig& rig,
                                                                             const std::string& file);

}  // namespace mogao::calibrate
