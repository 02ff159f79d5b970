// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/render_timing.h"
#include "common/thread_clock.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <limits>
#include <memory>

namespace mogao {
namespace {

// CPU time of the calling thread: everything timed here runs on it, and unlike wall time it does
// not count the time other processes on a shared machine take the core away.
template <typename F>
double cpu_seconds(F&& f) {
    const double start = thread_cpu_seconds();
    f();
    return thread_cpu_seconds() - start;
}

template <typename F>
double wall_seconds(F&& f) {
    const auto start = std::chrono::steady_clock::now();
    f();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

RenderTimings time_frame(Renderer& renderer, const ViewRequest& request, int repetitions) {
    renderer.begin_frame(request);
    const ImageSize size = renderer.render_size();
    const PixelRect whole = PixelRect::whole(size);
    RgbFloatImage frame(size);
    RenderTimings t;
    t.camera_rays_s = std::numeric_limits<double>::infinity();
    t.render_s = std::numeric_limits<double>::infinity();
    // Interleave (a) and (b) so that clock or load drift affects both alike.
    for (int i = 0; i < std::max(1, repetitions); ++i) {
        t.camera_rays_s =
            std::min(t.camera_rays_s, cpu_seconds([&] { t.camera_rays = renderer.trace_camera_rays(whole).rays; }));
        t.render_s = std::min(t.render_s, cpu_seconds([&] { t.render_rays = renderer.render(whole, frame).rays; }));
    }
    return t;
}

RenderTimings time_render_vs_embree(const Scene& scene, const ViewRequest& request, const RendererOptions& options,
                                    int repetitions) {
    std::unique_ptr<Renderer> renderer;
    const double build = wall_seconds([&] { renderer = std::make_unique<Renderer>(scene, options); });
    RenderTimings t = time_frame(*renderer, request, repetitions);
    t.build_s = build;
    return t;
}

TimedFrame render_fastest_of(Renderer& renderer, const ViewRequest& request, int repetitions) {
    TimedFrame best;
    best.seconds = std::numeric_limits<double>::infinity();
    for (int r = 0; r < repetitions; ++r) {
        renderer.begin_frame(request);
        RgbFloatImage image(renderer.render_size());
        const double t0 = thread_cpu_seconds();
        (void)renderer.render(PixelRect::whole(image.size), image);
        const double t = thread_cpu_seconds() - t0;
        if (t < best.seconds) best = {std::move(image), t};
    }
    return best;
}

}  // namespace mogao
