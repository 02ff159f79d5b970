// SPDX-License-Identifier: Apache-2.0
// Time against error for every quality knob on one view (docs/quality.md): each row is one frame
// rendered on one thread (CPU time of the calling thread, best of `reps`), compared with the view's
// converged reference by relMSE (linear), PSNR and SSIM (display, image_metrics.h).
#pragma once

#include <string>
#include <vector>

#include "bench/quality/quality_views.h"
#include "renderfarm/scene/scene.h"
#include "renderfarm/trace/renderer.h"

namespace mogao::quality {

struct Measurement {
    std::string view, knob, value;
    int spp = 1;
    double ms = 0;  // CPU ms of the frame (render, + guides and filter when denoised; encode for JPEG)
    double psnr_db = 0, relmse = 0, ssim = 0;  // relMSE NaN where not defined (JPEG: display only)
    bool is_default = false;                   // the farm's default value of this knob
    std::string note;
};

// The quality presets proposed in docs/quality.md (for the farm's --quality).
struct SweepOptions {
    int reps = 1;
    int max_spp = 256;                 // spp series 1, 2, 4, ... max_spp at the default knobs
    int max_reference_knob_spp = 64;   // spp series at the reference knobs (unbiased: the 1/sqrt(spp) line)
    std::vector<int> base_spp{1, 16};  // other knobs are swept from the defaults at each of these spp
    bool presets_only = false;         // only the preset rows (after quality_presets() changed)
};

// All rows for `view` against `reference` (linear radiance of the view's full render size).
[[nodiscard]] std::vector<Measurement> sweep_knobs(const Scene& scene, Renderer& renderer, const QualityView& view,
                                                   const RgbFloatImage& reference, const SweepOptions& options);

}  // namespace mogao::quality
