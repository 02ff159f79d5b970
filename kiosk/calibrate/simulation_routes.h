// SPDX-License-Identifier: Apache-2.0
// The routes of mogao-calibrate that need the virtual rig (SIMULATION, tests and benchmarks): the subcommands `rig`
// (the calibration of a rig file against its ground truth, rig_command.h) and `selfcal-simulate` (self-recalibration
// on a rig, selfcal_command.h), and the rig's camera filming the outputs (--camera rig:FILE).
// mogao-calibrate-sim links them (simulation_routes.cpp); the shipped mogao-calibrate links no_simulation.cpp,
// which has none, so that the appliance carries no simulation code (.ci/check-shipped-links). One main for both
// (main.cpp): the command line is the same, and the shipped program refuses the routes as a usage error (exit 2)
// naming mogao-calibrate-sim.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>

#include "drivers/output.h"
#include "kiosk/calibrate/calibration_camera.h"

namespace mogao::calibrate {

// Whether this program has the routes below (mogao-calibrate-sim); the others throw std::logic_error without them.
[[nodiscard]] bool has_simulation_routes();

// The program's name: mogao-calibrate-sim or mogao-calibrate.
[[nodiscard]] const char* program_name();

// The simulation subcommands' state (defined where they are: simulation_routes.cpp or no_simulation.cpp).
struct SimulationCommands;

// Adds `rig` and `selfcal-simulate` to `app`: mogao-calibrate-sim's, or in the shipped program hidden ones that
// refuse during the parse (CLI::ValidationError naming mogao-calibrate-sim).
[[nodiscard]] std::shared_ptr<SimulationCommands> add_simulation_commands(CLI::App& app);

// After the parse: the exit status of the simulation subcommand that ran, or nullopt when none was given.
[[nodiscard]] std::optional<int> run_simulation_commands(const SimulationCommands& cmds);

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
