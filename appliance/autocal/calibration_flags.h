// SPDX-License-Identifier: Apache-2.0
// The calibration flags of `mogao-calibrate` (on site, from images) and `mogao-calibrate-sim rig` (on a virtual
// rig), declared once so that a name means one thing with one help text in both
// (docs/cli.md, "Flag names"; the test cli_flag_names holds it).
//
//   --scale              resolution scale of projectors and camera, (0, 1] (also `mogao-calibrate patterns`
//                        and mogao-rig-film: add_scale_flag)
//   --content            the content frame WIDTHxHEIGHT, pixels (the farm's frame)
//   --alpha-bits         alpha map bits, 8 or 16
//   --warp-step-px       warp grid step, output pixels
//   --fit-screen, --fit-heights, --no-bow, --pinhole-projectors, --no-colour, --no-falloff, --no-indirect-light
//   switches of the fit
//   --max-self-check-px  the self-check gate, projector pixels (self_check.h)
//   --max-heights-shift-px  the told heights' check gate, projector pixels (autocal.h, check_heights)
//
// They fill CalibrationSettings (calibration_settings.h), which autocal::CalibrateJob and calibrate::OnSiteJob hold.
#pragma once

#include <CLI/CLI.hpp>

#include <string>

#include "appliance/autocal/calibration_settings.h"
#include "common/size_text.h"

namespace mogao::autocal {

// What the flags hold that is no job field as it stands: the negated switches and the size's text.
struct CalibrationFlags {
    std::string content = "1920x1080";
    bool no_bow = false;
    bool pinhole_projectors = false;
    bool no_colour = false;
    bool no_falloff = false;
    bool no_indirect_light = false;
};

inline CLI::Option* add_scale_flag(CLI::App& cmd, double& scale) {
    return cmd.add_option("--scale", scale, "Resolution scale of projectors and camera, (0, 1]")
        ->check(CLI::Range(0.05, 1.0));
}

inline void add_calibration_flags(CLI::App& cmd, CalibrationFlags& flags, CalibrationSettings& job) {
    add_scale_flag(cmd, job.scale);
    cmd.add_option("--content", flags.content, "Content frame WIDTHxHEIGHT (the farm's frame)");
    cmd.add_option("--alpha-bits", job.alpha_bits, "Alpha map bits: 8 (reference-library compatible) or 16")
        ->check(CLI::IsMember({8, 16}));
    cmd.add_option("--warp-step-px", job.options.warp_step_px, "Warp grid step, output pixels")
        ->check(CLI::Range(1, 64));
    cmd.add_flag("--fit-screen", job.options.fit_screen,
                 "Fit the screen's radius and arc too (known only roughly; the heights are taken as measured)");
    cmd.add_flag("--fit-heights", job.options.fit_heights,
                 "Fit the screen's top edge height too (heights taped, radius and arc known; the bottom edge stays)");
    cmd.add_flag("--no-bow", flags.no_bow,
                 "Take the screen as an exact cylinder: do not try a bow (kept by default only where it pays)");
    cmd.add_flag("--pinhole-projectors", flags.pinhole_projectors,
                 "Take the projectors as pinholes: do not try fitting their lens distortion (kept by default, per "
                 "projector, only where it pays; self-recalibration needs pinholes)");
    cmd.add_option("--max-self-check-px", job.self_check.max_mean_px,
                   "Self-check gate: refuse when the verification marks land further than this from where they "
                   "belong (mean, projector pixels; measured from the camera images against the screen's frame)")
        ->check(CLI::PositiveNumber);
    cmd.add_option("--max-heights-shift-px", job.options.max_heights_shift_px,
                   "Told heights' gate: refuse when the top edge the camera sees would move content by more than "
                   "this from where the told heights put it (mean, projector pixels; not checked with --fit-screen "
                   "or --fit-heights)")
        ->check(CLI::PositiveNumber);
    cmd.add_flag("--no-colour", flags.no_colour, "Geometry only: no response, black-level and colour matching step");
    cmd.add_flag("--no-falloff", flags.no_falloff,
                 "Colour step without the lens fall-off: one gain per projector and channel (flat projectors)");
    cmd.add_flag("--no-indirect-light", flags.no_indirect_light,
                 "Judge the calibration with outputs that leave the screen's own light on the picture (a kiosk with "
                 "[calibration] indirect_light = false)");
}

// After the parse: the flags into the job. Throws CLI::ValidationError naming --content (exit 2).
inline void apply_calibration_flags(const CalibrationFlags& flags, CalibrationSettings& job) {
    if (!parse_size(flags.content, job.content, 1, 16384)) {
        throw CLI::ValidationError("--content", "must be WIDTHxHEIGHT, 1..16384 per side");
    }
    job.colour = !flags.no_colour;
    job.colour_options.lens_falloff = !flags.no_falloff;
    job.indirect_light = !flags.no_indirect_light;
    job.options.fit_bow = !flags.no_bow;
    job.options.fit_projector_distortion = !flags.pinhole_projectors;
}

}  // namespace mogao::autocal
