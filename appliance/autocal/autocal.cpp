// SPDX-License-Identifier: Apache-2.0
// The calibration pipeline: decode, camera pose, projector fits, warp, blend (autocal.h).
#include "appliance/autocal/autocal.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <vector>

#include "appliance/autocal/bundle_adjust.h"
#include "appliance/autocal/camera_clipping.h"
#include "appliance/autocal/camera_timing.h"
#include "appliance/autocal/colour_calibration.h"
#include "appliance/autocal/gray_code.h"
#include "appliance/autocal/model_trials.h"
#include "appliance/autocal/screen_geometry.h"
#include "appliance/warp/calibration_validation.h"
#include "appliance/warp/ideal_calibration.h"
#include "appliance/warp/response_curve.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao::autocal {
namespace {

// The start's edge gate with the screen still to be fitted, in units of AutocalOptions::max_edge_rms_m.
constexpr double kStartEdgeGateScale = 5.0;

constexpr double kDeg = std::numbers::pi / 180.0;

// A straight piece of a device's image border, image positions (pixel centres at +0.5).
struct BorderPiece {
    Eigen::Vector2d a;
    Eigen::Vector2d b;
};

void check_inputs(const CalibrationPrior& prior, ImageSize content, const AutocalOptions& o) {
    const auto fail = [](const std::string& what) { throw std::invalid_argument("calibrate: " + what); };
    if (prior.projectors.empty() || prior.projectors.size() > 16) fail("prior.projectors: 1..16 projectors");
    if (content.width < 1 || content.height < 1 || content.width > 16384 || content.height > 16384)
        fail("content: 1..16384 per side");
    if (o.warp_step_px < 1 || o.warp_step_px > 64) fail("options.warp_step_px: 1..64");
    if (!(o.blend_ramp > 0.0 && o.blend_ramp <= 0.5)) fail("options.blend_ramp: (0, 0.5]");
    if (!(o.max_predicted_seam > 0.0 && o.max_predicted_seam <= 1.0)) fail("options.max_predicted_seam: (0, 1]");
    if (!(o.max_frame_straddle >= 0.0 && o.max_frame_straddle <= 1.0)) fail("options.max_frame_straddle: [0, 1]");
    if (!(o.shadow_relative >= 0.0 && o.shadow_relative <= 0.5)) fail("options.shadow_relative: [0, 0.5]");
    if (o.max_gray_bits != 0 && (o.max_gray_bits < o.min_bits || o.max_gray_bits > 16)) {
        fail("options.max_gray_bits: 0 (all) or min_bits (" + std::to_string(o.min_bits) + ")..16, got " +
             std::to_string(o.max_gray_bits));
    }
    if (o.frames_per_pattern < 1 || o.frames_per_pattern > 64) {
        fail("options.frames_per_pattern: 1..64, got " + std::to_string(o.frames_per_pattern));
    }
    if (o.phase_shifts != 0 && (o.phase_shifts < 3 || o.phase_shifts > 16)) {
        fail("options.phase_shifts: 0 (off) or 3..16, got " + std::to_string(o.phase_shifts));
    }
    if (!(o.phase_period_px >= 4.0 && o.phase_period_px <= 1024.0)) {
        fail("options.phase_period_px: 4..1024, got " + std::to_string(o.phase_period_px));
    }
    if (!(o.phase_gamma > 0.0 && o.phase_gamma <= 10.0)) fail("options.phase_gamma: (0, 10]");
    if (!(o.phase_sigma_floor_px > 0.0)) fail("options.phase_sigma_floor_px: > 0");
    if (!(o.shadow_noise_sigmas >= 0.0)) fail("options.shadow_noise_sigmas: >= 0");
    if (!(o.bow_min_gain >= 0.0 && o.bow_min_gain < 1.0)) fail("options.bow_min_gain: [0, 1)");
    if (!(o.max_heights_shift_px > 0.0)) fail("options.max_heights_shift_px: > 0");
    if (!(o.camera_sigma.focal > 0.0 && o.camera_sigma.principal_point > 0.0 && o.camera_sigma.distortion > 0.0)) {
        fail("options.camera_sigma: focal, principal_point and distortion > 0");
    }
    if (!(o.camera_sigma_gate > 0.0 && o.camera_sigma_gate <= 1.0)) fail("options.camera_sigma_gate: (0, 1]");
    if (!(o.intrinsics_min_gain >= 0.0 && o.intrinsics_min_gain < 1.0)) fail("options.intrinsics_min_gain: [0, 1)");
    if (!(o.distortion_min_gain >= 0.0 && o.distortion_min_gain < 1.0)) fail("options.distortion_min_gain: [0, 1)");
    if (!(prior.screen.radius_m > 0.0 && prior.screen.arc_deg > 0.0 && prior.screen.top_m > prior.screen.bottom_m)) {
        fail("prior.screen: radius_m > 0, arc_deg > 0, top_m > bottom_m");
    }
    for (const DeviceModel& p : prior.projectors) {
        if (p.resolution.width < 16 || p.resolution.height < 16 || !(p.fx_px > 0.0) || !(p.fy_px > 0.0)) {
            fail("prior.projectors '" + p.id + "': resolution >= 16x16 and focal lengths > 0");
        }
    }
}

// Screen point of a pinhole device's image position as (theta, h), or NaN.
Eigen::Vector2d device_screen(const DeviceModel& d, const ScreenModel& s, double x, double y) {
    const Eigen::Vector3d dir = d.rotation * device_ray(d, x, y);
    const auto hit = cylinder_hit(s, d.position_m, dir);
    if (!hit) return {std::nan(""), std::nan("")};
    return {std::atan2(hit->x(), -hit->z()), hit->y()};
}

bool lands_on_screen(const DeviceModel& d, const ScreenModel& s, const Eigen::Vector2d& xy) {
    const Eigen::Vector2d th = device_screen(d, s, xy.x(), xy.y());
    return std::isfinite(th.x()) && std::abs(th.x()) <= s.arc_deg * kDeg / 2.0 && th.y() >= s.bottom_m &&
           th.y() <= s.top_m;
}

// The parts of d's image border whose rays land on the screen, as straight pieces in its image. Each
// side is walked in steps of at most 4 px; each change between on and off the screen is located by
// bisection to 1e-6 of the side. A border beyond the screen's top, bottom or arc end is no overlap
// edge: the blend ramps run across the overlaps only.
std::vector<BorderPiece> on_screen_border(const DeviceModel& d, const ScreenModel& s) {
    const double w = d.resolution.width;
    const double h = d.resolution.height;
    const std::array<std::array<Eigen::Vector2d, 2>, 4> sides{{{Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0)},
                                                               {Eigen::Vector2d(w, 0), Eigen::Vector2d(w, h)},
                                                               {Eigen::Vector2d(w, h), Eigen::Vector2d(0, h)},
                                                               {Eigen::Vector2d(0, h), Eigen::Vector2d(0, 0)}}};
    std::vector<BorderPiece> pieces;
    for (const auto& side : sides) {
        // Named copies, not structured bindings: clang 14 cannot capture a binding in a lambda.
        const Eigen::Vector2d a = side[0];
        const Eigen::Vector2d b = side[1];
        const auto at = [&](double t) -> Eigen::Vector2d { return a + t * (b - a); };
        const auto on = [&](double t) { return lands_on_screen(d, s, at(t)); };
        const int steps = std::max(16, static_cast<int>(std::ceil((b - a).norm() / 4.0)));
        bool was_on = on(0.0);
        double start = 0.0;
        for (int i = 1; i <= steps; ++i) {
            const double t = static_cast<double>(i) / steps;
            if (on(t) == was_on) continue;
            double lo = static_cast<double>(i - 1) / steps;
            double hi = t;
            while (hi - lo > 1e-6) {
                const double mid = 0.5 * (lo + hi);
                if (on(mid) == was_on) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            if (was_on) pieces.push_back({at(start), at(lo)});
            start = hi;
            was_on = !was_on;
        }
        if (was_on) pieces.push_back({at(start), b});
    }
    return pieces;
}

double distance_to(const BorderPiece& piece, const Eigen::Vector2d& p) {
    const Eigen::Vector2d ab = piece.b - piece.a;
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0.0 ? std::clamp((p - piece.a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (piece.a + t * ab - p).norm();
}

// Distance of screen point (theta, h) from the on-screen parts of device d's image border
// (on_screen_border), in its pixels; 0 outside its image, infinite where no part of its border lies on
// the screen. The Euclidean distance to a fixed closed set is 1-Lipschitz, so the weight built on it is
// continuous everywhere on the screen: no test flips from one pixel to the next (Raskar et al. 1999,
// "Multi-projector displays using camera-based registration", and Raskar et al. 1998, "The office of
// the future": the weight falls with the distance to the edge of the projector's footprint on the
// display surface).
double border_distance(const DeviceModel& d, const std::vector<BorderPiece>& border, const ScreenModel& s,
                       const Eigen::Vector2d& th) {
    const Eigen::Vector3d q = d.rotation.transpose() * (screen_position(s, th.x(), th.y()) - d.position_m);
    if (q.z() <= 0.0) return 0.0;
    const Eigen::Vector2d p = device_image(d, q);
    if (!(p.x() >= 0.0 && p.x() <= d.resolution.width && p.y() >= 0.0 && p.y() <= d.resolution.height)) return 0.0;
    double best = std::numeric_limits<double>::infinity();
    for (const BorderPiece& piece : border) best = std::min(best, distance_to(piece, p));
    return best;
}

ProjectorCalibration build_projector(const std::vector<DeviceModel>& fitted,
                                     const std::vector<std::vector<BorderPiece>>& borders, std::size_t k,
                                     const ScreenModel& s, const AutocalOptions& o) {
    const DeviceModel& d = fitted[k];
    ProjectorCalibration pc;
    pc.id = d.id;
    pc.output = d.resolution;
    const ImageSize grid{std::max(2, (d.resolution.width + o.warp_step_px - 1) / o.warp_step_px),
                         std::max(2, (d.resolution.height + o.warp_step_px - 1) / o.warp_step_px)};
    pc.warp.size = grid;
    pc.blend.size = grid;
    pc.warp.uv.resize(static_cast<std::size_t>(grid.pixel_count()) * 2);
    pc.blend.weight.resize(static_cast<std::size_t>(grid.pixel_count()));
    const double arc = s.arc_deg * kDeg;
    for (int gy = 0; gy < grid.height; ++gy) {
        for (int gx = 0; gx < grid.width; ++gx) {
            const std::size_t i = static_cast<std::size_t>(gy) * grid.width + gx;
            // grid_to_output is in pixel-index coordinates (centre at x); the models use image
            // positions (centre at x + 0.5).
            const double x = grid_to_output(gx, d.resolution.width, grid.width) + 0.5;
            const double y = grid_to_output(gy, d.resolution.height, grid.height) + 0.5;
            const Eigen::Vector2d th = device_screen(d, s, x, y);
            pc.warp.uv[2 * i] = static_cast<float>((th.x() + arc / 2.0) / arc);
            pc.warp.uv[2 * i + 1] = static_cast<float>((s.top_m - th.y()) / (s.top_m - s.bottom_m));
            const bool on =
                std::isfinite(th.x()) && std::abs(th.x()) <= arc / 2.0 && th.y() >= s.bottom_m && th.y() <= s.top_m;
            double sum = 0.0;
            double own = 0.0;
            for (std::size_t j = 0; j < fitted.size() && on; ++j) {
                const double ramp = o.blend_ramp * fitted[j].resolution.width;
                const double f = smooth_ramp(border_distance(fitted[j], borders[j], s, th) / ramp);
                sum += f;
                if (j == k) own = f;
            }
            pc.blend.weight[i] = sum > 0.0 ? static_cast<float>(std::clamp(own / sum, 0.0, 1.0)) : 0.0f;
        }
    }
    pc.response = make_gamma_response(2.2);
    return pc;
}

// Per blend grid sample of device d (grid of `size` samples, row-major): 1 where its output position
// lands on the screen (the samples build_projector gives a weight), 0 where the blend is 0 for being off it.
std::vector<char> grid_on_screen(const DeviceModel& d, const ScreenModel& s, ImageSize size) {
    std::vector<char> on(static_cast<std::size_t>(size.pixel_count()));
    for (int gy = 0; gy < size.height; ++gy) {
        for (int gx = 0; gx < size.width; ++gx) {
            const Eigen::Vector2d xy(grid_to_output(gx, d.resolution.width, size.width) + 0.5,
                                     grid_to_output(gy, d.resolution.height, size.height) + 0.5);
            on[static_cast<std::size_t>(gy) * size.width + gx] = lands_on_screen(d, s, xy) ? 1 : 0;
        }
    }
    return on;
}

// Whether output pixel (x, y) of pc reads (bilinearly, warp_sampling.h) a blend sample that lies off the
// screen: the band, one grid cell wide, along the screen's edge where every projector's weight falls to
// its off-screen 0 alike. That is the screen's edge as the grid draws it, not a seam between projectors.
bool reads_off_screen(const std::vector<char>& on_screen, const ProjectorCalibration& pc, int x, int y) {
    const ImageSize g = pc.blend.size;
    const double gx = std::clamp(output_to_grid(x, pc.output.width, g.width), 0.0, g.width - 1.0);
    const double gy = std::clamp(output_to_grid(y, pc.output.height, g.height), 0.0, g.height - 1.0);
    const int x0 = static_cast<int>(gx);
    const int y0 = static_cast<int>(gy);
    for (int j = y0; j <= std::min(y0 + 1, g.height - 1); ++j) {
        for (int i = x0; i <= std::min(x0 + 1, g.width - 1); ++i) {
            if (!on_screen[static_cast<std::size_t>(j) * g.width + i]) return true;
        }
    }
    return false;
}

// The predicted seam gate (AutocalOptions::max_predicted_seam): a blend whose weights do not sum to 1
// across the overlaps shows as a bright or dark line, which neither the projector fits nor the camera
// pose see. Throws CalibrationRefused naming the figure, its value and its limit.
void check_predicted_seam(const PredictedSeam& predicted, const std::vector<DeviceModel>& projectors,
                          const AutocalOptions& o) {
    if (predicted.deviation <= o.max_predicted_seam) return;
    const std::string where = predicted.projector < 0
                                  ? std::string()
                                  : " at projector " + std::to_string(predicted.projector) + " '" +
                                        projectors[static_cast<std::size_t>(predicted.projector)].id + "' pixel (" +
                                        std::to_string(predicted.x) + ", " + std::to_string(predicted.y) +
                                        "), screen theta " + std::to_string(predicted.theta_rad / kDeg) + " deg, h " +
                                        std::to_string(predicted.h_m) + " m";
    throw CalibrationRefused(
        "blend: predicted seam (max |sum of the blend weights - 1| over the overlaps, from the fitted models at every "
        "projector pixel) " +
        std::to_string(predicted.deviation) + where + " above its gate max_predicted_seam " +
        std::to_string(o.max_predicted_seam) +
        ": a line or spot of that much luminance would show there (a weight that jumps, or two projectors' image edges "
        "crossing on the screen, where every overlap's weights meet at a point)");
}

}  // namespace

Eigen::Vector2d projector_content(const DeviceModel& projector, const ScreenModel& screen, double x, double y) {
    const Eigen::Vector2d th = device_screen(projector, screen, x, y);
    const double arc = screen.arc_deg * kDeg;
    return {(th.x() + arc / 2.0) / arc, (screen.top_m - th.y()) / (screen.top_m - screen.bottom_m)};
}

void require_locked_exposure(const PatternSource& source) {
    if (!source.exposure_locked()) {
        throw CalibrationRefused(
            "camera auto-exposure is not locked: every image is metered on its own, so patterns cannot be compared "
            "(lock exposure, gain and white balance: V4L2 exposure_auto = manual, libcamera AeEnable = false; "
            "virtual rig: camera.auto_exposure = false)");
    }
}

cv::Mat1f show_averaged(PatternSource& source, const std::vector<cv::Mat>& signals, int frames) {
    if (frames < 1) throw std::invalid_argument("show_averaged: frames >= 1, got " + std::to_string(frames));
    cv::Mat1f sum = source.show(signals);
    if (frames == 1) return sum;
    sum = sum.clone();  // the source may hand out a buffer it reuses
    for (int f = 1; f < frames; ++f) sum += source.show(signals);
    sum *= 1.0f / static_cast<float>(frames);
    return sum;
}

namespace {

// Refused where the camera clips a projector's white too far, or its grey as well (camera_clipping.h).
void require_unclipped_edges(const DeclippedWhite& d, std::size_t projector) {
    const bool grey_clips = d.grey_clipped_pixels > kMaxGreyClippedShare * d.clipped_pixels + kMaxGreyClippedPixels;
    if (d.overdrive <= kMaxWhiteOverdrive && !grey_clips) return;
    char why[512];
    std::snprintf(
        why, sizeof why,
        "camera exposure: projector %zu's white is clipped by the camera on %d pixels, its light there %.2f "
        "times full scale (median; measured from its grey %.2f, itself clipped on %d pixels), above %.1f: "
        "the phase patterns' sinusoids are clipped on too many of their images; lower the camera's exposure or gain to "
        "%s1/%.1f of the present",
        projector, d.clipped_pixels, d.overdrive, kLitGreySignal, d.grey_clipped_pixels, kMaxWhiteOverdrive,
        grey_clips ? "under " : "about ", grey_clips ? 1.0 / kLitGreySignal / kLitGreySignal : d.overdrive);
    throw CalibrationRefused(why);
}

}  // namespace

cv::Mat1f lit_screen(PatternSource& source, const std::vector<ImageSize>& sizes, const cv::Mat1f& black, int frames,
                     int& captures) {
    cv::Mat1f lit(black.size(), 0.0f);
    for (std::size_t k = 0; k < sizes.size(); ++k) {
        std::vector<cv::Mat> signals(sizes.size());
        signals[k] = cv::Mat1f(sizes[k].height, sizes[k].width, 1.0f);
        const cv::Mat1f white = show_averaged(source, signals, frames).clone();  // the source may reuse its buffer
        signals[k] = cv::Mat1f(sizes[k].height, sizes[k].width, kLitGreySignal);
        const cv::Mat1f grey = show_averaged(source, signals, frames);
        captures += 2 * frames;
        const DeclippedWhite one = declip_white(white, grey, black);
        require_unclipped_edges(one, k);
        lit = cv::max(lit, one.light);
    }
    return lit;
}

namespace {

// The camera's timing (camera_timing.h), before any other pattern: refused naming the settle and the dropped frames.
void require_frames_after_the_flip(PatternSource& source, const std::vector<ImageSize>& sizes,
                                   const AutocalOptions& options, AutocalReport& report) {
    const FrameStraddle straddle = measure_frame_straddle(source, sizes, options.min_contrast, report.captures);
    report.frame_straddle = straddle.share;
    if (straddle.share <= options.max_frame_straddle) return;
    char why[512];
    std::snprintf(why, sizeof why,
                  "camera timing: the first camera frame after a pattern change still holds %.1f %% of the previous "
                  "pattern (measured on %d camera pixels; gate max_frame_straddle %.1f %%): its exposure straddles the "
                  "projectors' flip, or the camera hands out frames queued before it; wait longer after each flip or "
                  "drop more frames (mogao-calibrate site --settle-ms, --drop-frames; virtual rig: --drop-frames)",
                  100.0 * straddle.share, straddle.pixels, 100.0 * options.max_frame_straddle);
    throw CalibrationRefused(why);
}

// Whether the bundle adjustment fits any of the screen's shape (its radius and arc, or its top edge's height): the
// edge fit on the told screen is then only a start, gated after the adjustment (adopt_bundle), and the edge points
// are assigned again through the adjusted model (reselect_edges).
bool screen_fitted(const AutocalOptions& options) { return options.fit_screen || options.fit_heights; }

// Step 2: the projectors white minus all black show the screen's lit edges, and the camera's pose from them. Every
// projector white at once is shown too (what the camera saw: the images route writes it as camera-white.png).
EdgeFit fit_camera_to_lit_screen(PatternSource& source, const CalibrationPrior& prior,
                                 const std::vector<ImageSize>& sizes, const AutocalOptions& options,
                                 AutocalReport& report) {
    std::vector<cv::Mat> signals(sizes.size());
    const int frames = options.frames_per_pattern;
    const cv::Mat1f black = show_averaged(source, signals, frames).clone();  // the source may reuse its buffer
    for (std::size_t k = 0; k < sizes.size(); ++k) signals[k] = cv::Mat1f(sizes[k].height, sizes[k].width, 1.0f);
    (void)show_averaged(source, signals, frames);
    report.captures += 2 * frames;
    const cv::Mat1f lit = lit_screen(source, sizes, black, frames, report.captures);
    // With the screen still to be fitted, an edge fit on the prior's cylinder is only a start (the told screen and
    // the camera's prior intrinsics together left the lit edges 13 mm off it on realistic-install at full
    // resolution): its gate is five times looser here, a sanity limit, and the gate itself holds the bundle
    // adjustment's edge fit (adopt_bundle).
    AutocalOptions start_options = options;
    if (screen_fitted(options)) start_options.max_edge_rms_m = kStartEdgeGateScale * options.max_edge_rms_m;
    EdgeFit edge = fit_camera_pose(lit, prior, start_options);
    report.edge_points = edge.points;
    report.edge_rms_m = edge.rms_m;
    report.camera_position_m = edge.camera.position_m;
    return edge;
}

// Step 3 for projector k: its patterns decoded into correspondences and its model fitted from the camera's pose.
// Throws CalibrationRefused when too few Gray-code bits resolve.
ProjectorFit observe_projector(PatternSource& source, const CalibrationPrior& prior,
                               const std::vector<ImageSize>& sizes, std::size_t k, const EdgeFit& edge,
                               const AutocalOptions& options, AutocalReport& report) {
    const Correspondences c = decode_projector(source, static_cast<int>(k), sizes, options);
    report.captures += c.captures;
    ProjectorReport pr{prior.projectors[k].id, c.column_bits, c.row_bits, static_cast<int>(c.camera.size()), 0.0, 0.0};
    pr.lit_pixels = c.lit_pixels;
    pr.phase_refined = std::min(c.phase_refined_columns, c.phase_refined_rows);
    pr.noise_sigma = c.noise_sigma;
    if (c.column_bits < options.min_bits || c.row_bits < options.min_bits) {
        throw CalibrationRefused("projector " + std::to_string(k) + " '" + pr.id + "': Gray-code decoding failed: " +
                                 std::to_string(c.column_bits) + " column and " + std::to_string(c.row_bits) +
                                 " row bits resolved (need >= " + std::to_string(options.min_bits) + "; " +
                                 std::to_string(c.lit_pixels) + " camera pixels lit)");
    }
    // With the screen or the camera's intrinsics still to be fitted, a projector's fit on the prior's is only a
    // start: its gate is applied after the bundle adjustment instead.
    AutocalOptions start_options = options;
    if (options.fit_screen || options.refine_camera_intrinsics)
        start_options.max_projector_rms = std::numeric_limits<double>::infinity();
    ProjectorFit fit =
        fit_projector(edge.camera, prior, static_cast<int>(k), c.camera, c.projector, c.sigma, start_options);
    pr.rms_px = fit.rms_px;
    pr.mean_view_angle_deg = fit.mean_view_angle_deg;
    report.projectors.push_back(pr);
    return fit;
}

// Step 4's result taken into `result`, through the gates a fitted screen and fitted projectors must pass.
void adopt_bundle(const BundleResult& ba, const CalibrationPrior& prior, const AutocalOptions& options,
                  AutocalResult& result) {
    if (!(ba.screen.radius_m > 0.0 && ba.screen.arc_deg > 0.0 && ba.screen.arc_deg <= 360.0)) {
        throw CalibrationRefused("fitted screen: radius " + std::to_string(ba.screen.radius_m) + " m, arc " +
                                 std::to_string(ba.screen.arc_deg) +
                                 " deg is no cylinder screen (radius > 0, arc in (0, 360]): the prior is too far off");
    }
    result.screen = ba.screen;
    result.camera = ba.camera;
    result.projectors = ba.projectors;
    result.report.camera_position_m = ba.camera.position_m;
    result.report.edge_rms_m = ba.edge_rms_m;
    if (screen_fitted(options) && ba.edge_inliers > 0) result.report.edge_points = ba.edge_inliers;
    if (screen_fitted(options) && ba.edge_rms_m > options.max_edge_rms_m) {
        throw CalibrationRefused("camera pose: edge fit rms " + std::to_string(ba.edge_rms_m * 1000.0) +
                                 " mm above its gate " + std::to_string(options.max_edge_rms_m * 1000.0) +
                                 " mm after the bundle adjustment with the screen fitted (radius " +
                                 std::to_string(ba.screen.radius_m) + " m, arc " + std::to_string(ba.screen.arc_deg) +
                                 " deg, top " + std::to_string(ba.screen.top_m) +
                                 " m): the screen is not the prior's cylinder (--fit-screen where its radius or arc "
                                 "are known only roughly), or the camera's intrinsics are off");
    }
    for (std::size_t k = 0; k < ba.projectors.size(); ++k) {
        result.report.projectors[k].rms_px = ba.rms_px[k];
        result.report.projectors[k].rms_sigma = ba.rms_sigma[k];
        result.report.projectors[k].cells = ba.inliers[k];
        if ((options.fit_screen || options.refine_camera_intrinsics) && ba.rms_sigma[k] > options.max_projector_rms) {
            throw CalibrationRefused(
                "projector " + std::to_string(k) + " '" + prior.projectors[k].id + "': fit rms " +
                std::to_string(ba.rms_sigma[k]) + " (in units of the decoded positions' uncertainty) above its gate " +
                std::to_string(options.max_projector_rms) + " after the bundle adjustment (screen radius " +
                std::to_string(ba.screen.radius_m) + " m, arc " + std::to_string(ba.screen.arc_deg) +
                " deg; camera focal " + std::to_string(ba.camera.fx_px) +
                " px): decoding errors, or the screen is not a cylinder of the prior's heights?");
        }
    }
}

// With the screen fitted (its radius and arc, or its top edge): the edge points assigned again through the adjusted
// model (select_edges), and the adjustment run again on them from the prior's intrinsics and the adjusted poses and
// screen. The pose's edge fit assigned them through the prior's intrinsics and the told screen: on realistic-install at
// half resolution it left out 45 % of the top edge's points (the prior's errors put them more than kEdgeGateM off), and
// the intrinsics and the arc were then fitted to a part of the edge. (On a told screen the assignment is left as it
// was: assigned again, standard.toml with the camera's k1 0.01 off calibrated 0.72 px off instead of 0.24.) Returns the
// edges `ba` was adjusted on.
std::vector<EdgeObservation> reselect_edges(const EdgeFit& edge, const CalibrationPrior& prior,
                                            const std::vector<ProjectorObservations>& observations,
                                            const BundleOptions& bo, BundleResult& ba) {
    std::vector<EdgeObservation> edges = edge.edges;
    if (!bo.refine_screen && !bo.refine_heights) return edges;  // a told screen: assigned on it, as judged
    for (int round = 0; round < 2; ++round) {
        std::vector<EdgeObservation> again = select_edges(edge.candidates, ba.camera, ba.screen, kEdgeGateM);
        if (again.size() <= edges.size()) break;  // the same points, or fewer: keep the adjustment as it is
        DeviceModel start = ba.camera;  // the adjusted pose, the prior's intrinsics (the centre of their prior)
        start.fx_px = prior.camera.fx_px;
        start.fy_px = prior.camera.fy_px;
        start.cx_px = prior.camera.cx_px;
        start.cy_px = prior.camera.cy_px;
        start.distortion = prior.camera.distortion;
        ba = bundle_adjust(ba.screen, start, ba.projectors, again, observations, bo);
        edges = std::move(again);
    }
    return edges;
}

// On told heights: the final fit against one with the top edge free (trials::check_told_heights, with the freedoms
// the trials kept), refused when content would move by more than the gate between them.
void check_heights(const BundleResult& ba, const CalibrationPrior& prior, const std::vector<EdgeObservation>& edges,
                   const std::vector<ProjectorObservations>& observations, BundleOptions bo,
                   const AutocalOptions& options, AutocalReport& report) {
    bo.refine_projector_distortion.assign(report.distortion.size(), false);
    for (std::size_t k = 0; k < report.distortion.size(); ++k)
        bo.refine_projector_distortion[k] = report.distortion[k].kept;
    trials::check_told_heights(ba, edges, observations, bo, options, report.heights);
    const HeightsCheck& h = report.heights;
    if (!h.tried || h.shift_mean_px <= options.max_heights_shift_px) return;
    char why[640];
    std::snprintf(why, sizeof why,
                  "screen heights: the camera sees the top edge at %.4f m where %.4f m was told (bottom %.4f m as "
                  "told): content would move by %.2f px mean (%.2f max) in the projectors' pixels, above the gate "
                  "%.2f px (--max-heights-shift-px): measure the screen's heights again, or calibrate with "
                  "--fit-heights where its radius and arc are known (a radius or arc told wrong shows here too: "
                  "--fit-screen where they are known only roughly)",
                  h.fitted_top_m, prior.screen.top_m, prior.screen.bottom_m, h.shift_mean_px, h.shift_max_px,
                  options.max_heights_shift_px);
    throw CalibrationRefused(why);
}

}  // namespace

AutocalResult calibrate(PatternSource& source, const CalibrationPrior& prior, ImageSize content,
                        const AutocalOptions& options) {
    check_inputs(prior, content, options);
    require_locked_exposure(source);
    std::vector<ImageSize> sizes;
    for (const DeviceModel& p : prior.projectors) sizes.push_back(p.resolution);
    AutocalResult result;
    require_frames_after_the_flip(source, sizes, options, result.report);
    const EdgeFit edge = fit_camera_to_lit_screen(source, prior, sizes, options, result.report);
    result.camera = edge.camera;
    std::vector<ProjectorObservations> observations;
    for (std::size_t k = 0; k < sizes.size(); ++k) {
        ProjectorFit fit = observe_projector(source, prior, sizes, k, edge, options, result.report);
        result.projectors.push_back(fit.model);
        observations.push_back(std::move(fit.observations));
    }
    // Step 4: camera pose and projector models refined together on every observation.
    BundleOptions bo;
    bo.refine_screen = options.fit_screen;
    bo.refine_heights = options.fit_heights;
    bo.camera_sigma = options.camera_sigma;
    BundleResult ba = bundle_adjust(prior.screen, edge.camera, result.projectors, edge.edges, observations, bo);
    // The bow first: on a bowed screen free intrinsics take up part of the bow (k1, k2 bend the rays much as
    // the bow bends the screen); then the intrinsics, with the bow free too where it was kept.
    if (options.fit_bow) trials::try_bow(ba, edge.edges, observations, bo, options, result.report.bow);
    bo.refine_bow = result.report.bow.kept;
    trials::try_camera_intrinsics(ba, prior, edge.edges, observations, bo, options, result.report);
    bo.refine_camera_intrinsics = result.report.intrinsics.kept;
    const std::vector<EdgeObservation> edges = reselect_edges(edge, prior, observations, bo, ba);
    // Last, with what the other trials kept free: each projector's lens distortion.
    trials::try_projector_distortion(ba, prior, edges, observations, bo, options, result.report);
    if (!screen_fitted(options)) check_heights(ba, prior, edges, observations, bo, options, result.report);
    adopt_bundle(ba, prior, options, result);
    result.calibration = calibration_from_models(result.projectors, result.screen, content, options);
    result.report.predicted_seam = predicted_seam_deviation(result.projectors, result.screen, result.calibration);
    check_predicted_seam(result.report.predicted_seam, result.projectors, options);
    return result;
}

ScreenCalibration calibration_from_models(const std::vector<DeviceModel>& projectors, const ScreenModel& screen,
                                          ImageSize content, const AutocalOptions& options) {
    CalibrationPrior prior;
    prior.screen = screen;
    prior.projectors = projectors;
    check_inputs(prior, content, options);
    ScreenCalibration out;
    out.content = content;
    std::vector<std::vector<BorderPiece>> borders;
    for (const DeviceModel& d : projectors) borders.push_back(on_screen_border(d, screen));
    for (std::size_t k = 0; k < projectors.size(); ++k) {
        out.projectors.push_back(build_projector(projectors, borders, k, screen, options));
    }
    validate_screen(out);
    return out;
}

PredictedSeam predicted_seam_deviation(const std::vector<DeviceModel>& projectors, const ScreenModel& screen,
                                       const ScreenCalibration& calibration) {
    if (projectors.size() != calibration.projectors.size()) {
        throw std::invalid_argument("predicted_seam_deviation: " + std::to_string(projectors.size()) + " models for " +
                                    std::to_string(calibration.projectors.size()) + " projectors");
    }
    std::vector<std::vector<char>> on_screen;
    for (std::size_t k = 0; k < projectors.size(); ++k) {
        on_screen.push_back(grid_on_screen(projectors[k], screen, calibration.projectors[k].blend.size));
    }
    const double half_arc = 0.49 * screen.arc_deg * kDeg;  // content inset by 1 % of the frame on every side
    const double margin_m = 0.01 * (screen.top_m - screen.bottom_m);
    PredictedSeam worst;
    for (std::size_t k = 0; k < projectors.size(); ++k) {
        const ImageSize out = calibration.projectors[k].output;
        for (int y = 0; y < out.height; ++y) {
            for (int x = 0; x < out.width; ++x) {
                const Eigen::Vector2d th = device_screen(projectors[k], screen, x + 0.5, y + 0.5);
                if (!(std::abs(th.x()) <= half_arc && th.y() >= screen.bottom_m + margin_m &&
                      th.y() <= screen.top_m - margin_m)) {
                    continue;  // NaN (no hit) fails too
                }
                double sum = 0.0;
                int lit = 0;
                bool edge = false;
                for (std::size_t j = 0; j < projectors.size() && !edge; ++j) {
                    const ProjectorCalibration& pc = calibration.projectors[j];
                    const Eigen::Vector2d xy =
                        j == k ? Eigen::Vector2d(x, y) : model_pixel(projectors[j], screen, th.x(), th.y());
                    if (!xy.allFinite()) continue;
                    const int px = static_cast<int>(xy.x());
                    const int py = static_cast<int>(xy.y());
                    edge = reads_off_screen(on_screen[j], pc, px, py);
                    const float w = sample_blend(pc.blend, pc.output, px, py);
                    sum += w;
                    lit += w > 0.0F;
                }
                if (lit >= 2 && !edge && std::abs(sum - 1.0) > worst.deviation) {
                    worst = {std::abs(sum - 1.0), static_cast<int>(k), x, y, th.x(), th.y()};
                }
            }
        }
    }
    return worst;
}

std::array<double, 6> falloff_basis(const DeviceModel& d, double x, double y) {
    const double half_diagonal = 0.5 * std::hypot(d.resolution.width, d.resolution.height);
    const double u = (x - d.cx_px) / half_diagonal;
    const double v = (y - d.cy_px) / half_diagonal;
    return {1.0, u, v, u * u, u * v, v * v};
}

double falloff_at(const DeviceModel& d, double x, double y) {
    if (d.falloff.flat()) return 1.0;
    const std::array<double, 6> b = falloff_basis(d, x, y);
    double f = 0.0;
    for (std::size_t i = 0; i < b.size(); ++i) f += d.falloff.c[i] * b[i];
    return f;
}

std::optional<Eigen::Vector3d> falloff_out_of_range(const DeviceModel& d) {
    for (int j = 0; j <= 2; ++j) {
        for (int i = 0; i <= 2; ++i) {
            const double x = d.resolution.width * i / 2.0;
            const double y = d.resolution.height * j / 2.0;
            const double f = falloff_at(d, x, y);
            if (!(f >= 0.05 && f <= 5.0)) return Eigen::Vector3d(x, y, f);
        }
    }
    return std::nullopt;
}

CalibrationPrior with_bench_lenses(CalibrationPrior prior, const std::vector<std::optional<BenchLens>>& lenses) {
    if (lenses.size() > prior.projectors.size()) {
        throw std::invalid_argument("bench lenses: " + std::to_string(lenses.size()) + " given for " +
                                    std::to_string(prior.projectors.size()) + " projectors");
    }
    for (std::size_t k = 0; k < lenses.size(); ++k) {
        if (!lenses[k]) continue;
        const BenchLens& b = *lenses[k];
        DeviceModel& d = prior.projectors[k];
        const double sx = static_cast<double>(d.resolution.width) / b.size.width;
        const double sy = static_cast<double>(d.resolution.height) / b.size.height;
        if (!(std::abs(sx - sy) <= 1e-3 * std::max(sx, sy))) {
            throw std::invalid_argument(b.source + ": projector '" + d.id + "' runs at " +
                                        std::to_string(d.resolution.width) + "x" + std::to_string(d.resolution.height) +
                                        ", not a uniform scale of the bench's " + std::to_string(b.size.width) + "x" +
                                        std::to_string(b.size.height));
        }
        // A uniform rescale of the image about its (0, 0) corner, pixel edges staying edges.
        d.fx_px = b.fx_px * sx;
        d.fy_px = b.fy_px * sy;
        d.cx_px = b.cx_px * sx;
        d.cy_px = b.cy_px * sy;
        d.distortion = b.distortion;
    }
    return prior;
}

}  // namespace mogao::autocal
