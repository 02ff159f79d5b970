// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate-sim selfcal-simulate` (SIMULATION, not installed): a self-recalibration scenario on a virtual rig
// (appliance/selfcal/rig_simulation.h; docs/calibration.md, "Self-recalibration"): bumps, noise, exposure changes,
// visitors; prints the detection time in simulated seconds at the stated monitor rate, the geometric error against
// the rig's ground truth before and after, and the CPU time per monitored frame.
//
//   mogao-calibrate-sim selfcal-simulate --rig rigs/standard.toml --bump proj1:yaw=1deg [--models FILE] ...
//
// Exit codes: 0 done, 1 failed, 2 bad flags (a malformed --bump, models of another scale included).
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "appliance/selfcal/rig_simulation.h"

namespace mogao::calibrate {

// What `selfcal-simulate` takes beyond SimulationOptions' own fields.
struct SelfcalCommand {
    CLI::App* app = nullptr;
    std::string rig;
    std::vector<std::string> bumps;
    double bump_at_s = 2.0;
    bool verbose = false;
    std::string content = "textured";
    bool no_edge_check = false;
    double prior_mm = 0.0;
    std::string models;
    selfcal::SimulationOptions o;
};

// Adds the subcommand and its options to `parent`.
void add_selfcal_command(CLI::App& parent, SelfcalCommand& cmd);

// Runs a parsed subcommand: 0 done, 1 failed, 2 a malformed --bump or starting models that do not fit the rig.
[[nodiscard]] int run_selfcal_command(SelfcalCommand cmd);

}  // namespace mogao::calibrate
