// SPDX-License-Identifier: Apache-2.0
// The on-site self-check: marks through the new warp and blend, filmed, against where they belong (self_check.h).
#include "appliance/autocal/self_check.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "appliance/autocal/bundle_adjust.h"
#include "appliance/autocal/screen_geometry.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao::autocal {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

void check_options(const SelfCheckOptions& o) {
    const auto fail = [](const std::string& what) { throw std::invalid_argument("self-check: options." + what); };
    if (o.columns < 2 || o.rows < 2 || o.columns > 256 || o.rows > 256) fail("columns, rows: 2..256");
    if (!(o.inset > 0.0 && o.inset < 0.5)) fail("inset: (0, 0.5)");
    if (!(o.mark_sigma > 0.0 && o.mark_sigma <= 0.1)) fail("mark_sigma: (0, 0.1]");
    if (o.frames < 1 || o.frames > 64) fail("frames: 1..64");
    if (o.min_marks < 1) fail("min_marks: >= 1");
    if (!(o.max_view_angle_deg > 0.0 && o.max_view_angle_deg < 90.0)) fail("max_view_angle_deg: (0, 90)");
    if (!(o.max_mean_px > 0.0)) fail("max_mean_px (max_self_check_px): > 0");
}

Eigen::Vector2d mark_content(const SelfCheckOptions& o, int i, int j) {
    return {o.inset + (1.0 - 2.0 * o.inset) * i / (o.columns - 1), o.inset + (1.0 - 2.0 * o.inset) * j / (o.rows - 1)};
}

// Screen point (theta, h) of content (u, v) on screen s (autocal.h's convention).
Eigen::Vector2d content_screen(const ScreenModel& s, const Eigen::Vector2d& uv) {
    return {(uv.x() - 0.5) * s.arc_deg * kDeg, s.top_m - uv.y() * (s.top_m - s.bottom_m)};
}

// A projector's image position of screen point th (through its distortion, device_image), unclipped (NaN
// behind the device).
Eigen::Vector2d pinhole_pixel(const DeviceModel& d, const ScreenModel& s, const Eigen::Vector2d& th) {
    const Eigen::Vector3d q = d.rotation.transpose() * (screen_position(s, th.x(), th.y()) - d.position_m);
    if (q.z() <= 0.0) return {std::nan(""), std::nan("")};
    return device_image(d, q);
}

// The camera's image position of screen point th, through its distortion (OpenCV's Brown-Conrady model).
Eigen::Vector2d camera_pixel(const DeviceModel& c, const ScreenModel& s, const Eigen::Vector2d& th) {
    const Eigen::Vector3d q = c.rotation.transpose() * (screen_position(s, th.x(), th.y()) - c.position_m);
    if (q.z() <= 0.0) return {std::nan(""), std::nan("")};
    const double x = q.x() / q.z();
    const double y = q.y() / q.z();
    const auto& k = c.distortion;
    const double r2 = x * x + y * y;
    const double radial = 1.0 + k[0] * r2 + k[1] * r2 * r2 + k[4] * r2 * r2 * r2;
    const double xd = x * radial + 2.0 * k[2] * x * y + k[3] * (r2 + 2.0 * x * x);
    const double yd = y * radial + k[2] * (r2 + 2.0 * y * y) + 2.0 * k[3] * x * y;
    return {c.fx_px * xd + c.cx_px, c.fy_px * yd + c.cy_px};
}

// Screen point (theta, h) of camera image position xy through camera c, NaN when its ray misses.
Eigen::Vector2d camera_screen(const DeviceModel& c, const ScreenModel& s, const Eigen::Vector2d& xy) {
    const std::vector<Eigen::Vector3d> rays = camera_rays(c, {cv::Point2d(xy.x(), xy.y())});
    const Eigen::Vector3d p = ray_on_screen(s, c, rays[0]);
    return {std::atan2(p.x(), -p.z()), p.y()};
}

// Angle in degrees between camera c's ray to screen point th and the screen's normal there (the cylinder's
// radial direction: a bow's slope is left out).
double view_angle_deg(const DeviceModel& c, const ScreenModel& s, const Eigen::Vector2d& th) {
    const Eigen::Vector3d p = screen_position(s, th.x(), th.y());
    const Eigen::Vector3d normal(std::sin(th.x()), 0.0, -std::cos(th.x()));
    return std::acos(std::clamp(std::abs((p - c.position_m).normalized().dot(normal)), 0.0, 1.0)) / kDeg;
}

struct Mark {
    Eigen::Vector2d uv;
    int i = 0;
    int j = 0;
};

