// SPDX-License-Identifier: Apache-2.0
// The farm's request policy: what one appliance request may cost before it is rendered.
//
// A valid ViewRequest can still ask for a frame that would take the farm minutes (16384^2 pixels
// at 4096 spp with 64 bounces is inside request_limits.h). The policy bounds each request by
//  - rendered pixels (after resolution_scale), `max_megapixels`;
//  - estimated rays per frame, `max_gigarays`:
//        rays = pixels * spp * (1 + (1 + bounces) * shadow_rays_per_vertex + bounces)
//    where shadow_rays_per_vertex = directional + point lights + area lights * area_light_samples
//    + (environment ? max(1, ao_samples) : 0): the renderer's one-ray-per-light path (renderer.h),
//    with every path assumed to reach max_bounces, so an upper bound of what is traced.
// A request over a bound is degraded, never refused outright, so that a museum still gets a frame:
// spp is lowered first (it only trades noise), then area-light and AO samples, then bounces, then
// resolution_scale (the appliance upsamples a smaller frame). Each step halves the knob until the
// estimate fits or the knob is at its floor; resolution_scale is then cut to what fits, down to
// the link's smallest frame (16 px on the shorter side, request_limits.h). The decision names every knob that was
// changed, before and after.
//
// Units: pixels, rays (counts). Errors: RequestPolicy::validate throws std::invalid_argument naming
// the field and its limit for non-finite or non-positive bounds.
#pragma once

#include <string>

#include "common/view_request.h"
#include "renderfarm/scene/scene.h"

namespace mogao {

struct RequestPolicy {
    double max_megapixels = 8.3;  // rendered pixels per frame, millions (8.3: 3840x2160)
    double max_gigarays = 0.1;    // estimated rays per frame, billions (12 s at 8 Mrays/s)
    // The least resolution scale the ray bound may lower a request to, in [0, 1] (0: no floor; a request
    // asking for less, or held lower by max_megapixels, keeps that): the other knobs are lowered first,
    // and the scale stops here even when the estimate is then still over max_gigarays.
    double min_resolution_scale = 0.0;
    void validate() const;
};

// What a scene asks of each path vertex (the renderer's shadow-ray count, legacy light sampling).
struct LightCounts {
    int directional = 0;
    int point = 0;
    int area = 0;
    bool environment = false;
    [[nodiscard]] static LightCounts of(const Scene& scene);
};

// Upper bound of the rays a request traces (formula above).
[[nodiscard]] double estimated_rays(const ViewRequest& request, const LightCounts& lights);

struct PolicyDecision {
    ViewRequest view;  // the request as it will be rendered
    bool degraded = false;
    std::string changes;  // e.g. "spp 4096 -> 16, max_bounces 64 -> 0" (empty when not degraded)
    double requested_rays = 0.0;
    double rendered_rays = 0.0;
};

// Applies `policy` to a validated request.
[[nodiscard]] PolicyDecision apply_request_policy(const ViewRequest& request, const LightCounts& lights,
                                                  const RequestPolicy& policy);

}  // namespace mogao
