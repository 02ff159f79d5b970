// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/progressive_accumulator.h"

#include <algorithm>
#include <stdexcept>

namespace mogao {
namespace {

bool same_camera(const CameraModel& a, const CameraModel& b) {
    if (a.index() != b.index()) return false;
    if (const auto* pa = std::get_if<PinholeCamera>(&a))
        return pa->vertical_fov_deg == std::get<PinholeCamera>(b).vertical_fov_deg;
    const auto& ca = std::get<CylinderScreen>(a);
    const auto& cb = std::get<CylinderScreen>(b);
    return ca.radius_m == cb.radius_m && ca.arc_deg == cb.arc_deg && ca.bottom_m == cb.bottom_m &&
           ca.top_m == cb.top_m && ca.eye_m == cb.eye_m;
}

}  // namespace

bool same_view(const ViewRequest& a, const ViewRequest& b) {
    const Quality& qa = a.quality;
    const Quality& qb = b.quality;
    return a.pose.eye == b.pose.eye && a.pose.yaw_deg == b.pose.yaw_deg && a.pose.pitch_deg == b.pose.pitch_deg &&
           same_camera(a.camera, b.camera) && a.size == b.size && a.seed == b.seed &&
           qa.max_bounces == qb.max_bounces && qa.ao_samples == qb.ao_samples &&
           qa.area_light_samples == qb.area_light_samples && qa.resolution_scale == qb.resolution_scale;
}

std::uint64_t pass_frame_id(std::uint64_t first_frame_id, int pass) {
    if (pass < 0) throw std::invalid_argument("pass_frame_id: pass must be >= 0");
    // Request ids count up from 1 per session, far below 2^40; passes live above it.
    return first_frame_id + (static_cast<std::uint64_t>(pass) << 40);
}

int ProgressiveAccumulator::add(const ViewRequest& view, const RgbFloatImage& pass) {
    if (pass.size != render_size(view))
        throw std::invalid_argument("ProgressiveAccumulator: pass size does not match render_size(view)");
    if (view.quality.spp < 1) throw std::invalid_argument("ProgressiveAccumulator: view.quality.spp must be >= 1");
    const auto weight = static_cast<float>(view.quality.spp);
    if (!continues(view)) {
        view_ = view;
        sum_ = RgbFloatImage(pass.size);
        sum_squares_ = RgbFloatImage(pass.size);
        samples_ = 0;
        passes_ = 0;
    }
    for (std::size_t i = 0; i < pass.pixels.size(); ++i) {
        const float v = pass.pixels[i];
        sum_.pixels[i] += weight * v;
        sum_squares_.pixels[i] += weight * v * v;
    }
    samples_ += view.quality.spp;
    ++passes_;
    return samples_;
}

RgbFloatImage ProgressiveAccumulator::mean() const {
    RgbFloatImage out(sum_.size);
    if (samples_ == 0) return out;
    const float inv = 1.0f / static_cast<float>(samples_);
    for (std::size_t i = 0; i < sum_.pixels.size(); ++i) out.pixels[i] = sum_.pixels[i] * inv;
    return out;
}

RgbFloatImage ProgressiveAccumulator::variance_of_mean() const {
    if (passes_ < 2) return {};
    RgbFloatImage out(sum_.size);
    const double n = samples_;
    const double scale = 1.0 / ((passes_ - 1) * n);
    for (std::size_t i = 0; i < sum_.pixels.size(); ++i) {
        const double mean = sum_.pixels[i] / n;
        const double spread = static_cast<double>(sum_squares_.pixels[i]) - n * mean * mean;
        out.pixels[i] = static_cast<float>(std::max(0.0, spread * scale));
    }
    return out;
}

void ProgressiveAccumulator::reset() {
    sum_ = {};
    sum_squares_ = {};
    samples_ = 0;
    passes_ = 0;
}

}  // namespace mogao