// The marks projector k shows: its fitted model puts the mark's centre at least 3 spot sigmas inside its
// image, and its blend weight there is above 0.
std::vector<Mark> marks_of(const AutocalResult& r, int k, const SelfCheckOptions& o) {
    const DeviceModel& d = r.projectors[static_cast<std::size_t>(k)];
    const ProjectorCalibration& pc = r.calibration.projectors[static_cast<std::size_t>(k)];
    const double sigma_m = o.mark_sigma * (r.screen.top_m - r.screen.bottom_m);
    std::vector<Mark> out;
    for (int j = 0; j < o.rows; ++j) {
        for (int i = 0; i < o.columns; ++i) {
            const Eigen::Vector2d uv = mark_content(o, i, j);
            const Eigen::Vector2d th = content_screen(r.screen, uv);
            const Eigen::Vector2d p = pinhole_pixel(d, r.screen, th);
            const Eigen::Vector2d q = pinhole_pixel(d, r.screen, th + Eigen::Vector2d(0.0, sigma_m));
            const double margin = 3.0 * (p - q).norm();
            if (!p.allFinite() || !q.allFinite() || p.x() < margin || p.y() < margin ||
                p.x() > d.resolution.width - margin || p.y() > d.resolution.height - margin) {
                continue;
            }
            const int px = static_cast<int>(p.x());
            const int py = static_cast<int>(p.y());
            if (sample_blend(pc.blend, pc.output, px, py) <= 0.0F) continue;
            out.push_back({uv, i, j});
        }
    }
    return out;
}

// Intensity-weighted centroid of the spot near `guess` in `lit` (window of half-size `half`, pixels above a
// fifth of the window's peak, re-centred three times); NaN when the window's peak is below `floor`.
Eigen::Vector2d spot_centroid(const cv::Mat1f& lit, Eigen::Vector2d guess, double half, double floor) {
    for (int round = 0; round < 4; ++round) {
        const int x0 = std::max(0, static_cast<int>(std::floor(guess.x() - 0.5 - half)));
        const int x1 = std::min(lit.cols - 1, static_cast<int>(std::ceil(guess.x() - 0.5 + half)));
        const int y0 = std::max(0, static_cast<int>(std::floor(guess.y() - 0.5 - half)));
        const int y1 = std::min(lit.rows - 1, static_cast<int>(std::ceil(guess.y() - 0.5 + half)));
        if (x1 <= x0 || y1 <= y0) return {std::nan(""), std::nan("")};
        float peak = 0.0F;
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) peak = std::max(peak, lit(y, x));
        if (!(peak > floor)) return {std::nan(""), std::nan("")};
        const double threshold = 0.2 * peak;
        double sw = 0.0;
        Eigen::Vector2d sum = Eigen::Vector2d::Zero();
        for (int y = y0; y <= y1; ++y) {
            for (int x = x0; x <= x1; ++x) {
                const double w = lit(y, x) - threshold;
                if (w <= 0.0) continue;
                sw += w;
                sum += w * Eigen::Vector2d(x + 0.5, y + 0.5);
            }
        }
        if (!(sw > 0.0)) return {std::nan(""), std::nan("")};
        guess = sum / sw;
    }
    return guess;
}

// Signed distance on the screen (metres) of where camera c's ray lands from the edge it was seen on.
double edge_distance(const ScreenModel& s, const DeviceModel& c, const Eigen::Vector3d& ray, ScreenEdge edge) {
    const Eigen::Vector3d x = ray_on_screen(s, c, ray);
    const double theta = std::atan2(x.x(), -x.z());
    const double half = s.arc_deg * kDeg / 2.0;
    switch (edge) {
        case ScreenEdge::top:
            return x.y() - s.top_m;
        case ScreenEdge::bottom:
            return x.y() - s.bottom_m;
        case ScreenEdge::left_end:
            return s.radius_m * (theta + half);
        case ScreenEdge::right_end:
            return s.radius_m * (theta - half);
    }
    return std::nan("");
}

DeviceModel posed(const DeviceModel& c, const Eigen::Matrix<double, 6, 1>& q) {
    DeviceModel out = c;
    const Eigen::Vector3d w = q.head<3>();
    if (w.norm() > 0.0) out.rotation = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * c.rotation;
    out.position_m = c.position_m + q.tail<3>();
    return out;
}

