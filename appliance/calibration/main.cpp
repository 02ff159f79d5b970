// SPDX-License-Identifier: Apache-2.0
// mogao-calibration: see calibration_cli.h.
#include <iostream>

#include "appliance/calibration/calibration_cli.h"

int main(int argc, char** argv) { return mogao::run_calibration_cli(argc, argv, std::cout, std::cerr); }
