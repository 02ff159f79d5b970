// SPDX-License-Identifier: Apache-2.0
// mogao_tracking_eval: evaluation of the detector defaults and of region-of-interest tracking
// (tracking_eval.h). Exit codes: 0, 1 the job failed, 2 bad command line, 77 data absent.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

#include "appliance/tracker/lab/tags_real.h"
#include "appliance/tracker/lab/tracking_eval.h"

namespace {

namespace eval = mogao::eval;

// Every subcommand's options, and which one was given.
struct EvalCommands {
    explicit EvalCommands(const std::filesystem::path& source, const std::filesystem::path& data)
        : real{source / "appliance/tracker/lab/tags_real_truth.json", data},
          ref{source / "appliance/tracker/lab/tags_real_manifest.json", data,
              source / "appliance/tracker/lab/tags_real_truth.json"} {
        rank.data = data;
    }
    eval::RealOptions real;
    eval::ReferenceOptions ref;
    eval::RankCodesOptions rank;
    eval::RoiOptions roi;
    eval::GrottoDevelopOptions develop;
    eval::GrottoOptions grotto;
    CLI::App *r = nullptr, *f = nullptr, *k = nullptr, *o = nullptr, *d = nullptr, *g = nullptr;
};

// The subcommands on the real photographs (../shared/data/tags-real).
void add_photograph_commands(CLI::App& app, EvalCommands& c) {
    eval::RealOptions& real = c.real;
    eval::ReferenceOptions& ref = c.ref;
    eval::RankCodesOptions& rank = c.rank;
    CLI::App*& r = c.r;
    CLI::App*& f = c.f;
    CLI::App*& k = c.k;
    r = app.add_subcommand("real", "detection rate and corner error on the real photographs, per setting");
    r->add_option("--truth", real.truth, "truth file")->capture_default_str();
    r->add_option("--data", real.data, "tags-real folder")->capture_default_str();
    r->add_option("--repeat", real.repeat, "timing runs per image")->check(CLI::Range(1, 100))->capture_default_str();
    r->add_flag("--per-image", real.per_image, "per-image lines on stderr");

    f = app.add_subcommand("reference", "independent reference corners (ArUco + edge-line fits) -> truth file");
    f->add_option("--manifest", ref.manifest, "hand-written manifest")->capture_default_str();
    f->add_option("--data", ref.data, "tags-real folder")->capture_default_str();
    f->add_option("--out", ref.out, "truth file to write")->capture_default_str();

    k = app.add_subcommand("rank-codes", "independent check of a decoded id: every code ranked by correlation");
    k->add_option("--data", rank.data, "tags-real folder")->capture_default_str();
    k->add_option("--image", rank.image, "image file in the folder")->required();
    k->add_option("--id", rank.id, "the decoded id to check")->required()->check(CLI::Range(0, 100000));
    k->add_option("--family", rank.family, "tag family")->capture_default_str();
    k->add_option("--top", rank.top, "hypotheses to print")->check(CLI::Range(1, 100))->capture_default_str();
    k->add_option("--jitter-px", rank.jitter_px, "corner offsets of the robustness trials")
        ->check(CLI::Range(0.0, 5.0))
        ->capture_default_str();
    k->add_option("--trials", rank.trials, "robustness trials")->check(CLI::Range(0, 10000))->capture_default_str();
}

// The subcommands on sequences: the synthetic hand-held one, the rendered grotto set.
void add_sequence_commands(CLI::App& app, EvalCommands& c) {
    eval::RoiOptions& roi = c.roi;
    eval::GrottoDevelopOptions& develop = c.develop;
    eval::GrottoOptions& grotto = c.grotto;
    CLI::App*& o = c.o;
    CLI::App*& d = c.d;
    CLI::App*& g = c.g;
    o = app.add_subcommand("roi", "ROI tracking against full-frame detection on the hand-held sequence");
    o->add_option("--length-s", roi.seconds, "Length of the sequence, seconds")
        ->check(CLI::Range(0.5, 60.0))
        ->capture_default_str();
    o->add_option("--repeat", roi.repeat, "timing passes")->check(CLI::Range(1, 100))->capture_default_str();
    o->add_option("--stride", roi.stride, "track every N-th frame only")
        ->check(CLI::Range(1, 30))
        ->capture_default_str();
    o->add_option("--window-tag-px", roi.window_tag_px,
                  "extra ROI modes with these window_tag_px (0 = full resolution)")
        ->check(CLI::Range(0.0, 1000.0));

    d = app.add_subcommand("grotto-develop",
                           "rendered grotto set: sub-frames -> motion blur, noise, gain, JPEG frames");
    d->add_option("--set", develop.set, "folder of bench/tracking-grotto/make-grotto-set")->required();
    d->add_option("--shot", develop.shot, "shot-noise variance per unit signal (linear)")
        ->check(CLI::Range(0.0, 1.0))
        ->capture_default_str();
    d->add_option("--read", develop.read, "read-noise sigma (linear)")
        ->check(CLI::Range(0.0, 1.0))
        ->capture_default_str();
    d->add_option("--jpeg-quality", develop.jpeg_quality, "TurboJPEG quality")
        ->check(CLI::Range(1, 100))
        ->capture_default_str();

    g = app.add_subcommand("grotto", "rendered grotto set: detection, corner error, reference, ROI tracking");
    g->add_option("--set", grotto.set, "developed set folder")->required();
    g->add_option("--repeat", grotto.repeat, "timing runs per frame")->check(CLI::Range(1, 100))->capture_default_str();
    g->add_option("--min-rate", grotto.min_rate, "exit 1 if the defaults' rate is below")->check(CLI::Range(0.0, 1.0));
    g->add_option("--max-median-px", grotto.max_median_px, "exit 1 if the defaults' median corner error exceeds")
        ->check(CLI::Range(0.0, 1000.0));
}

int run_eval(const EvalCommands& c) {
    const std::filesystem::path& needed = *c.r ? c.real.data : (*c.f ? c.ref.data : c.rank.data);
    if ((*c.r || *c.f || *c.k) && !std::filesystem::exists(needed)) {
        std::fprintf(stderr, "mogao_tracking_eval: real photographs not found at %s (../shared/data/tags-real)\n",
                     needed.c_str());
        return 77;
    }
    if (*c.r) return eval::run_real(c.real);
    if (*c.f) return eval::run_reference(c.ref);
    if (*c.k) return eval::run_rank_codes(c.rank);
    if (*c.o) return eval::run_roi(c.roi);
    if (*c.d) return eval::run_grotto_develop(c.develop);
    if (*c.g) return eval::run_grotto(c.grotto);
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"mogao_tracking_eval: tag detection and tracking against ground truth"};
    app.require_subcommand(1);
    EvalCommands commands(MOGAO_SOURCE_DIR, mogao::tags_real_dir(MOGAO_TAGS_REAL_DIR));
    add_photograph_commands(app, commands);
    add_sequence_commands(app, commands);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }
    try {
        return run_eval(commands);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao_tracking_eval: %s\n", e.what());
        return 1;
    }
}
