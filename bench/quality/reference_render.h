// SPDX-License-Identifier: Apache-2.0
// Renders (or extends, or reads from the cache) a converged reference of one view for the quality
// curves: reference_cache.h holds the format and the key.
//
// Progressive: batches of `batch_spp` samples with seeds 0x5eed0000 + k (k = 0, 1, ...; disjoint from
// the curves' seed 1), batch k going to half A when k is even and half B when odd, until each half
// has the requested spp or the wall-time budget is spent (then it stops after a whole pair of
// batches, and says so). A cached reference with the same key but fewer spp is extended, so a long
// reference can be built over several runs. The file is <cache_dir>/<view>-<key>.ref. Rows of each batch are split over
// `threads` threads (Renderer::render is const and thread-safe; the frame is bit-identical for any split).
#pragma once

#include <filesystem>
#include <string>

#include "bench/quality/quality_views.h"
#include "bench/quality/reference_cache.h"
#include "renderfarm/trace/renderer.h"

namespace mogao::quality {

struct ReferencePlan {
    int spp_per_half = 1024;
    int batch_spp = 32;
    int threads = 2;
    double budget_seconds = 1e9;  // wall seconds this run may spend on this reference
    std::filesystem::path cache_dir;
    std::string scene_text;        // the scene file's bytes (part of the key)
    std::string renderer_version;  // e.g. the git tree of renderfarm/trace + renderfarm/scene (part of the key)
};

// The reference request of a view: its camera and size with the reference knobs.
[[nodiscard]] ViewRequest reference_request(const QualityView& view);

// Cached or rendered (and saved) reference; prints what it did to stderr.
[[nodiscard]] CachedReference obtain_reference(Renderer& renderer, const QualityView& view, const ReferencePlan& plan);

// Noise floor of a reference from its two halves. Each half has n samples (variance s^2 / n per
// pixel), the reference 2n (s^2 / 2n), and the difference of the halves 2 s^2 / n: so the reference's
// own error is a quarter of the halves' relMSE against each other, and its PSNR 10 log10 4 = 6.02 dB
// above theirs (docs/quality.md, "References").
struct ReferenceFloor {
    double halves_relmse = 0, halves_psnr_db = 0, halves_ssim = 0;
    double floor_relmse = 0, floor_psnr_db = 0;
};
[[nodiscard]] ReferenceFloor reference_floor(const CachedReference& ref, float exposure, ToneMap tone_map);

// Renders the whole frame of `request` with its rows split over `threads` threads.
void render_threaded(Renderer& renderer, const ViewRequest& request, int threads, RgbFloatImage& frame);

}  // namespace mogao::quality
