// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate patterns` (patterns_command.h).
#include "kiosk/calibrate/patterns_command.h"

#include <cstdio>
#include <iostream>
#include <stdexcept>

#include "appliance/autocal/calibration_flags.h"
#include "kiosk/calibrate/on_site_job.h"
#include "kiosk/calibrate/pattern_catalogue.h"

namespace mogao::calibrate {

void add_patterns_command(CLI::App& parent, PatternsCommand& cmd) {
    cmd.app = parent.add_subcommand("patterns",
                                    "Write the calibration's patterns (PNG per pattern per projector, patterns.json, "
                                    "captures.json) for any camera to capture (docs/on-site-calibration.md)");
    cmd.app->add_option("--site", cmd.site, "Site file (rig format): the installation as measured")
        ->required()
        ->check(CLI::ExistingFile);
    cmd.app->add_option("--out", cmd.out, "Folder to write the patterns into")->required();
    autocal::add_scale_flag(*cmd.app, cmd.scale);
    cmd.app
        ->add_option("--phase-periods-px", cmd.phase_periods_px,
                     "Phase-shift periods, projector pixels (default: the calibration's; add longer ones when the "
                     "camera resolves fewer Gray bits)")
        ->delimiter(',')
        ->check(CLI::Range(4.0, 16384.0));
}

int run_patterns_command(const PatternsCommand& cmd) {
    try {
        OnSiteJob job;
        job.site = cmd.site;
        job.scale = cmd.scale;
        const autocal::CalibrationPrior prior = site_prior(job);
        const PatternCatalogue catalogue(prior.projectors, job.options, cmd.phase_periods_px);
        (void)write_patterns(catalogue, cmd.out, cmd.site.string(), cmd.scale);
        std::printf("%zu patterns for %zu projectors, camera %dx%d: written to %s (patterns.json, captures.json)\n",
                    catalogue.patterns().size(), prior.projectors.size(), prior.camera.resolution.width,
                    prior.camera.resolution.height, cmd.out.c_str());
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "mogao-calibrate patterns: " << e.what() << "\n";
        return 1;
    }
}

}  // namespace mogao::calibrate
