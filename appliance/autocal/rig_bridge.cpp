// SPDX-License-Identifier: Apache-2.0
// The virtual rig as calibration input, and accuracy against its ground truth (rig_bridge.h).
#include "appliance/autocal/rig_bridge.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "appliance/autocal/projector_footprint.h"
#include "appliance/rig/screen_light.h"
#include "appliance/warp/composite.h"
#include "appliance/warp/response_curve.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao::autocal {

namespace {

bool same_signals(const std::vector<cv::Mat>& a, const std::vector<cv::Mat>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t k = 0; k < a.size(); ++k) {
        if (a[k].empty() != b[k].empty()) return false;
        if (a[k].empty()) continue;
        if (a[k].size() != b[k].size() || a[k].type() != b[k].type() || cv::norm(a[k], b[k], cv::NORM_INF) != 0.0)
            return false;
    }
    return true;
}

}  // namespace

cv::Mat1f RigPatternSource::show(const std::vector<cv::Mat>& signals) {
    const auto t0 = std::chrono::steady_clock::now();
    const bool changed = !shown_.empty() && !same_signals(signals, shown_);
    cv::Mat1f img = sim_.capture(signals, frame_);
    const double straddle = sim_.rig().camera.straddle;
    if (changed && straddle > 0.0 && drop_frames_ == 0) {
        // The same noise seed: the frame is one exposure, of two patterns' light in turn.
        cv::addWeighted(img, 1.0 - straddle, sim_.capture(shown_, frame_), straddle, 0.0, img);
    }
    ++frame_;
    if (shown_.empty() || changed) {
        shown_.clear();
        for (const cv::Mat& m : signals) shown_.push_back(m.clone());
    }
    simulate_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return img;
}

GeometryError measure_geometry(const rig::VirtualRig& rig, const ScreenCalibration& calibration, int step) {
    std::vector<double> errors;
    GeometryError out;
    for (std::size_t k = 0; k < calibration.projectors.size(); ++k) {
        const ProjectorCalibration& pc = calibration.projectors[k];
        for (int y = 0; y < pc.output.height; y += step) {
            for (int x = 0; x < pc.output.width; x += step) {
                const auto truth = rig::projector_to_screen(rig, static_cast<int>(k), x + 0.5, y + 0.5);
                if (!truth) continue;
                const float w = sample_blend(pc.blend, pc.output, x, y);
                const ContentUv uv = sample_warp(pc.warp, pc.output, x, y);
                ++out.samples;
                if (w <= 0.0f || !std::isfinite(uv.u)) {
                    ++out.missing;
                    continue;
                }
                const auto belongs =
                    rig::screen_to_projector(rig, static_cast<int>(k), rig::screen_of(rig.screen, {uv.u, uv.v}));
                if (!belongs) {
                    ++out.outside;  // its content belongs beyond this projector's image (edge pixels)
                    continue;
                }
                errors.push_back(std::hypot(belongs->x() - (x + 0.5), belongs->y() - (y + 0.5)));
            }
        }
    }
    if (errors.empty()) return out;
    std::sort(errors.begin(), errors.end());
    double sum = 0.0;
    for (double e : errors) sum += e;
    out.mean_px = sum / static_cast<double>(errors.size());
    out.p95_px =
        errors[std::min(errors.size() - 1, static_cast<std::size_t>(0.95 * static_cast<double>(errors.size())))];
    out.max_px = errors.back();
    return out;
}

std::vector<rig::ScreenPoint> seam_grid(const rig::VirtualRig& rig, double inset, int columns, int rows) {
    if (columns < 2 || rows < 2) throw std::invalid_argument("seam_grid: columns and rows >= 2");
    std::vector<rig::ScreenPoint> grid;
    grid.reserve(static_cast<std::size_t>(columns) * static_cast<std::size_t>(rows));
    for (int j = 0; j < rows; ++j) {
        for (int i = 0; i < columns; ++i) grid.push_back(seam_grid_point(rig, inset, columns, rows, i, j));
    }
    return grid;
}