// The camera's pose fitted to the frame's edge points in camera pixels: each edge point's distance on the
// screen from its edge divided by the metres one camera pixel spans there across the edge, so that points
// seen at a grazing angle (near the camera, many millimetres per pixel) weigh what their pixels are worth.
// Gauss-Newton on the pose (small rotation in the screen frame, position), points beyond 4 median
// residuals dropped after the first round. Returns the camera and the rms in camera pixels.
DeviceModel pixel_edge_fit(const ScreenModel& s, const DeviceModel& start, const std::vector<EdgeObservation>& edges,
                           double& rms_px) {
    std::vector<Eigen::Vector3d> rays;
    std::vector<double> per_px;
    std::vector<ScreenEdge> which;
    for (const EdgeObservation& e : edges) {
        if (!e.image.allFinite()) continue;
        const Eigen::Vector2d xy = e.image;
        const std::vector<Eigen::Vector3d> r = camera_rays(
            start, {cv::Point2d(xy.x(), xy.y()), cv::Point2d(xy.x() + 1.0, xy.y()), cv::Point2d(xy.x(), xy.y() + 1.0)});
        const double d0 = edge_distance(s, start, r[0], e.edge);
        const double gx = edge_distance(s, start, r[1], e.edge) - d0;
        const double gy = edge_distance(s, start, r[2], e.edge) - d0;
        const double m = std::hypot(gx, gy);
        if (!std::isfinite(d0) || !(m > 0.0)) continue;
        rays.push_back(r[0]);
        per_px.push_back(m);
        which.push_back(e.edge);
    }
    std::vector<char> use(rays.size(), 1);
    DeviceModel c = start;
    const auto residual = [&](const DeviceModel& d, std::size_t i) {
        return edge_distance(s, d, rays[i], which[i]) / per_px[i];
    };
    for (int round = 0; round < 2; ++round) {
        for (int it = 0; it < 15; ++it) {
            Eigen::Matrix<double, 6, 6> n = Eigen::Matrix<double, 6, 6>::Zero();
            Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
            for (std::size_t i = 0; i < rays.size(); ++i) {
                const double r0 = residual(c, i);
                if (!use[i] || !std::isfinite(r0)) continue;
                Eigen::Matrix<double, 6, 1> j;
                for (int p = 0; p < 6; ++p) {
                    Eigen::Matrix<double, 6, 1> q = Eigen::Matrix<double, 6, 1>::Zero();
                    q[p] = 1e-6;
                    j[p] = (residual(posed(c, q), i) - r0) / 1e-6;
                }
                if (!j.allFinite()) continue;
                n += j * j.transpose();
                g += j * r0;
            }
            const Eigen::Matrix<double, 6, 1> step =
                -(n + 1e-9 * Eigen::Matrix<double, 6, 6>::Identity()).ldlt().solve(g);
            c = posed(c, step);
            if (step.norm() < 1e-9) break;
        }
        std::vector<double> abs_r;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const double r = residual(c, i);
            if (std::isfinite(r)) abs_r.push_back(std::abs(r));
        }
        if (abs_r.empty()) break;
        std::nth_element(abs_r.begin(), abs_r.begin() + static_cast<long>(abs_r.size() / 2), abs_r.end());
        const double limit = 4.0 * abs_r[abs_r.size() / 2];
        for (std::size_t i = 0; i < rays.size(); ++i) use[i] = std::abs(residual(c, i)) <= limit;
    }
    double sum = 0.0;
    int count = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const double r = residual(c, i);
        if (!use[i] || !std::isfinite(r)) continue;
        sum += r * r;
        ++count;
    }
    rms_px = count > 0 ? std::sqrt(sum / count) : 0.0;
    return c;
}

// The check's camera: the calibration's intrinsics (refined or the prior's), posed by the screen's lit frame
// alone (each projector's white minus black, lit_screen; edge points as in step 2 of autocal.h, fitted in camera
// pixels).
DeviceModel frame_camera(PatternSource& source, const CalibrationPrior& prior, const AutocalResult& r,
                         const SelfCheckOptions& o, SelfCheckResult& out) {
    const std::size_t n = r.projectors.size();
    std::vector<cv::Mat> signals(n);
    std::vector<ImageSize> sizes(n);
    for (std::size_t k = 0; k < n; ++k) sizes[k] = r.projectors[k].resolution;
    const cv::Mat1f black = show_averaged(source, signals, o.frames).clone();
    out.captures += o.frames;
    const cv::Mat1f lit = lit_screen(source, sizes, black, o.frames, out.captures);
    CalibrationPrior start = prior;
    start.screen = r.screen;
    start.camera = r.camera;
    const EdgeFit edge = fit_camera_pose(lit, start, AutocalOptions{});
    out.edge_points = edge.points;
    return pixel_edge_fit(r.screen, edge.camera, edge.edges, out.edge_rms_px);
}

