// SPDX-License-Identifier: Apache-2.0
// The converged reference the renderer benchmarks measure against: the same view at `spp` samples,
// Russian roulette off (no extra variance), another seed (independent of the frames measured),
// rendered in 4-row bands on every hardware thread. The renderer's path options are back at their
// defaults afterwards.
#pragma once

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "common/image.h"
#include "common/view_request.h"
#include "renderfarm/trace/renderer.h"

namespace mogao::bench {

inline RgbFloatImage reference_frame(Renderer& renderer, ViewRequest view, int spp) {
    RendererOptions o;
    o.russian_roulette = false;
    renderer.set_path_options(o);
    view.quality.spp = spp;
    view.seed += 1000;
    view.radiance_cache = false;
    renderer.begin_frame(view);
    RgbFloatImage frame(renderer.render_size());
    std::atomic<int> next{0};
    const auto work = [&] {
        for (int y0 = 4 * next++; y0 < frame.size.height; y0 = 4 * next++)
            (void)renderer.render(PixelRect{0, y0, frame.size.width, std::min(frame.size.height, y0 + 4)}, frame);
    };
    std::vector<std::jthread> pool;
    for (unsigned t = 1; t < std::max(1u, std::thread::hardware_concurrency()); ++t) pool.emplace_back(work);
    work();
    pool.clear();
    renderer.set_path_options(RendererOptions{});
    return frame;
}

}  // namespace mogao::bench
