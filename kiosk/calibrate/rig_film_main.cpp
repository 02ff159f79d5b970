// SPDX-License-Identifier: Apache-2.0
// mogao-rig-film: the virtual rig as the technician's camera for the captured-images route, and the
// ground truth of the result (rig_film.h). SIMULATION; test and documentation side, not installed.
//
//   mogao-rig-film film --rig rigs/standard.toml --scale 0.25 --patterns DIR
//   mogao-rig-film measure --rig rigs/standard.toml --scale 0.25 --mpcdi OUT/calibration.mpcdi
//
// Exit codes: 0 done, 1 failed (the message names the file), 2 bad command line.
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "appliance/autocal/calibration_flags.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/rig/rig_file.h"
#include "common/program_cli.h"
#include "kiosk/calibrate/rig_film.h"

int main(int argc, char** argv) {
    using namespace mogao;
    CLI::App app{
        "SIMULATION: a virtual rig films the written calibration patterns, or measures an MPCDI against its "
        "ground truth (docs/on-site-calibration.md)"};
    cli::prepare(app, "mogao-rig-film");
    std::filesystem::path rig_file;
    std::filesystem::path patterns;
    std::filesystem::path mpcdi;
    double scale = 1.0;
    app.add_option("--rig", rig_file, "Virtual rig (rigs/*.toml)")->required()->check(CLI::ExistingFile);
    autocal::add_scale_flag(app, scale);
    auto* film = app.add_subcommand("film", "Film every pattern of DIR/patterns.json into DIR/captures.json's files");
    film->add_option("--patterns", patterns, "Folder `mogao-calibrate patterns` wrote")
        ->required()
        ->check(CLI::ExistingDirectory);
    auto* measure = app.add_subcommand("measure", "Geometry error of an MPCDI against the rig's ground truth");
    measure->add_option("--mpcdi", mpcdi, "calibration.mpcdi")->required()->check(CLI::ExistingFile);
    app.require_subcommand(1);
    if (auto status = cli::parse(app, argc, argv)) return *status;
    try {
        const rig::VirtualRig rig = autocal::scaled_rig(rig::load_rig(rig_file), scale, scale);
        if (film->parsed()) {
            std::printf("%d patterns filmed by rig %s\n", calibrate::film_patterns(patterns, rig), rig.name.c_str());
            return 0;
        }
        const autocal::GeometryError g = autocal::measure_geometry(rig, to_screen_calibration(read_mpcdi(mpcdi)), 4);
        std::printf("SIMULATION ground truth (rig %s): geometry mean %.3f p95 %.3f px\n", rig.name.c_str(), g.mean_px,
                    g.p95_px);
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "mogao-rig-film: " << e.what() << "\n";
        return 1;
    }
}
