// SPDX-License-Identifier: Apache-2.0
// mogao-track: tag detection, printable tags and tag-driven navigation from the command line (a camera's
// intrinsics: mogao-calibrate camera-intrinsics); synthetic sequences are mogao-tag-sequence's (a laboratory
// program) (docs/tracking.md). Exit codes: 0 success, 1 job failed, 2 bad command line.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <string>

#include "appliance/tools/track_commands.h"
#include "appliance/tracker/tag_family.h"
#include "common/program_cli.h"

namespace {

using mogao::DetectorSettings;

// The detector flags shared by `detect` and `navigate`.
void add_detector_flags(CLI::App& cmd, DetectorSettings& s) {
    cmd.add_option("--family", s.family, "tag family")
        ->check(CLI::IsMember(mogao::TagFamily::known_names()))
        ->capture_default_str();
    cmd.add_option("--decimate", s.decimation, "quad decimation factor")
        ->check(CLI::Range(1.0f, 8.0f))
        ->capture_default_str();
    cmd.add_option("--blur-px", s.blur_sigma, "Gaussian blur sigma before the quad search, pixels")
        ->check(CLI::Range(-5.0f, 5.0f))
        ->capture_default_str();
    cmd.add_flag("!--no-refine", s.refine_edges, "do not refine the quad edges");
    cmd.add_option("--min-white-black-diff", s.min_white_black_diff, "threshold contrast floor")
        ->check(CLI::Range(0, 255))
        ->capture_default_str();
    cmd.add_option("--threads", s.threads, "detector threads")->check(CLI::Range(1, 64))->capture_default_str();
}

// The help texts of flags mogao-tag-sequence and mogao-calibrate declare too, word for word (one
// text per name, docs/cli.md; the test cli_flag_names compares them).
constexpr const char* kTagIdHelp = "Tag id (navigate: the one to follow, -1 the largest)";
constexpr const char* kCameraHelp =
    "Capture device: v4l2:/dev/videoN (or /dev/videoN) or libcamera:[id]; mogao-calibrate also replay:DIR and "
    "rig:FILE (simulation: mogao-calibrate-sim)";

CLI::App* add_detect(CLI::App& app, mogao::track::DetectOptions& detect) {
    auto* d = app.add_subcommand("detect", "print every tag's id and corners in images (JPEG, PNG, PGM)");
    d->add_option("IMAGE", detect.images, "images")->required();
    d->add_flag("--json", detect.json, "one JSON array instead of text");
    add_detector_flags(*d, detect.detector);
    return d;
}

CLI::App* add_make_tag(CLI::App& app, mogao::track::TagImageOptions& tag) {
    auto* t = app.add_subcommand("make-tag", "write a printable tag image (PNG), generated from the family's codes");
    t->add_option("ID", tag.id, "tag id")->required()->check(CLI::NonNegativeNumber);
    t->add_option("--family", tag.family, "tag family")
        ->check(CLI::IsMember(mogao::TagFamily::known_names()))
        ->capture_default_str();
    t->add_option("--px-per-cell", tag.pixels_per_cell, "pixels per cell")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
    t->add_option("--margin-cells", tag.margin_cells, "extra white margin (cells)")
        ->check(CLI::Range(0, 100))
        ->capture_default_str();
    t->add_option("--out", tag.out, "PNG to write")->required();
    return t;
}

CLI::App* add_navigate(CLI::App& app, mogao::track::NavigateOptions& nav) {
    auto* n = app.add_subcommand("navigate", "frames through tracker and navigation; print ViewerPoses (JSON lines)");
    auto* replay = n->add_option("REPLAY", nav.replay, "folder of frames (e.g. from mogao-tag-sequence)")
                       ->check(CLI::ExistingDirectory);
    n->add_option("--camera", nav.device, kCameraHelp)->excludes(replay);
    n->add_option("--camera-calibration", nav.camera,
                  "camera calibration file (default REPLAY/camera.json; required with --camera)");
    n->add_option("--tag-size-mm", nav.tag_size_mm, "tag size (black border)")
        ->check(CLI::Range(1.0, 1000.0))
        ->capture_default_str();
    n->add_option("--id", nav.id, kTagIdHelp)->check(CLI::Range(-1, 100000))->capture_default_str();
    n->add_option("--display-hz", nav.display_hz, "rate of the output poses")
        ->check(CLI::Range(1.0, 1000.0))
        ->capture_default_str();
    n->add_option("--replay-fps", nav.fps, "frame rate of a REPLAY folder without timestamps.txt")
        ->check(CLI::Range(0.1, 1000.0))
        ->capture_default_str();
    n->add_option("--out", nav.out, "JSON lines file (default stdout)");
    n->add_flag("!--no-roi", nav.roi, "search every frame whole with the detector settings (no window)");
    n->add_option("--window-tag-px", nav.window_tag_px,
                  "ROI window: decimate while the tag keeps this shortest side (px); 0 = detector settings")
        ->check(CLI::Range(0.0, 1000.0))  // (0, 4) is refused by TagTracker, naming the field
        ->capture_default_str();
    add_detector_flags(*n, nav.detector);
    return n;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"mogao-track: AprilTag tracking and tag-driven navigation"};
    mogao::cli::prepare(app, "mogao-track");
    app.require_subcommand(1);
    mogao::track::DetectOptions detect;
    mogao::track::TagImageOptions tag;
    mogao::track::NavigateOptions nav;
    auto* d = add_detect(app, detect);
    auto* t = add_make_tag(app, tag);
    auto* n = add_navigate(app, nav);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return mogao::cli::exit_status(app, e);
    }
    try {
        if (*d) return mogao::track::detect(detect);
        if (*t) return mogao::track::make_tag(tag);
        if (*n) {
            if (nav.replay.empty() == nav.device.empty() || (!nav.device.empty() && nav.camera.empty())) {
                std::fprintf(stderr, "mogao-track navigate: give REPLAY, or --camera with --camera-calibration\n");
                return 2;
            }
            return mogao::track::navigate(nav);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao-track: %s\n", e.what());
        return 1;
    }
    return 2;
}