rig::ScreenPoint seam_grid_point(const rig::VirtualRig& rig, double inset, int columns, int rows, int i, int j) {
    const Eigen::Vector2d uv(inset + (1.0 - 2.0 * inset) * i / (columns - 1),
                             inset + (1.0 - 2.0 * inset) * j / (rows - 1));
    return rig::screen_of(rig.screen, uv);
}

SeamGridSize pixel_dense_seam_grid(const rig::VirtualRig& rig, double per_pixel) {
    int width = 0;
    int height = 0;
    for (const rig::RigProjector& p : rig.projectors) {
        width += p.resolution.width;
        height = std::max(height, p.resolution.height);
    }
    return {std::max(2, static_cast<int>(std::ceil(per_pixel * width))),
            std::max(2, static_cast<int>(std::ceil(per_pixel * height)))};
}

std::optional<std::array<int, 2>> output_pixel(const rig::VirtualRig& rig, int k, const ProjectorCalibration& pc,
                                               const rig::ScreenPoint& s) {
    const auto p = rig::screen_to_projector(rig, k, s);
    if (!p) return std::nullopt;
    return output_pixel_at(pc, *p);
}

std::array<int, 2> output_pixel_at(const ProjectorCalibration& pc, const Eigen::Vector2d& position) {
    return {std::clamp(static_cast<int>(std::floor(position.x())), 0, pc.output.width - 1),
            std::clamp(static_cast<int>(std::floor(position.y())), 0, pc.output.height - 1)};
}

LensFalloff falloff_of(const rig::RigProjector& p) { return {{1.0, 0.0, 0.0, -p.falloff, 0.0, -p.falloff}}; }

namespace {

// Projector output pixel (x, y) showing white content (less the indirect light's `field` where the outputs subtract
// one): its light before the lens fall-off (the rig's response and brightness, black level left out), mono (the
// channels' mean), and its blend weight in `weight`.
double white_pixel_light(const rig::RigProjector& rp, const ProjectorCalibration& pc, const RgbFloatImage& field, int x,
                         int y, float* weight) {
    const float w = sample_blend(pc.blend, pc.output, x, y);
    std::array<float, 3> content{1.0F, 1.0F, 1.0F};
    if (const ContentUv uv = sample_warp(pc.warp, pc.output, x, y); uv.valid())
        content = take_off_indirect_light(content, field, uv.u, uv.v);
    double l = 0.0;
    for (int c = 0; c < 3; ++c) {
        const double signal = apply_response(pc.response, c, content[static_cast<std::size_t>(c)] * w);
        l += rp.brightness[static_cast<std::size_t>(c)] * std::pow(signal, rp.gamma[static_cast<std::size_t>(c)]) / 3.0;
    }
    if (weight != nullptr) *weight = w;
    return l;
}

// white_pixel_light of every output pixel of each defocused projector (RigProjector::blur_px > 0), row-major; empty
// for a sharp one.
std::vector<std::vector<float>> defocused_white_lights(const rig::VirtualRig& rig, const ScreenCalibration& calibration,
                                                       const RgbFloatImage& field) {
    std::vector<std::vector<float>> out(calibration.projectors.size());
    for (std::size_t k = 0; k < out.size(); ++k) {
        if (rig.projectors[k].blur_px <= 0.0) continue;
        const ProjectorCalibration& pc = calibration.projectors[k];
        out[k].resize(static_cast<std::size_t>(pc.output.pixel_count()));
        cv::parallel_for_(cv::Range(0, pc.output.height), [&](const cv::Range& rows) {
            for (int y = rows.start; y < rows.end; ++y) {
                for (int x = 0; x < pc.output.width; ++x) {
                    out[k][static_cast<std::size_t>(y) * pc.output.width + x] =
                        static_cast<float>(white_pixel_light(rig.projectors[k], pc, field, x, y, nullptr));
                }
            }
        });
    }
    return out;
}

}  // namespace