struct Figures {
    double mean = 0.0;
    double p95 = 0.0;
    double max = 0.0;
};

Figures figures_of(std::vector<double> e) {
    Figures f;
    if (e.empty()) return f;
    std::sort(e.begin(), e.end());
    double sum = 0.0;
    for (double x : e) sum += x;
    f.mean = sum / static_cast<double>(e.size());
    f.p95 = e[std::min(e.size() - 1, static_cast<std::size_t>(0.95 * static_cast<double>(e.size())))];
    f.max = e.back();
    return f;
}

// Where mark m landed (its observed camera position through camera c onto the screen) against where it
// belongs, in its projector's pixels and in millimetres on the screen; false where either is not on it.
bool mark_error(const AutocalResult& r, const DeviceModel& c, const SelfCheckMark& m, double& px, double& mm) {
    const Eigen::Vector2d th = content_screen(r.screen, m.content);
    const Eigen::Vector2d landed = camera_screen(c, r.screen, m.camera_observed);
    const DeviceModel& d = r.projectors[static_cast<std::size_t>(m.projector)];
    const Eigen::Vector2d p_landed = pinhole_pixel(d, r.screen, landed);
    const Eigen::Vector2d p_belongs = pinhole_pixel(d, r.screen, th);
    if (!p_landed.allFinite() || !p_belongs.allFinite()) return false;
    px = (p_landed - p_belongs).norm();
    mm = 1e3 * (screen_position(r.screen, landed.x(), landed.y()) - screen_position(r.screen, th.x(), th.y())).norm();
    return true;
}

// Projector k's marks filmed: each found spot's observed camera position (camera_expected: where the check's
// camera expects it).
void film_marks(PatternSource& source, const AutocalResult& r, std::size_t k, const cv::Mat1f& black,
                const SelfCheckOptions& o, SelfCheckResult& out) {
    const std::vector<Mark> marks = marks_of(r, static_cast<int>(k), o);
    if (marks.empty()) return;
    std::vector<cv::Mat> signals(r.projectors.size());
    signals[k] = verification_signal(r, static_cast<int>(k), o);
    cv::Mat1f lit;
    cv::subtract(show_averaged(source, signals, o.frames), black, lit);
    out.captures += o.frames;
    if (out.filmed.empty()) out.filmed = cv::Mat1f(lit.size(), 0.0F);
    out.filmed += cv::max(lit, 0.0F);
    const double sigma_m = o.mark_sigma * (r.screen.top_m - r.screen.bottom_m);
    for (const Mark& m : marks) {
        ++out.shown;
        const Eigen::Vector2d th = content_screen(r.screen, m.uv);
        SelfCheckMark sm;
        sm.projector = static_cast<int>(k);
        sm.content = m.uv;
        sm.view_angle_deg = view_angle_deg(out.camera, r.screen, th);
        if (sm.view_angle_deg > o.max_view_angle_deg) {
            ++out.steep;
            continue;
        }
        // The search starts where the calibration's own camera expects the spot.
        const Eigen::Vector2d guess = camera_pixel(r.camera, r.screen, th);
        const double spot_px = (camera_pixel(r.camera, r.screen, th + Eigen::Vector2d(0.0, sigma_m)) - guess).norm();
        if (!guess.allFinite() || !std::isfinite(spot_px)) continue;
        sm.camera_expected = camera_pixel(out.camera, r.screen, th);
        sm.camera_observed = spot_centroid(lit, guess, std::max(3.0, 3.0 * spot_px), 0.05);
        if (!sm.camera_observed.allFinite()) continue;
        if (!mark_error(r, out.camera, sm, sm.error_px, sm.error_mm)) continue;
        out.marks.push_back(sm);
    }
}

}  // namespace

