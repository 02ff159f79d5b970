// SPDX-License-Identifier: Apache-2.0
// The MPCDI subcommands of mogao-calibrate (kiosk/calibrate/main.cpp; docs/calibration.md): make and inspect
// MPCDI calibration files.
//
//   mogao-calibrate ideal --projectors 3 --overlap 0.15 --projector-size 1024x768 --content 1920x1080
//                         --out ideal.mpcdi [--alpha-bits 8] [--gamma 2.2] [--check]
//   mogao-calibrate mpcdi-info FILE.mpcdi
//
// Exit codes (docs/architecture.md): 0 success, 1 the job failed (unreadable file, write failure,
// failed --check), 2 bad command line (CLI11's, during the parse: a malformed size included).
#pragma once

#include <iosfwd>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "appliance/warp/ideal_calibration.h"

namespace mogao {

struct MpcdiCommands {
    CLI::App* ideal = nullptr;  // `ideal`
    CLI::App* info = nullptr;   // `mpcdi-info`
    IdealCalibrationParams params;
    std::string projector_size = "1024x768";
    std::string content = "1920x1080";
    std::string out;
    int alpha_bits = 8;
    bool check = false;
    std::string info_path;
};

// Adds `ideal` and `mpcdi-info` to `parent`; their sizes are checked when `ideal` is parsed (CLI::ValidationError
// naming the flag).
void add_mpcdi_commands(CLI::App& parent, MpcdiCommands& cmds);

// After the parse: the exit status of the one that was given (reports on `out`, errors on `err`), or nullopt
// when neither was.
[[nodiscard]] std::optional<int> run_mpcdi_commands(const MpcdiCommands& cmds, std::ostream& out, std::ostream& err);

}  // namespace mogao