LuminanceError measure_luminance(const rig::VirtualRig& rig, const ScreenCalibration& calibration, double inset,
                                 SeamGridSize grid, const IndirectLight* indirect, bool defocused) {
    const RgbFloatImage field = indirect != nullptr ? indirect->flat_field(1.0) : RgbFloatImage{};
    const std::vector<std::vector<float>> lights = defocused
                                                       ? defocused_white_lights(rig, calibration, field)
                                                       : std::vector<std::vector<float>>(calibration.projectors.size());
    // White content's light at s, as the viewer sees it (`seen`: through the screen's gain) or as it leaves a
    // matte screen (what bounces); `lit` counts the projectors whose blend is on there. A defocused projector's
    // light is its pixels' through their footprint (projector_footprint.h), a sharp one's its one pixel's.
    const auto direct = [&](const rig::ScreenPoint& s, bool seen, int* lit) {
        double l = 0.0;
        for (std::size_t k = 0; k < calibration.projectors.size(); ++k) {
            const ProjectorCalibration& pc = calibration.projectors[k];
            const rig::RigProjector& rp = rig.projectors[k];
            const bool spread = !lights[k].empty();
            // A defocused projector's light reaches past its image's edge (virtual_rig.h's header comment).
            const auto position =
                rig::screen_to_projector(rig, static_cast<int>(k), s, spread ? rig::defocus_margin(rp) : 0);
            if (!position) continue;
            const std::array<int, 2> xy = output_pixel_at(pc, *position);
            const bool inside = position->x() >= 0.0 && position->y() >= 0.0 && position->x() < rp.resolution.width &&
                                position->y() < rp.resolution.height;
            float w = 0.0F;
            double light = inside ? white_pixel_light(rp, pc, field, xy[0], xy[1], &w) : 0.0;
            if (w > 0.0f && lit != nullptr) ++*lit;
            if (spread) {
                light = 0.0;
                for_each_footprint_pixel(position->x(), position->y(), pc.output.width, pc.output.height, rp.blur_px,
                                         [&](std::size_t i, double weight) { light += weight * lights[k][i]; });
            }
            const double f = (spread ? rig::projector_falloff(rp, position->x(), position->y())
                                     : rig::projector_falloff(rp, xy[0] + 0.5, xy[1] + 0.5)) *
                             (seen ? rig::screen_gain(rig.screen, s, rp.pose.position_m, rig.viewer_m) : 1.0);
            l += f * light;
        }
        return l;
    };
    std::optional<rig::ScreenBounce> bounce;
    std::vector<double> bounced;
    if (rig.screen.interreflection > 0.0) {
        bounce.emplace(rig.screen);
        std::vector<double> leaving;
        for (int i = 0; i < bounce->patches(); ++i) leaving.push_back(direct(bounce->centre(i), false, nullptr));
        bounced = bounce->bounce(leaving);
    }
    std::vector<double> lum;
    std::vector<bool> seam;
    const std::vector<rig::ScreenPoint> points = seam_grid(rig, inset, grid.columns, grid.rows);
    for (const rig::ScreenPoint& s : points) {
        int lit = 0;
        lum.push_back(direct(s, true, &lit) + (bounce ? bounce->at(bounced, s) : 0.0));
        seam.push_back(lit >= 2);
    }
    LuminanceError out;
    out.samples = static_cast<int>(lum.size());
    std::vector<double> sorted = lum;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double median = sorted[sorted.size() / 2];
    for (std::size_t i = 0; i < lum.size(); ++i) {
        const double d = std::abs(lum[i] / median - 1.0);
        out.max_deviation = std::max(out.max_deviation, d);
        if (seam[i] && d > out.seam_max_deviation) {
            out.seam_max_deviation = d;
            out.seam_max_at = points[i];
        }
    }
    return out;
}

}  // namespace mogao::autocal
