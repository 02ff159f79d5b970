// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate [site]`: the on-site calibration job (on_site_job.h; docs/on-site-calibration.md), the program's
// default: its flags are those of the top level and of the subcommand `site` alike, so that
// `mogao-calibrate --site FILE ...` (the appliance's scripts) and `mogao-calibrate site --site FILE ...` are one job.
//
//   On site (the kiosk stopped: it holds the outputs):
//     mogao-calibrate --site /etc/mogao/site.toml --outputs kms --camera v4l2:/dev/video0
//                     --out /var/lib/mogao/calibration [--install /var/lib/mogao/etc/screen.mpcdi]
//   The whole on-site path without hardware (SIMULATION, mogao-calibrate-sim: the rig's camera films the headless
//   outputs, or with --outputs kms the kernel's scanout buffers: the appliance image's QEMU test):
//     mogao-calibrate-sim --site rigs/standard.toml --outputs headless --camera rig:rigs/standard.toml --out DIR
//   From images captured by any camera (`mogao-calibrate patterns` wrote the patterns):
//     mogao-calibrate --site FILE --images DIR --out DIR [--install FILE] [--camera-transfer srgb|linear]
//   How many images and how long the capture takes:
//     mogao-calibrate --site FILE --budget [--camera-fps 30 --settle-ms 150 --drop-frames 2]
//
// Exit codes: 0 success, 1 refused or failed (the message says why; the last good calibration is untouched),
// 2 bad command line (the shipped program's --camera rig:FILE too, naming mogao-calibrate-sim).
#pragma once

#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "appliance/autocal/calibration_flags.h"
#include "kiosk/calibrate/on_site_job.h"

namespace mogao::calibrate {

struct SiteCommand {
    CLI::App* app = nullptr;  // `site`; the same flags are the top level's
    OnSiteJob job;
    autocal::CalibrationFlags shared;  // calibration_flags.h
    std::filesystem::path site;
    std::string outputs;
    std::string camera;
    std::filesystem::path images;
    std::filesystem::path kms_device;
    std::string camera_size;
    int camera_fps = 0;
    double exposure_us = 0.0;
    double gain = -1.0;
    double white_balance_k = 0.0;
    std::string transfer = "srgb";
    bool grey = false;
    bool budget = false;
    double budget_fps = 30.0;
};

// Adds the job's flags to `parent` (the default) and the subcommand `site` with the same flags.
void add_site_command(CLI::App& parent, SiteCommand& cmd);

// After the parse, when no other subcommand was given: what CLI11 cannot check, and the flags into cmd.job.
// Throws CLI::ValidationError (exit 2).
void check_site_command(SiteCommand& cmd);

// Runs the checked job: the budget, the captured images or the cameras and outputs. 0, or 1 with the message.
[[nodiscard]] int run_site_command(const SiteCommand& cmd);

}  // namespace mogao::calibrate
