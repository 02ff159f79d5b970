// SPDX-License-Identifier: Apache-2.0
// mogao_tracking_eval: detector and tracker evaluation on image sets with ground truth or an
// independent reference (docs/tracking.md, "Evaluation"). Not part of the appliance. Each
// subcommand prints a Markdown table (bench/tracking-eval puts them into docs/tracking.md).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "appliance/tracker/detector_settings.h"
#include "appliance/tracker/tag_tracker.h"

namespace mogao::eval {

// One detector configuration under test, with the name printed in the tables.
struct NamedSettings {
    std::string name;
    DetectorSettings settings;
};
// The configurations the real-photograph table compares: the defaults, AprilTag's stock (decimation
// 1, no blur, no coarse pass, max_hamming not capped per family), the defaults without the coarse
// pass and with max_line_fit_mse 20 (with and without it), the old defaults (2, 0.8) and the
// tracker's whole-frame search (RoiSettings).
[[nodiscard]] std::vector<NamedSettings> compared_settings();

struct RealOptions {
    std::filesystem::path truth;  // tags_real_truth.json
    std::filesystem::path data;   // the tags-real folder
    int repeat = 3;               // timing: fastest of this many runs per image
    bool per_image = false;
};
int run_real(const RealOptions& options);

struct ReferenceOptions {
    std::filesystem::path manifest;
    std::filesystem::path data;
    std::filesystem::path out;
};
int run_reference(const ReferenceOptions& options);

// rank-codes: the independent check of one decoded id (code_ranking.h). The detector defaults find
// the tag with that id in the image; every code is then ranked by correlation with its cells.
// Prints the best hypotheses, the best other id and the best mirrored one (chance). Exit 1 when
// the detector does not find the id.
struct RankCodesOptions {
    std::filesystem::path data;  // the tags-real folder
    std::string image;           // a file in it
    int id = 0;
    std::string family = "tag36h11";
    int top = 5;
    // Robustness: the ranking is repeated with every corner moved by a uniform random offset of
    // up to +/- jitter_px in x and y, `trials` times; the count of trials where the id stays first
    // is printed.
    double jitter_px = 0.5;
    int trials = 100;
};
int run_rank_codes(const RankCodesOptions& options);

struct RoiOptions {
    double seconds = 12.0;  // of the hand-held sequence (hand_sequence.h), 30 fps, 800x600
    int repeat = 3;         // timing: fastest of this many passes per frame
    int stride = 1;         // track every stride-th frame only (a busy tracker skips frames)
    // Extra ROI modes with these RoiSettings::window_tag_px (a sweep; the defaults always run).
    std::vector<double> window_tag_px;
};
int run_roi(const RoiOptions& options);

// The rendered grotto set (bench/tracking-grotto/make-grotto-set writes SETDIR/set.json and the
// ray-traced sub-frames; docs/tracking.md, "Rendered grotto set").
struct GrottoDevelopOptions {
    std::filesystem::path set;  // SETDIR
    // The camera's sensor model applied to the average of the sub-frames (linear light, 1 = white):
    // Gaussian noise of variance shot * signal + read^2 (a Poisson-Gaussian model's normal
    // approximation; Foi et al., "Practical Poissonian-Gaussian noise modeling", IEEE TIP 2008),
    // then the frame's gain, clipping, sRGB encoding and JPEG (TurboJPEG, 4:2:0) at jpeg_quality.
    double shot = 0.001;
    double read = 0.0015;
    int jpeg_quality = 75;
};
// Writes SETDIR/frames/<variant>-NNNN.jpg; seeded per frame (set.json noise_seed), so reruns give
// the same bytes with the same standard library.
int run_grotto_develop(const GrottoDevelopOptions& options);

struct GrottoOptions {
    std::filesystem::path set;  // SETDIR, developed
    int repeat = 2;             // timing: fastest of this many runs per frame
    // Checks (the integration test): exit 1 when the defaults' rate is below min_rate or their
    // median corner error exceeds max_median_px (against the exact corners). Negative: no check.
    double min_rate = -1.0;
    double max_median_px = -1.0;
};
int run_grotto(const GrottoOptions& options);

}  // namespace mogao::eval
