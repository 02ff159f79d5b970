// SPDX-License-Identifier: Apache-2.0
// The shipped mogao-calibrate's side of simulation_routes.h: no simulation routes (main.cpp refuses --rig and
// --camera rig:FILE before it would call them, naming mogao-calibrate-sim).
#include <stdexcept>

#include "kiosk/calibrate/simulation_routes.h"

namespace mogao::calibrate {
namespace {

[[noreturn]] void none() {
    throw std::logic_error("this mogao-calibrate has no simulation routes (mogao-calibrate-sim has)");
}

}  // namespace

bool has_simulation_routes() { return false; }

int run_rig_calibration(const autocal::CalibrateJob&) { none(); }

std::unique_ptr<CalibrationCamera> open_rig_camera(const std::filesystem::path&, double, OutputBackend&) { none(); }

void print_simulation_truth(const std::filesystem::path&, double, const std::filesystem::path&) { none(); }

}  // namespace mogao::calibrate
