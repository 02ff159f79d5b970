// SPDX-License-Identifier: Apache-2.0
// The routes of mogao-calibrate that need the virtual rig (SIMULATION, tests and benchmarks): the calibration of a
// rig file against its ground truth (--rig FILE) and the rig's camera filming the outputs (--camera rig:FILE).
// mogao-calibrate-sim links them (simulation_routes.cpp); the shipped mogao-calibrate links no_simulation.cpp,
// which has none, so that the appliance carries no simulation code (.ci/check-shipped-links). One main for both
// (main.cpp): the command line is the same, and the shipped program refuses the two routes as a usage error
// naming mogao-calibrate-sim.
#pragma once

#include <filesystem>
#include <memory>

#include "appliance/autocal/calibrate_job.h"
#include "drivers/output.h"
#include "kiosk/calibrate/calibration_camera.h"

namespace mogao::calibrate {

// Whether this program has the routes below (mogao-calibrate-sim); the others throw std::logic_error without them.
[[nodiscard]] bool has_simulation_routes();

// --rig FILE: calibrates the rig file's virtual rig (autocal::run_calibrate_job, job.rig set) and prints the
// result against the rig's ground truth. Returns the exit status (0); throws what run_calibrate_job throws.
int run_rig_calibration(const autocal::CalibrateJob& job);

// --camera rig:FILE: the rig file's camera (at `scale`) filming `outputs` (headless: their last presents; KMS:
// the kernel's scanout buffers), rig projector k lit by output k. Throws rig::RigError naming the file, or
// std::invalid_argument for another output backend.
[[nodiscard]] std::unique_ptr<CalibrationCamera> open_rig_camera(const std::filesystem::path& rig_file, double scale,
                                                                 OutputBackend& outputs);

// After a --camera rig:FILE calibration: the MPCDI written to `mpcdi` (as the kiosk reads it) against the rig's
// ground truth, in projector pixels of the rig at `scale` (autocal::measure_geometry), printed on stdout as
// "SIMULATION ground truth (rig NAME): geometry mean M p95 P px".
void print_simulation_truth(const std::filesystem::path& rig_file, double scale, const std::filesystem::path& mpcdi);

}  // namespace mogao::calibrate
