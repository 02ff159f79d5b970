// SPDX-License-Identifier: Apache-2.0
// Seam luminance and colour against the rig's ground truth (colour_truth.h).
#include "appliance/autocal/colour_truth.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "appliance/autocal/projector_footprint.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/rig/screen_light.h"
#include "appliance/warp/composite.h"
#include "appliance/warp/response_curve.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao::autocal {
namespace {

struct Point {
    std::array<double, 3> rgb{};
    int lit = 0;
    int shown_by = -1;           // the projector with the largest blend weight there
    std::array<int, 2> pixel{};  // its output pixel there
};

// Flat content `level` as the outputs show it at content point uv: less the indirect light's field there
// (render_output's `indirect`, clamped at 0), or as it is without one.
std::array<float, 3> shown_content(double level, const RgbFloatImage& indirect, ContentUv uv) {
    const auto l = static_cast<float>(level);
    if (!uv.valid()) return {l, l, l};
    return take_off_indirect_light({l, l, l}, indirect, uv.u, uv.v);
}

// Projector output pixel (x, y) for flat content `level`: its light before the lens fall-off (the rig's response,
// brightness and black level; the black also where it shows no content), and its blend weight in `weight`.
std::array<double, 3> pixel_rgb(const rig::RigProjector& rp, const ProjectorCalibration& pc, double level,
                                const RgbFloatImage& indirect, int x, int y, float* weight) {
    const ContentUv uv = sample_warp(pc.warp, pc.output, x, y);
    const bool shown = uv.valid();
    const float w = shown ? sample_blend(pc.blend, pc.output, x, y) : 0.0F;
    const std::array<float, 3> beta = sample_beta(pc.beta, pc.output, x, y);
    const std::array<float, 3> content = shown_content(level, indirect, uv);
    std::array<double, 3> rgb{};
    for (std::size_t c = 0; c < 3; ++c) {
        const double signal = shown ? apply_response(pc.response, static_cast<int>(c), content[c] * w + beta[c]) : 0.0;
        rgb[c] = rp.brightness[c] * (rp.black_level + (1.0 - rp.black_level) * std::pow(signal, rp.gamma[c]));
    }
    if (weight != nullptr) *weight = w;
    return rgb;
}

// Per projector with a defocus (RigProjector::blur_px > 0): pixel_rgb of every output pixel, row-major; empty for a
// sharp one (a point takes its one pixel's light).
using PixelLights = std::vector<std::vector<std::array<float, 3>>>;
PixelLights defocused_pixel_lights(const rig::VirtualRig& rig, const ScreenCalibration& calibration, double level,
                                   const RgbFloatImage& indirect) {
    PixelLights out(calibration.projectors.size());
    for (std::size_t k = 0; k < out.size(); ++k) {
        const rig::RigProjector& rp = rig.projectors[k];
        if (rp.blur_px <= 0.0) continue;
        const ProjectorCalibration& pc = calibration.projectors[k];
        out[k].resize(static_cast<std::size_t>(pc.output.pixel_count()));
        cv::parallel_for_(cv::Range(0, pc.output.height), [&](const cv::Range& rows) {
            for (int y = rows.start; y < rows.end; ++y) {
                for (int x = 0; x < pc.output.width; ++x) {
                    const std::array<double, 3> rgb = pixel_rgb(rp, pc, level, indirect, x, y, nullptr);
                    out[k][static_cast<std::size_t>(y) * pc.output.width + x] = {
                        static_cast<float>(rgb[0]), static_cast<float>(rgb[1]), static_cast<float>(rgb[2])};
                }
            }
        });
    }
    return out;
}

// Whether image position `p` lies in projector `rp`'s image (not in the margin its defocus reaches past it).
bool inside_image(const rig::RigProjector& rp, const Eigen::Vector2d& p) {
    return p.x() >= 0.0 && p.y() >= 0.0 && p.x() < rp.resolution.width && p.y() < rp.resolution.height;
}

// The light of `lights` (one projector's, row-major, `size`) at image position (x, y) through its pixels' footprint
// (projector_footprint.h).
std::array<double, 3> footprint_rgb(const std::vector<std::array<float, 3>>& lights, ImageSize size, double blur_px,
                                    double x, double y) {
    std::array<double, 3> rgb{};
    for_each_footprint_pixel(x, y, size.width, size.height, blur_px, [&](std::size_t i, double w) {
        for (std::size_t c = 0; c < 3; ++c) rgb[c] += w * lights[i][c];
    });
    return rgb;
}

// The light at screen point s for flat content `level`: each projector's, as the viewer sees it (`seen`: times the
// screen's gain toward rig.viewer_m) or as it leaves a matte screen (what bounces), plus the ambient. A defocused
// projector's light is its pixels' through their footprint (`lights`, defocused_pixel_lights), a sharp one's its
// one pixel's.
Point direct_light(const rig::VirtualRig& rig, const ScreenCalibration& calibration, double level,
                   const RgbFloatImage& indirect, const PixelLights& lights, const rig::ScreenPoint& s, bool seen) {
    Point pt;
    pt.rgb = {rig.ambient, rig.ambient, rig.ambient};
    float most = 0.0F;
    for (std::size_t k = 0; k < calibration.projectors.size(); ++k) {
        const ProjectorCalibration& pc = calibration.projectors[k];
        const rig::RigProjector& rp = rig.projectors[k];
        const bool defocused = !lights[k].empty();
        // A defocused projector's light reaches past its image's edge (virtual_rig.h's header comment).
        const auto position =
            rig::screen_to_projector(rig, static_cast<int>(k), s, defocused ? rig::defocus_margin(rp) : 0);
        if (!position) continue;
        std::array<double, 3> rgb{};
        const std::array<int, 2> xy = output_pixel_at(pc, *position);
        if (inside_image(rp, *position)) {
            float w = 0.0F;
            rgb = pixel_rgb(rp, pc, level, indirect, xy[0], xy[1], &w);
            if (w > 0.0F) ++pt.lit;
            if (w > most) {
                most = w;
                pt.shown_by = static_cast<int>(k);
                pt.pixel = xy;
            }
        }
        const auto [x, y] = xy;
        if (defocused) rgb = footprint_rgb(lights[k], pc.output, rp.blur_px, position->x(), position->y());
        const double f = (defocused ? rig::projector_falloff(rp, position->x(), position->y())
                                    : rig::projector_falloff(rp, x + 0.5, y + 0.5)) *
                         (seen ? rig::screen_gain(rig.screen, s, rp.pose.position_m, rig.viewer_m) : 1.0);
        for (std::size_t c = 0; c < 3; ++c) pt.rgb[c] += f * rgb[c];
    }
    return pt;
}

// The light the viewer sees on the screen for flat content `level`: direct light through the screen's gain,
// plus one bounce of the screen's own light (virtual_rig.h's header comment).
class ViewedLight {
public:
    ViewedLight(const rig::VirtualRig& rig, const ScreenCalibration& calibration, double level,
                const IndirectLight* compensation, bool defocused)
        : rig_(rig), calibration_(calibration), level_(level) {
        if (compensation != nullptr) indirect_ = compensation->flat_field(level);
        lights_ = defocused ? defocused_pixel_lights(rig, calibration, level, indirect_)
                            : PixelLights(calibration.projectors.size());
        if (rig.screen.interreflection <= 0.0) return;
        bounce_.emplace(rig.screen);
        std::array<std::vector<double>, 3> leaving;
        for (int i = 0; i < bounce_->patches(); ++i) {
            const Point p = direct_light(rig, calibration, level, indirect_, lights_, bounce_->centre(i), false);
            for (std::size_t c = 0; c < 3; ++c) leaving[c].push_back(p.rgb[c] - rig.ambient);
        }
        for (std::size_t c = 0; c < 3; ++c) bounced_[c] = bounce_->bounce(leaving[c]);
    }

