// SPDX-License-Identifier: Apache-2.0
// mogao-tag-sequence: renders a synthetic hand-held tag sequence from known poses (PNG frames,
// timestamps.txt, camera.json and the truth, truth.json) for replay through the tracker
// (`mogao-track navigate`, the kiosk's "replay:<folder>" camera; docs/tracking.md). A laboratory
// program: not installed, so no appliance carries the synthetic-image code.
// Exit codes: 0 success, 1 the job failed, 2 bad command line.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

#include "appliance/tools/track_commands.h"
#include "appliance/tracker/tag_family.h"
#include "common/program_cli.h"

int main(int argc, char** argv) {
    CLI::App app{"mogao-tag-sequence: a synthetic hand-held tag sequence (PNGs + truth) for replay"};
    mogao::cli::prepare(app, "mogao-tag-sequence");
    mogao::track::SequenceOptions seq;
    CLI::App* s = &app;
    s->add_option("OUT", seq.out, "output folder")->required();
    s->add_option("--length-s", seq.seconds, "Length of the sequence, seconds")
        ->check(CLI::Range(0.01, 600.0))
        ->capture_default_str();
    s->add_option("--fps", seq.fps, "frames per second")->check(CLI::Range(0.1, 240.0))->capture_default_str();
    s->add_option("--family", seq.family, "tag family")
        ->check(CLI::IsMember(mogao::TagFamily::known_names()))
        ->capture_default_str();
    // The same text as mogao-track navigate's --id (one text per name, docs/cli.md).
    s->add_option("--id", seq.id, "Tag id (navigate: the one to follow, -1 the largest)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    s->add_option("--tag-size-mm", seq.tag_size_mm, "tag size (black border)")
        ->check(CLI::Range(1.0, 1000.0))
        ->capture_default_str();
    s->add_option("--width", seq.width, "Image width in pixels")->check(CLI::Range(16, 8192))->capture_default_str();
    s->add_option("--height", seq.height, "Image height in pixels")->check(CLI::Range(16, 8192))->capture_default_str();
    s->add_option("--focal-px", seq.focal_px, "focal length (px)")
        ->check(CLI::Range(10.0, 100000.0))
        ->capture_default_str();
    s->add_option("--noise", seq.noise, "sensor noise sigma (grey levels)")
        ->check(CLI::Range(0.0, 50.0))
        ->capture_default_str();
    s->add_option("--seed", seq.seed, "noise seed")->capture_default_str();

    if (auto status = mogao::cli::parse(app, argc, argv)) return *status;
    try {
        return mogao::track::make_sequence(seq);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao-tag-sequence: %s\n", e.what());
        return 1;
    }
}
