// SPDX-License-Identifier: Apache-2.0
// The shipped mogao-calibrate's side of simulation_routes.h: no simulation routes. `rig` and `selfcal-simulate` are
// hidden subcommands refused during the parse, and main.cpp refuses --camera rig:FILE before it would call the rig's
// camera, each naming mogao-calibrate-sim (exit 2).
#include <stdexcept>

#include "kiosk/calibrate/simulation_routes.h"

namespace mogao::calibrate {
namespace {

[[noreturn]] void none() {
    throw std::logic_error("this mogao-calibrate has no simulation routes (mogao-calibrate-sim has)");
}

}  // namespace

struct SimulationCommands {};

bool has_simulation_routes() { return false; }

const char* program_name() { return "mogao-calibrate"; }

std::shared_ptr<SimulationCommands> add_simulation_commands(CLI::App& app) {
    for (const char* name : {"rig", "selfcal-simulate"}) {
        CLI::App* refused = app.add_subcommand(name, "");
        refused->group("");  // not in --help
        refused->allow_extras();
        refused->parse_complete_callback([name] {
            throw CLI::ValidationError(
                name, "is simulation: mogao-calibrate-sim has it (built with the tests, not installed)");
        });
    }
    return std::make_shared<SimulationCommands>();
}

std::optional<int> run_simulation_commands(const SimulationCommands&) { return std::nullopt; }

std::unique_ptr<CalibrationCamera> open_rig_camera(const std::filesystem::path&, double, OutputBackend&) { none(); }

void print_simulation_truth(const std::filesystem::path&, double, const std::filesystem::path&) { none(); }

}  // namespace mogao::calibrate
