// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/request_policy.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "common/request_limits.h"

namespace mogao {
namespace {

double pixels_of(const ViewRequest& request) {
    const ImageSize size = render_size(request);
    return double(size.width) * double(size.height);
}

void note(std::string& changes, const char* knob, double before, double after) {
    if (!changes.empty()) changes += ", ";
    changes += fmt::format("{} {:g} -> {:g}", knob, before, after);
}

// Halves `knob` towards `floor` while the estimate is over `budget`.
void halve_while_over(ViewRequest& view, int& knob, int floor, const char* name, const LightCounts& lights,
                      double budget, std::string& changes) {
    const int before = knob;
    while (knob > floor && estimated_rays(view, lights) > budget) knob = std::max(floor, knob / 2);
    if (knob != before) note(changes, name, before, knob);
}

// Cuts resolution_scale so that about `ratio` (< 1) of today's pixels remain, never below the
// link's smallest frame side (request_limits::kLinkImageSide.min). render_size rounds to nearest, so the scale then
// steps down while `over(view)` holds.
template <typename Over>
void scale_pixels(ViewRequest& view, double ratio, const Over& over) {
    const double smallest =
        std::min(1.0, double(request_limits::kLinkImageSide.min) / double(std::min(view.size.width, view.size.height)));
    double& scale = view.quality.resolution_scale;
    scale = std::max(smallest, scale * std::sqrt(std::max(0.0, ratio)));
    for (int i = 0; i < 200 && over(view) && scale > smallest; ++i) scale = std::max(smallest, scale * 0.995);
}

}  // namespace

void RequestPolicy::validate() const {
    if (!std::isfinite(max_megapixels) || max_megapixels <= 0)
        throw std::invalid_argument(fmt::format("RequestPolicy.max_megapixels = {} must be > 0", max_megapixels));
    if (!std::isfinite(max_gigarays) || max_gigarays <= 0)
        throw std::invalid_argument(fmt::format("RequestPolicy.max_gigarays = {} must be > 0", max_gigarays));
    if (!(min_resolution_scale >= 0 && min_resolution_scale <= 1))
        throw std::invalid_argument(
            fmt::format("RequestPolicy.min_resolution_scale = {} must be in [0, 1]", min_resolution_scale));
}

LightCounts LightCounts::of(const Scene& scene) {
    return {static_cast<int>(scene.directional_lights.size()), static_cast<int>(scene.point_lights.size()),
            static_cast<int>(scene.area_lights.size()), !scene.environment_lights.empty()};
}

double estimated_rays(const ViewRequest& request, const LightCounts& lights) {
    const Quality& q = request.quality;
    const double shadow = double(lights.directional) + double(lights.point) +
                          double(lights.area) * double(q.area_light_samples) +
                          (lights.environment ? double(std::max(1, q.ao_samples)) : 0.0);
    const double bounces = double(q.max_bounces);
    const double per_sample = 1.0 + (1.0 + bounces) * shadow + bounces;
    return pixels_of(request) * double(q.spp) * per_sample;
}

PolicyDecision apply_request_policy(const ViewRequest& request, const LightCounts& lights,
                                    const RequestPolicy& policy) {
    policy.validate();
    PolicyDecision d;
    d.view = request;
    d.requested_rays = estimated_rays(request, lights);
    ViewRequest& v = d.view;
    const double max_pixels = policy.max_megapixels * 1e6;
    Quality& q = v.quality;
    const double requested_scale = q.resolution_scale;
    const auto too_many_pixels = [&](const ViewRequest& r) { return pixels_of(r) > max_pixels; };
    if (too_many_pixels(v)) scale_pixels(v, max_pixels / pixels_of(v), too_many_pixels);
    const double pixel_bound_scale = q.resolution_scale;  // the floor below is the ray bound's only

    const double budget = policy.max_gigarays * 1e9;
    halve_while_over(v, q.spp, 1, "spp", lights, budget, d.changes);
    halve_while_over(v, q.area_light_samples, 1, "area_light_samples", lights, budget, d.changes);
    halve_while_over(v, q.ao_samples, 0, "ao_samples", lights, budget, d.changes);
    halve_while_over(v, q.max_bounces, 0, "max_bounces", lights, budget, d.changes);
    const auto too_many_rays = [&](const ViewRequest& r) { return estimated_rays(r, lights) > budget; };
    if (too_many_rays(v)) scale_pixels(v, budget / estimated_rays(v, lights), too_many_rays);
    q.resolution_scale = std::max(q.resolution_scale, std::min(pixel_bound_scale, policy.min_resolution_scale));
    if (q.resolution_scale < requested_scale) note(d.changes, "resolution_scale", requested_scale, q.resolution_scale);
    d.degraded = !d.changes.empty();
    d.rendered_rays = estimated_rays(v, lights);
    return d;
}

}  // namespace mogao