    [[nodiscard]] Point at(const rig::ScreenPoint& s) const {
        Point p = direct_light(rig_, calibration_, level_, indirect_, lights_, s, true);
        if (bounce_) {
            for (std::size_t c = 0; c < 3; ++c) p.rgb[c] += bounce_->at(bounced_[c], s);
        }
        return p;
    }

private:
    const rig::VirtualRig& rig_;
    const ScreenCalibration& calibration_;
    double level_;
    RgbFloatImage indirect_;  // the compensation's field for this level (empty: none)
    PixelLights lights_;      // defocused projectors' pixel lights
    std::optional<rig::ScreenBounce> bounce_;
    std::array<std::vector<double>, 3> bounced_;
};

// The light at every grid point for flat content `level`.
std::vector<Point> screen_light(const ViewedLight& light, const rig::VirtualRig& rig, double inset) {
    std::vector<Point> points;
    for (const rig::ScreenPoint& s : seam_grid(rig, inset)) points.push_back(light.at(s));
    return points;
}

// The light of `p` averaged over the footprint of the output pixel that shows it (p.shown_by's), at
// kSub x kSub points of that pixel placed on the screen by the rig's true projector.
std::array<double, 3> pixel_light(const rig::VirtualRig& rig, const ViewedLight& light, const Point& p) {
    constexpr int kSub = 8;
    std::array<double, 3> sum{};
    int n = 0;
    for (int j = 0; j < kSub; ++j) {
        for (int i = 0; i < kSub; ++i) {
            const auto s =
                rig::projector_to_screen(rig, p.shown_by, p.pixel[0] + (i + 0.5) / kSub, p.pixel[1] + (j + 0.5) / kSub);
            if (!s) continue;
            const Point q = light.at(*s);
            for (std::size_t c = 0; c < 3; ++c) sum[c] += q.rgb[c];
            ++n;
        }
    }
    if (n == 0) return p.rgb;
    for (double& v : sum) v /= n;
    return sum;
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
}

double luminance(const std::array<double, 3>& rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

double lab_f(double t) {
    constexpr double d = 6.0 / 29.0;
    return t > d * d * d ? std::cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
}

// Per-channel median over points lit by one projector (or all points when none is).
std::array<double, 3> reference_rgb(const std::vector<Point>& pts) {
    std::array<double, 3> ref{};
    bool any_single = false;
    for (const Point& p : pts) any_single = any_single || p.lit == 1;
    for (std::size_t c = 0; c < 3; ++c) {
        std::vector<double> v;
        for (const Point& p : pts) {
            if (p.lit == 1 || !any_single) v.push_back(p.rgb[c]);
        }
        ref[c] = median(v);
    }
    return ref;
}

}  // namespace

std::array<double, 3> rgb_to_xyz(const std::array<double, 3>& c) {
    return {0.4124 * c[0] + 0.3576 * c[1] + 0.1805 * c[2], 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2],
            0.0193 * c[0] + 0.1192 * c[1] + 0.9505 * c[2]};
}

