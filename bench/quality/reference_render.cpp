// SPDX-License-Identifier: Apache-2.0
#include "bench/quality/reference_render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <thread>
#include <vector>

#include "bench/quality/image_metrics.h"
#include "common/thread_clock.h"
#include "renderfarm/denoise/frame_error.h"

namespace mogao::quality {
namespace {

constexpr std::uint64_t kReferenceSeedBase = 0x5eed0000;

std::string key_description(const QualityView& view, const ReferencePlan& plan) {
    return "view " + view.name + "; " + describe_request(reference_request(view)) + "; renderer " +
           plan.renderer_version + "; scene " + cache_key(plan.scene_text);
}

// Adds `sum` (mean of n_old samples) and a batch (mean of n_new) into the running mean.
void accumulate(RgbFloatImage& mean, int n_old, const RgbFloatImage& batch, int n_new) {
    const double w_old = double(n_old) / (n_old + n_new), w_new = double(n_new) / (n_old + n_new);
    for (std::size_t i = 0; i < mean.pixels.size(); ++i)
        mean.pixels[i] = float(w_old * mean.pixels[i] + w_new * batch.pixels[i]);
}

}  // namespace

ViewRequest reference_request(const QualityView& view) {
    ViewRequest r = view.request;
    r.quality = Quality{};
    r.quality.max_bounces = kReferenceBounces;
    r.quality.ao_samples = 1;
    r.quality.area_light_samples = 1;
    return r;
}

void render_threaded(Renderer& renderer, const ViewRequest& request, int threads, RgbFloatImage& frame) {
    renderer.begin_frame(request);
    const ImageSize size = renderer.render_size();
    if (frame.size.width != size.width || frame.size.height != size.height) frame = RgbFloatImage(size);
    threads = std::max(1, threads);
    // Bands of 4-row packet rows dealt round-robin, so a slow region does not land on one thread.
    const int band = 4, bands = (size.height + band - 1) / band;
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
            for (int b = t; b < bands; b += threads) {
                const int y0 = b * band, y1 = std::min(size.height, y0 + band);
                renderer.render(PixelRect{0, y0, size.width, y1}, frame);
            }
        });
    for (std::thread& th : pool) th.join();
}

CachedReference obtain_reference(Renderer& renderer, const QualityView& view, const ReferencePlan& plan) {
    const std::string description = key_description(view, plan);
    // Named by its key: a reference made stale by a scene, camera or renderer change stays on disk
    // (for a change that cannot alter a pixel, or to go back) instead of being overwritten.
    const std::filesystem::path file = plan.cache_dir / (view.name + "-" + cache_key(description) + ".ref");
    CachedReference ref;
    if (std::filesystem::exists(file)) {
        Result<CachedReference> cached = load_reference(file, description);
        if (cached.ok()) ref = std::move(*cached);
        else
            std::fprintf(stderr, "reference %s: %s; rendering it again\n", view.name.c_str(),
                         cached.error().message.c_str());
    }
    if (ref.spp_per_half >= plan.spp_per_half) {
        std::fprintf(stderr, "reference %s: cached, %d spp per half (%s)\n", view.name.c_str(), ref.spp_per_half,
                     file.c_str());
        return ref;
    }
    ViewRequest request = reference_request(view);
    const ImageSize size = render_size(request);
    if (ref.spp_per_half == 0) {
        ref = CachedReference{description, 0, 0.0, RgbFloatImage(size), RgbFloatImage(size)};
    }
    const double start = monotonic_seconds();
    RgbFloatImage batch(size);
    const int batch_spp = std::min(plan.batch_spp, 4096);
    // At least one pair of batches, so a reference always exists, then until the spp or the budget.
    while (ref.spp_per_half < plan.spp_per_half &&
           (ref.spp_per_half == 0 || monotonic_seconds() - start < plan.budget_seconds)) {
        const int k0 = 2 * (ref.spp_per_half / batch_spp);  // batches already in each half, as pairs
        for (int half = 0; half < 2; ++half) {
            request.seed = kReferenceSeedBase + std::uint64_t(k0 + half);
            request.quality.spp = batch_spp;
            render_threaded(renderer, request, plan.threads, batch);
            accumulate(half == 0 ? ref.half_a : ref.half_b, ref.spp_per_half, batch, batch_spp);
        }
        ref.spp_per_half += batch_spp;
        std::fprintf(stderr, "\rreference %s: %d spp per half, %.0f s", view.name.c_str(), ref.spp_per_half,
                     monotonic_seconds() - start);
    }
    ref.seconds += monotonic_seconds() - start;
    std::fprintf(stderr, "\n");
    if (ref.spp_per_half < plan.spp_per_half)
        std::fprintf(stderr, "reference %s: budget spent at %d of %d spp per half (saved; the next run extends it)\n",
                     view.name.c_str(), ref.spp_per_half, plan.spp_per_half);
    if (Status s = save_reference(file, ref); !s.ok()) throw std::runtime_error(s.error().message);
    return ref;
}

ReferenceFloor reference_floor(const CachedReference& ref, float exposure, ToneMap tone_map) {
    ReferenceFloor f;
    const RgbFloatImage full = reference_image(ref);
    // relMSE of A against B with B's own denominator, symmetrised through the mean image.
    double sum = 0;
    for (std::size_t i = 0; i < full.pixels.size(); ++i) {
        const double d = double(ref.half_a.pixels[i]) - ref.half_b.pixels[i], r = full.pixels[i];
        sum += d * d / (r * r + kRelMseEpsilon);
    }
    f.halves_relmse = sum / double(full.pixels.size());
    const Rgb8Image a = display_frame(ref.half_a, exposure, tone_map),
                    b = display_frame(ref.half_b, exposure, tone_map);
    f.halves_psnr_db = display_psnr_db(a, b);
    f.halves_ssim = ssim_luminance(a, b);
    f.floor_relmse = f.halves_relmse / 4.0;
    f.floor_psnr_db = f.halves_psnr_db + 10.0 * std::log10(4.0);
    return f;
}

}  // namespace mogao::quality