cv::Mat1f verification_signal(const AutocalResult& r, int k, const SelfCheckOptions& o) {
    check_options(o);
    const ProjectorCalibration& pc = r.calibration.projectors.at(static_cast<std::size_t>(k));
    std::vector<char> shown(static_cast<std::size_t>(o.columns) * o.rows, 0);
    for (const Mark& m : marks_of(r, k, o)) shown[static_cast<std::size_t>(m.j) * o.columns + m.i] = 1;
    const double arc_m = r.screen.arc_deg * kDeg * r.screen.radius_m;
    const double height_m = r.screen.top_m - r.screen.bottom_m;
    const double sigma_m = o.mark_sigma * height_m;
    const double du = (1.0 - 2.0 * o.inset) / (o.columns - 1);
    const double dv = (1.0 - 2.0 * o.inset) / (o.rows - 1);
    cv::Mat1f signal(pc.output.height, pc.output.width, 0.0F);
    for (int y = 0; y < pc.output.height; ++y) {
        for (int x = 0; x < pc.output.width; ++x) {
            const ContentUv uv = sample_warp(pc.warp, pc.output, x, y);
            if (!uv.valid() || sample_blend(pc.blend, pc.output, x, y) <= 0.0F) continue;
            const int i = std::clamp(static_cast<int>(std::lround((uv.u - o.inset) / du)), 0, o.columns - 1);
            const int j = std::clamp(static_cast<int>(std::lround((uv.v - o.inset) / dv)), 0, o.rows - 1);
            if (!shown[static_cast<std::size_t>(j) * o.columns + i]) continue;
            const Eigen::Vector2d c = mark_content(o, i, j);
            const double dx = (uv.u - c.x()) * arc_m;
            const double dy = (uv.v - c.y()) * height_m;
            signal(y, x) = static_cast<float>(std::exp(-(dx * dx + dy * dy) / (2.0 * sigma_m * sigma_m)));
        }
    }
    return signal;
}

SelfCheckResult run_self_check(PatternSource& source, const CalibrationPrior& prior, const AutocalResult& r,
                               const SelfCheckOptions& o) {
    check_options(o);
    require_locked_exposure(source);
    if (r.projectors.size() != r.calibration.projectors.size()) {
        throw std::invalid_argument("self-check: the calibration's models and maps differ in number");
    }
    SelfCheckResult out;
    out.camera = frame_camera(source, prior, r, o, out);
    std::vector<cv::Mat> signals(r.projectors.size());
    const cv::Mat1f black = show_averaged(source, signals, o.frames).clone();
    out.captures += o.frames;
    for (std::size_t k = 0; k < r.projectors.size(); ++k) film_marks(source, r, k, black, o, out);
    if (static_cast<int>(out.marks.size()) < o.min_marks) {
        throw CalibrationRefused(
            "self-check: " + std::to_string(out.marks.size()) + " of " + std::to_string(out.shown) +
            " verification marks found in the camera image (need >= " + std::to_string(o.min_marks) +
            "): the projectors do not show the new calibration where the camera sees them");
    }
    std::vector<double> px;
    std::vector<double> own;
    double mm = 0.0;
    for (const SelfCheckMark& m : out.marks) {
        px.push_back(m.error_px);
        mm += m.error_mm;
        double e = 0.0;
        double e_mm = 0.0;
        if (mark_error(r, r.camera, m, e, e_mm)) own.push_back(e);
    }
    const Figures f = figures_of(px);
    out.mean_px = f.mean;
    out.p95_px = f.p95;
    out.max_px = f.max;
    out.mean_mm = mm / static_cast<double>(out.marks.size());
    out.own_camera_mean_px = figures_of(own).mean;
    return out;
}

void check_self_check_gate(const SelfCheckResult& check, const SelfCheckOptions& o) {
    if (check.mean_px <= o.max_mean_px) return;
    throw CalibrationRefused(
        "self-check: the verification marks landed " + std::to_string(check.mean_px) + " projector pixels (mean; p95 " +
        std::to_string(check.p95_px) + ", " + std::to_string(check.mean_mm) + " mm on the screen) from where their " +
        "content belongs, above its gate max_self_check_px " + std::to_string(o.max_mean_px) +
        " (measured against the screen's frame; through the calibration's own camera " +
        std::to_string(check.own_camera_mean_px) +
        " px): the camera's intrinsics, its pose or the screen's size in the site file are off (a new chessboard "
        "calibration of the camera, the intrinsics' refinement where the command has it, or fitting the screen)");
}

nlohmann::json heights_check_report(const HeightsCheck& h, double gate_px) {
    return {{"tried", h.tried},
            {"fitted_top_m", h.fitted_top_m},
            {"shift_mean_px", h.shift_mean_px},
            {"shift_max_px", h.shift_max_px},
            {"gate_px", gate_px}};
}

nlohmann::json self_check_report(const SelfCheckResult& c, const SelfCheckOptions& o) {
    return {{"mean_px", c.mean_px},
            {"p95_px", c.p95_px},
            {"max_px", c.max_px},
            {"mean_mm", c.mean_mm},
            {"gate_max_mean_px", o.max_mean_px},
            {"own_camera_mean_px", c.own_camera_mean_px},
            {"marks_found", c.marks.size()},
            {"marks_shown", c.shown},
            {"marks_too_steep", c.steep},
            {"captures", c.captures},
            {"frame_edge_points", c.edge_points},
            {"frame_edge_rms_camera_px", c.edge_rms_px}};
}

}  // namespace mogao::autocal