std::array<double, 3> rgb_to_lab(const std::array<double, 3>& rgb, const std::array<double, 3>& white_xyz) {
    const std::array<double, 3> xyz = rgb_to_xyz(rgb);
    const double fx = lab_f(xyz[0] / white_xyz[0]);
    const double fy = lab_f(xyz[1] / white_xyz[1]);
    const double fz = lab_f(xyz[2] / white_xyz[2]);
    return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

namespace {

// How many projectors show content (blend weight > 0) at screen point s: Point::lit without the light.
int projectors_showing(const rig::VirtualRig& rig, const ScreenCalibration& calibration, const rig::ScreenPoint& s) {
    int lit = 0;
    for (std::size_t k = 0; k < calibration.projectors.size(); ++k) {
        const ProjectorCalibration& pc = calibration.projectors[k];
        const auto position = rig::screen_to_projector(rig, static_cast<int>(k), s);
        if (!position || !inside_image(rig.projectors[k], *position)) continue;
        const auto [x, y] = output_pixel_at(pc, *position);
        lit += sample_warp(pc.warp, pc.output, x, y).valid() && sample_blend(pc.blend, pc.output, x, y) > 0.0F;
    }
    return lit;
}

// The seam figures of one measurement, point by point (measure_seam_colour).
class SeamTally {
public:
    SeamTally(const rig::VirtualRig& rig, const ViewedLight& light, const std::array<double, 3>& reference,
              const std::array<double, 3>& white_xyz, double level)
        : rig_(rig), light_(light), reference_(reference), white_(white_xyz) {
        out_.level = level;
        out_.reference_luminance = luminance(reference);
        reference_lab_ = rgb_to_lab(reference, white_xyz);
    }

    // Point p in the figures over all points.
    void add_to_all(const Point& p) {
        const double dev = deviation(p);
        ++out_.samples;
        out_.luminance_max_deviation = std::max(out_.luminance_max_deviation, dev);
        all_dev_.push_back(static_cast<float>(dev));
        out_.delta_e_max = std::max(out_.delta_e_max, delta_e(p));
    }

    // Seam point p (lit >= 2) in the seam's figures; its pixel mean now (`pixel_now`) or, on a dense grid, in
    // finish() for the kPixelCandidates seam points of largest deviation.
    void add_to_seam(const Point& p, bool pixel_now) {
        const double dev = deviation(p);
        const double de = delta_e(p);
        ++out_.seam_samples;
        out_.seam_luminance_deviation = std::max(out_.seam_luminance_deviation, dev);
        out_.seam_delta_e = std::max(out_.seam_delta_e, de);
        seam_dev_.push_back(static_cast<float>(dev));
        seam_de_.push_back(static_cast<float>(de));
        if (pixel_now) {
            note_pixel(p);
            return;
        }
        // The kPixelCandidates points of largest deviation so far, a min-heap on their deviation.
        const auto smaller_first = [](const auto& a, const auto& b) { return a.first > b.first; };
        if (candidates_.size() == kPixelCandidates && dev <= candidates_.front().first) return;
        if (candidates_.size() == kPixelCandidates) {
            std::pop_heap(candidates_.begin(), candidates_.end(), smaller_first);
            candidates_.pop_back();
        }
        candidates_.emplace_back(dev, p);
        std::push_heap(candidates_.begin(), candidates_.end(), smaller_first);
    }

    SeamColour finish() {
        for (const auto& candidate : candidates_) note_pixel(candidate.second);
        // The seam's points are points of the screen too (on a dense grid, more than the default grid has).
        out_.luminance_max_deviation = std::max(out_.luminance_max_deviation, out_.seam_luminance_deviation);
        out_.delta_e_max = std::max(out_.delta_e_max, out_.seam_delta_e);
        out_.seam_luminance_p95 = percentile(seam_dev_, 0.95);
        out_.luminance_p95 = percentile(all_dev_, 0.95);
        out_.seam_delta_e_p95 = percentile(seam_de_, 0.95);
        return out_;
    }

private:
    [[nodiscard]] double deviation(const Point& p) const {
        return std::abs(luminance(p.rgb) / out_.reference_luminance - 1.0);
    }
    [[nodiscard]] double delta_e(const Point& p) const {
        const std::array<double, 3> lab = rgb_to_lab(p.rgb, white_);
        return std::hypot(lab[0] - reference_lab_[0], lab[1] - reference_lab_[1], lab[2] - reference_lab_[2]);
    }

    // A pixel's mean is at most the largest point deviation inside it, and a dense grid has a point in or next to
    // every pixel: the pixel of the largest mean is among those of the points of largest deviation. Each pixel mean
    // costs 64 lights, as many as 64 points: a bound keeps the dense grid's cost at about its points'.
    static constexpr std::size_t kPixelCandidates = 4096;

    void note_pixel(const Point& p) {
        const double pixel_dev = std::abs(luminance(pixel_light(rig_, light_, p)) / out_.reference_luminance - 1.0);
        out_.seam_luminance_pixel_max = std::max(out_.seam_luminance_pixel_max, pixel_dev);
    }
    static double percentile(std::vector<float> v, double q) {
        if (v.empty()) return 0.0;
        const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
        std::nth_element(v.begin(), v.begin() + static_cast<long>(i), v.end());
        return v[i];
    }

    const rig::VirtualRig& rig_;
    const ViewedLight& light_;
    std::array<double, 3> reference_, white_, reference_lab_{};
    SeamColour out_;
    std::vector<float> seam_dev_, seam_de_, all_dev_;
    std::vector<std::pair<double, Point>> candidates_;
};

}  // namespace

SeamColour measure_seam_colour(const rig::VirtualRig& rig, const ScreenCalibration& calibration, double level,
                               double inset, const IndirectLight* indirect, bool defocused, SeamGridSize grid) {
    if (grid.columns < 2 || grid.rows < 2)
        throw std::invalid_argument("measure_seam_colour: grid columns and rows >= 2");
    const std::array<double, 3> white =
        rgb_to_xyz(reference_rgb(screen_light(ViewedLight(rig, calibration, 1.0, indirect, defocused), rig, inset)));
    const ViewedLight light(rig, calibration, level, indirect, defocused);
    // The reference from the default grid: a median over the single-lit screen, which a denser grid does not move.
    const std::vector<Point> coarse = screen_light(light, rig, inset);
    SeamTally tally(rig, light, reference_rgb(coarse), white, level);
    const SeamGridSize standard;
    const bool dense = grid.columns != standard.columns || grid.rows != standard.rows;
    for (const Point& p : coarse) {
        tally.add_to_all(p);
        if (!dense && p.lit >= 2) tally.add_to_seam(p, true);
    }
    // The seams on the dense grid, row by row (a pixel-dense grid of a wide rig holds millions of points), each point's
    // light evaluated only where two projectors show content.
    for (int j = 0; dense && j < grid.rows; ++j) {
        for (int i = 0; i < grid.columns; ++i) {
            const rig::ScreenPoint s = seam_grid_point(rig, inset, grid.columns, grid.rows, i, j);
            if (projectors_showing(rig, calibration, s) >= 2) tally.add_to_seam(light.at(s), false);
        }
    }
    return tally.finish();
}

}  // namespace mogao::autocal
