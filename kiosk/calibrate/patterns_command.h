// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate patterns`: the calibration's patterns written as files, so that any camera can
// capture them (pattern_catalogue.h; docs/on-site-calibration.md, "Calibration from captured images").
//
//   mogao-calibrate patterns --site FILE --out DIR [--scale S] [--phase-periods-px P[,P...]]
//
// Writes DIR/p<k>/*.png (one image per pattern per projector, the site file's projectors left to
// right), DIR/patterns.json (the manifest) and DIR/captures.json (the captures manifest to fill in).
#pragma once

#include <filesystem>
#include <vector>

#include <CLI/CLI.hpp>

namespace mogao::calibrate {

struct PatternsCommand {
    CLI::App* app = nullptr;
    std::filesystem::path site;
    std::filesystem::path out;
    double scale = 1.0;
    std::vector<double> phase_periods_px;  // empty: the calibration's phase period
};

// Adds the subcommand and its options to `parent`.
void add_patterns_command(CLI::App& parent, PatternsCommand& cmd);

// Runs a parsed subcommand: 0 written, 1 failed (the message names the file and the reason).
[[nodiscard]] int run_patterns_command(const PatternsCommand& cmd);

}  // namespace mogao::calibrate
