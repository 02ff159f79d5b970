// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate-sim rig` (SIMULATION, not installed): the camera-based calibration of a virtual rig against its
// ground truth (appliance/autocal/calibrate_job.h; docs/calibration.md, "The calibrate command").
//
//   mogao-calibrate-sim rig --rig rigs/standard.toml --out DIR [--scale 0.5] [--content 1920x1080]
//                 [--alpha-bits 16] [--warp-step-px 2] [--gray-bits N] [--frames-per-pattern 1] [--no-colour]
//                 [--no-falloff] [--fit-screen] [--fit-heights] [--no-bow] [--fixed-camera-intrinsics]
//                 [--intrinsics-min-gain 0.01]
//                 [--pinhole-projectors] [--distortion-min-gain 0.01] [--max-self-check-px 0.65]
//
// Exit codes: 0 success, 1 the job failed or the calibration was refused (the message says why; nothing in DIR
// changes), 2 bad command line.
#pragma once

#include <CLI/CLI.hpp>

#include "appliance/autocal/calibrate_job.h"
#include "appliance/autocal/calibration_flags.h"

namespace mogao::calibrate {

struct RigCommand {
    CLI::App* app = nullptr;
    autocal::CalibrateJob job;
    autocal::CalibrationFlags shared;  // calibration_flags.h: the flag set the on-site job has too
    bool fixed_intrinsics = false;
};

// Adds the subcommand and its options to `parent`; the flags go into `cmd.job` when it is parsed.
void add_rig_command(CLI::App& parent, RigCommand& cmd);

// Runs a parsed subcommand: prints the self-check and the result against the rig's ground truth; 0 or 1.
[[nodiscard]] int run_rig_command(const RigCommand& cmd);

}  // namespace mogao::calibrate
