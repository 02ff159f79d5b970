// SPDX-License-Identifier: Apache-2.0
// Measures the renderer against raw Embree on the same camera rays, in one run, so the ratio is
// meaningful on any machine: (a) Renderer::trace_camera_rays (ray generation + rtcIntersect16 of
// exactly the packets render() traces), (b) Renderer::render (everything). Both run on the calling
// thread over the whole frame; each figure is the calling thread's CPU time (not wall time, so
// other processes on a shared machine do not inflate it), best (minimum) of `repetitions` runs.
#pragma once

#include <cstdint>

#include "common/view_request.h"
#include "renderfarm/scene/scene.h"
#include "renderfarm/trace/renderer.h"

namespace mogao {

struct RenderTimings {
    double build_s = 0.0;           // Renderer construction (BVH builds), wall seconds; 0 if not measured
    double camera_rays_s = 0.0;     // (a) raw Embree camera packets, CPU seconds per frame
    double render_s = 0.0;          // (b) full render, CPU seconds per frame
    std::uint64_t camera_rays = 0;  // rays per frame in (a)
    std::uint64_t render_rays = 0;  // rays per frame in (b): camera + shadow + AO + bounce
    [[nodiscard]] double ratio() const { return camera_rays_s > 0.0 ? render_s / camera_rays_s : 0.0; }
};

// Uses an existing renderer (calls begin_frame(request)).
[[nodiscard]] RenderTimings time_frame(Renderer& renderer, const ViewRequest& request, int repetitions = 3);

// A whole frame of `request` (linear radiance, the renderer's render_size) and the calling thread's
// CPU seconds it took: the fastest of `repetitions` renders (the benchmarks' way of timing a frame).
struct TimedFrame {
    RgbFloatImage image;
    double seconds = 0.0;
};
[[nodiscard]] TimedFrame render_fastest_of(Renderer& renderer, const ViewRequest& request, int repetitions);

// Builds a renderer for `scene` (timed as build_s) and times one frame of `request`.
[[nodiscard]] RenderTimings time_render_vs_embree(const Scene& scene, const ViewRequest& request,
                                                  const RendererOptions& options = {}, int repetitions = 3);

}  // namespace mogao
