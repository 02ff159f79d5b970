// SPDX-License-Identifier: Apache-2.0
// mogao-calibrate: the calibration program (docs/on-site-calibration.md, docs/calibration.md). Subcommands:
//   [site]             the on-site job, the default: patterns on the outputs filmed by a camera, or captured
//                      images, into the MPCDI the kiosk loads (site_command.h)
//   patterns           the patterns as files for any camera to capture (patterns_command.h)
//   procam             projector intrinsics on the bench from Gray-code captures of a board (procam_command.h)
//   camera-intrinsics  a camera's intrinsics from chessboard photos (camera_intrinsics_command.h)
//   ideal, mpcdi-info  an ideal MPCDI; what an MPCDI holds (appliance/calibration/calibration_cli.h)
// mogao-calibrate-sim, the same program with the virtual rig (SIMULATION, not installed; simulation_routes.h), also:
//   rig                a virtual rig calibrated against its ground truth (rig_command.h)
//   selfcal-simulate   self-recalibration on a virtual rig (selfcal_command.h)
// Exit codes: 0 success, 1 refused or failed (the message says why), 2 bad command line.
#include <iostream>

#include <CLI/CLI.hpp>

#include "appliance/calibration/calibration_cli.h"
#include "common/program_cli.h"
#include "kiosk/calibrate/camera_intrinsics_command.h"
#include "kiosk/calibrate/patterns_command.h"
#include "kiosk/calibrate/procam_command.h"
#include "kiosk/calibrate/simulation_routes.h"
#include "kiosk/calibrate/site_command.h"

int main(int argc, char** argv) {
    using namespace mogao::calibrate;
    CLI::App app{
        "Camera-based calibration of the projector wall (docs/on-site-calibration.md): the on-site job by "
        "default (`site`), or a subcommand"};
    mogao::cli::prepare(app, program_name());
    SiteCommand site;
    add_site_command(app, site);
    PatternsCommand patterns;
    add_patterns_command(app, patterns);
    ProcamCommand procam;
    add_procam_command(app, procam);
    CameraIntrinsicsCommand intrinsics;
    add_camera_intrinsics_command(app, intrinsics);
    mogao::MpcdiCommands mpcdi;
    add_mpcdi_commands(app, mpcdi);
    const auto simulation = add_simulation_commands(app);
    try {
        app.parse(argc, argv);
        if (patterns.app->parsed()) return run_patterns_command(patterns);
        if (procam.app->parsed()) return run_procam_command(procam);
        if (intrinsics.app->parsed()) return run_camera_intrinsics_command(intrinsics);
        if (const auto status = run_mpcdi_commands(mpcdi, std::cout, std::cerr)) return *status;
        if (const auto status = run_simulation_commands(*simulation)) return *status;
        check_site_command(site);
    } catch (const CLI::ParseError& e) {
        return mogao::cli::exit_status(app, e);
    }
    return run_site_command(site);
}
