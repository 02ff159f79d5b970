// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/frame_time_controller.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/request_limits.h"

namespace mogao {
namespace {

void require(bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("FrameTimeTarget." + what);
}

// Smallest scale keeping both sides of `size` at kLinkImageSide.min pixels or more.
double smallest_link_scale(ImageSize size) {
    const double side = std::max(1, std::min(size.width, size.height));
    return std::min(1.0, request_limits::kLinkImageSide.min / side);
}

}  // namespace

FrameTimeController::FrameTimeController(FrameTimeTarget target) : target_(target) {
    require(std::isfinite(target_.target_seconds) && target_.target_seconds > 0, "target_seconds must be > 0");
    require(target_.gain > 0 && target_.gain <= 1, "gain must be in (0, 1]");
    require(std::isfinite(target_.max_step) && target_.max_step >= 1, "max_step must be >= 1");
    require(target_.min_scale > 0 && target_.min_scale <= 1, "min_scale must be in (0, 1]");
    require(request_limits::kSpp.contains(target_.max_spp), "max_spp must be in " + request_limits::kSpp.text());
}

FrameChoice FrameTimeController::choose(const ViewRequest& request) const {
    const double top = std::clamp(request.quality.resolution_scale, 1e-6, 1.0);
    const double bottom = std::min(top, std::max(target_.min_scale, smallest_link_scale(request.size)));
    if (work_ < 0) return {top, std::clamp(request.quality.spp, 1, target_.max_spp)};
    FrameChoice choice;
    const double full = top * top;
    if (work_ <= full) {
        choice.resolution_scale = std::clamp(std::sqrt(work_), bottom, top);
        choice.spp = 1;
    } else {
        choice.resolution_scale = top;
        choice.spp = std::clamp(static_cast<int>(std::lround(work_ / full)), 1, target_.max_spp);
    }
    return choice;
}

void FrameTimeController::observe(const FrameChoice& used, double seconds) {
    const double step = target_.max_step;
    const double ratio =
        (std::isfinite(seconds) && seconds > 0) ? std::clamp(target_.target_seconds / seconds, 1.0 / step, step) : step;
    const double next = used.work() * std::pow(ratio, target_.gain);
    // Bounded so a long run of extreme frames cannot wind w up beyond what choose() can use.
    work_ = std::clamp(next, 1e-8, static_cast<double>(target_.max_spp) + 1.0);
}

}  // namespace mogao
