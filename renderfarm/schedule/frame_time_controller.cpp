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
    require(target_.jitter_weight >= 0 && target_.jitter_weight < 1, "jitter_weight must be in [0, 1)");
    require(target_.min_aim > 0 && target_.min_aim <= 1, "min_aim must be in (0, 1]");
    require(target_.headroom >= 0 && target_.headroom <= 1 - target_.min_aim, "headroom must be in [0, 1 - min_aim]");
    require(target_.max_handoff >= 0 && target_.max_handoff < 1, "max_handoff must be in [0, 1)");
    require(request_limits::kMaxBounces.contains(target_.min_bounces),
            "min_bounces must be in " + request_limits::kMaxBounces.text());
    require(std::isfinite(target_.bounce_cost) && target_.bounce_cost > 0, "bounce_cost must be > 0");
    require(target_.climb_margin > 0 && target_.climb_margin <= 1, "climb_margin must be in (0, 1]");
}

double FrameTimeController::charged_gap(double gap_seconds) const {
    const bool handoff =
        std::isfinite(gap_seconds) && gap_seconds > 0 && gap_seconds < target_.max_handoff * target_.target_seconds;
    return handoff ? gap_seconds : 0.0;
}

double FrameTimeController::jitter_allowance() const {
    if (!timed_ || arithmetic_ <= 0) return 1.0;
    return std::min(1.0, std::exp(log_mean_) / arithmetic_);
}

void FrameTimeController::set_target_seconds(double seconds) {
    require(std::isfinite(seconds) && seconds > 0, "target_seconds must be > 0");
    target_.target_seconds = seconds;
}

double FrameTimeController::aim_seconds() const {
    return target_.target_seconds * std::max(target_.min_aim, (1.0 - target_.headroom) * jitter_allowance());
}

double FrameTimeController::level_work(const FrameChoice& like, int bounces) const {
    const double c = target_.bounce_cost;
    return like.floor_scale * like.floor_scale * (1.0 + c * bounces) / (1.0 + c * like.request_bounces);
}

FrameChoice FrameTimeController::choose(const ViewRequest& request) const {
    const double top = std::clamp(request.quality.resolution_scale, 1e-6, 1.0);
    const double bottom = std::min(top, std::max(target_.min_scale, smallest_link_scale(request.size)));
    FrameChoice choice;
    choice.floor_scale = bottom;
    choice.request_bounces = std::max(0, request.quality.max_bounces);
    choice.fewest_bounces = std::min(choice.request_bounces, target_.min_bounces);
    choice.bounces = choice.request_bounces;
    if (work_ < 0) {
        choice.resolution_scale = top;
        choice.spp = std::clamp(request.quality.spp, 1, target_.max_spp);
        return choice;
    }
    const double full = top * top;
    if (work_ > full) {
        choice.resolution_scale = top;
        choice.spp = std::clamp(static_cast<int>(std::lround(work_ / full)), 1, target_.max_spp);
    } else if (work_ >= bottom * bottom * (1.0 - 1e-9)) {
        choice.resolution_scale = std::clamp(std::sqrt(work_), bottom, top);
    } else {  // below the floor: the deepest level of the ladder that w pays for
        choice.resolution_scale = bottom;
        while (choice.bounces > choice.fewest_bounces && level_work(choice, choice.bounces) > work_ * (1.0 + 1e-9))
            --choice.bounces;
        choice.bounce_work = level_work(choice, choice.bounces) / (bottom * bottom);
    }
    return choice;
}

// The level of the ladder below the floor to render next, from the time of `used` (see the header):
// the deepest whose predicted time meets the aim, a deeper one than used only within climb_margin.
double FrameTimeController::ladder_work(const FrameChoice& used, double seconds) const {
    const int used_bounces = used.bounces < 0 ? used.request_bounces : used.bounces;
    const double ladder_aim = target_.target_seconds * (1.0 - target_.headroom);
    for (int b = used.request_bounces; b > used.fewest_bounces; --b) {
        const double w = level_work(used, b);
        const double margin = b > used_bounces ? target_.climb_margin : 1.0;
        if (seconds * w / used.work() <= margin * ladder_aim) return w;
    }
    return level_work(used, used.fewest_bounces);
}

void FrameTimeController::observe(const FrameChoice& used, double frame_seconds, double gap_seconds) {
    const double step = target_.max_step;
    const bool timed = std::isfinite(frame_seconds) && frame_seconds > 0;
    const double seconds = timed ? frame_seconds + charged_gap(gap_seconds) : frame_seconds;
    const double wanted = timed ? aim_seconds() / seconds : step;
    const double ratio = std::clamp(wanted, 1.0 / step, step);
    if (timed && ratio == wanted) note_time(seconds);
    const double next = used.work() * std::pow(ratio, target_.gain);
    const bool below_floor = used.floor_scale > 0 && next < level_work(used, used.request_bounces) * (1.0 - 1e-9);
    // Bounded so a long run of extreme frames cannot wind w up beyond what choose() can use.
    if (timed && below_floor) {
        const bool same_level = std::abs(used.work() - ladder_used_work_) <= 1e-12 * used.work();
        ladder_seconds_ = same_level ? ladder_seconds_ + kLadderWeight * (seconds - ladder_seconds_) : seconds;
        ladder_used_work_ = used.work();
        work_ = ladder_work(used, ladder_seconds_);
        return;
    }
    ladder_used_work_ = -1.0;
    work_ = std::clamp(next, 1e-8, static_cast<double>(target_.max_spp) + 1.0);
}

void FrameTimeController::note_time(double seconds) {
    const double a = target_.jitter_weight;
    if (!timed_) {
        log_mean_ = std::log(seconds);
        arithmetic_ = seconds;
        timed_ = true;
        return;
    }
    log_mean_ += a * (std::log(seconds) - log_mean_);
    arithmetic_ += a * (seconds - arithmetic_);
}

}  // namespace mogao
