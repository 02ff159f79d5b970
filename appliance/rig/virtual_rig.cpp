// SPDX-License-Identifier: Apache-2.0
// The virtual rig: geometry (ground truth) and camera image formation. Formulas in virtual_rig.h.
#include "appliance/rig/virtual_rig.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace mogao::rig {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

void check(bool ok, const std::string& field, const std::string& limit) {
    if (!ok) throw std::invalid_argument("rig: " + field + " must be " + limit);
}

void check_range(double v, double lo, double hi, const std::string& field) {
    check(std::isfinite(v) && v >= lo && v <= hi, field,
          "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " + std::to_string(v) + ")");
}

void validate_size(ImageSize s, const std::string& field) {
    check(s.width >= 1 && s.width <= 16384 && s.height >= 1 && s.height <= 16384, field,
          "1..16384 per side (got " + std::to_string(s.width) + "x" + std::to_string(s.height) + ")");
}

void validate_intrinsics(const RigIntrinsics& in, ImageSize size, const std::string& field) {
    check_range(in.fx_px, 1e-3, 1e6, field + ".fx_px");
    check_range(in.fy_px, 1e-3, 1e6, field + ".fy_px");
    check_range(in.cx_px, -4.0 * size.width, 5.0 * size.width, field + ".cx_px");
    check_range(in.cy_px, -4.0 * size.height, 5.0 * size.height, field + ".cy_px");
    for (double d : in.distortion) check_range(d, -10.0, 10.0, field + ".distortion");
}

void validate_pose(const RigPose& pose, const RigScreen& screen, const std::string& field) {
    for (int i = 0; i < 3; ++i) check_range(pose.position_m[i], -1e3, 1e3, field + ".position_m");
    const double inner = screen.radius_m - std::max(0.0, -screen.bulge_m);
    check(std::hypot(pose.position_m.x(), pose.position_m.z()) < inner, field + ".position_m",
          "inside the cylinder (distance from the axis < radius_m - max(0, -bulge_m) = " + std::to_string(inner) + ")");
    check_range(pose.yaw_deg, -360.0, 360.0, field + ".yaw_deg");
    check_range(pose.pitch_deg, -89.0, 89.0, field + ".pitch_deg");
    check_range(pose.roll_deg, -180.0, 180.0, field + ".roll_deg");
}

// The far (forward) intersection of o + t d with the cylinder x^2 + z^2 = r^2, o inside.
std::optional<Eigen::Vector3d> hit_cylinder(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r) {
    const double a = d.x() * d.x() + d.z() * d.z();
    if (a < 1e-18) return std::nullopt;
    const double b = 2.0 * (o.x() * d.x() + o.z() * d.z());
    const double c = o.x() * o.x() + o.z() * o.z() - r * r;
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) return std::nullopt;
    const double t = (-b + std::sqrt(disc)) / (2.0 * a);
    if (t <= 0.0) return std::nullopt;
    return o + t * d;
}

// The screen's distance from the axis at (theta, h): the cylinder's radius plus the bulge's
// half-sine bow, zero on the frame (the arc's ends, the bottom and top edges) and bulge_m in the
// middle; the nominal radius outside the screen.
double radius_at(const RigScreen& screen, double theta, double h) {
    const double arc = screen.arc_deg * kDeg;
    if (screen.bulge_m == 0.0 || std::abs(theta) > arc / 2.0 || h < screen.bottom_m || h > screen.top_m) {
        return screen.radius_m;
    }
    return screen.radius_m + screen.bulge_m * std::cos(std::numbers::pi * theta / arc) *
                                 std::sin(std::numbers::pi * (h - screen.bottom_m) / (screen.top_m - screen.bottom_m));
}

// The far intersection of o + t d (o inside) with the screen surface r = radius_at(theta, h): the
// cylinder's intersection, then fixed-point steps through the cylinder of the radius at the last
// hit. Each step shrinks the error by about the bow's slope times the tangent of the ray's incidence;
// validate_rig bounds the slope (0.2), so a few dozen steps reach 1e-12 m but at grazing incidence.
std::optional<Eigen::Vector3d> hit_screen(const RigScreen& screen, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
    auto hit = hit_cylinder(o, d, screen.radius_m);
    if (!hit || screen.bulge_m == 0.0) return hit;
    for (int i = 0; i < 200; ++i) {
        const double r = radius_at(screen, std::atan2(hit->x(), -hit->z()), hit->y());
        const auto next = hit_cylinder(o, d, r);
        if (!next) return std::nullopt;
        const bool converged = (*next - *hit).norm() < 1e-12;
        hit = next;
        if (converged) return hit;
    }
    return std::nullopt;  // not converged: no ground truth rather than a wrong one
}

std::optional<ScreenPoint> on_screen(const RigScreen& screen, const Eigen::Vector3d& p) {
    const ScreenPoint s{std::atan2(p.x(), -p.z()), p.y()};
    const double half = screen.arc_deg * kDeg / 2.0;
    if (std::abs(s.theta_rad) > half || s.h_m < screen.bottom_m || s.h_m > screen.top_m) return std::nullopt;
    return s;
}

Eigen::Vector3d screen_position(const RigScreen& screen, ScreenPoint p) {
    const double r = radius_at(screen, p.theta_rad, p.h_m);
    return {r * std::sin(p.theta_rad), p.h_m, -r * std::cos(p.theta_rad)};
}

// The normalised radius of a projector's image corner farthest from its principal point.
double corner_radius(const RigProjector& p) {
    const RigIntrinsics& in = p.intrinsics;
    double corner = 0.0;
    for (const double x : {0.0, static_cast<double>(p.resolution.width)}) {
        for (const double y : {0.0, static_cast<double>(p.resolution.height)}) {
            corner = std::max(corner, std::hypot((x - in.cx_px) / in.fx_px, (y - in.cy_px) / in.fy_px));
        }
    }
    return corner;
}

// A projector's distortion (RigProjector::intrinsics.distortion): coefficients within the ranges a
// projection lens has, and the radial map r -> r (1 + k1 r^2 + k2 r^4 + k3 r^6) increasing out to 1.2
// times the normalised radius of the image's farthest corner (one ray per image position).
void validate_projector_distortion(const RigProjector& p, const std::string& f) {
    const auto& k = p.intrinsics.distortion;
    const std::array<double, 5> limit{1.0, 1.0, 0.1, 0.1, 1.0};
    for (std::size_t i = 0; i < k.size(); ++i) {
        check_range(k[i], -limit[i], limit[i], f + ".distortion[" + std::to_string(i) + "]");
    }
    const double corner = corner_radius(p);
    for (int i = 0; i <= 100; ++i) {
        const double r2 = std::pow(1.2 * corner * i / 100.0, 2);
        const double slope = 1.0 + r2 * (3.0 * k[0] + r2 * (5.0 * k[1] + r2 * 7.0 * k[4]));
        check(
            slope > 0.0 && (i < 100 || std::sqrt(r2) * (1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]))) > corner),
            f + ".distortion",
            "one-to-one out to 1.2 times the image's corners (d/dr of r (1 + k1 r^2 + k2 r^4 + k3 r^6) > 0 for r <= " +
                std::to_string(1.2 * corner) + ", and that radius mapped beyond the corners' " +
                std::to_string(corner) + ")");
    }
}

void validate_camera(const RigCamera& c, const RigScreen& s, const std::string& f) {
    validate_size(c.resolution, f + ".resolution");
    validate_intrinsics(c.intrinsics, c.resolution, f);
    validate_pose(c.pose, s, f);
    check_range(c.exposure, 1e-3, 100.0, f + ".exposure");
    check_range(c.gain, 1e-3, 100.0, f + ".gain");
    check_range(c.read_noise, 0.0, 0.5, f + ".read_noise");
    check_range(c.shot_noise, 0.0, 0.5, f + ".shot_noise");
    check_range(c.blur_sigma_px, 0.0, 20.0, f + ".blur_sigma_px");
    check(c.bits >= 1 && c.bits <= 16, f + ".bits", "1..16");
    check(c.supersample >= 1 && c.supersample <= 4, f + ".supersample", "1..4");
    check_range(c.vignetting, 0.0, 0.45, f + ".vignetting");
}

// Light per projector pixel value before the fall-off, per channel: brightness * (black + (1 - black) * s^gamma),
// mean of channels.
double projector_light(const RigProjector& p, const float* v, int channels) {
    double sum = 0.0;
    for (int c = 0; c < 3; ++c) {
        const double s = std::clamp(static_cast<double>(v[channels == 3 ? c : 0]), 0.0, 1.0);
        const double lin = s <= 0.0 ? 0.0 : (s >= 1.0 ? 1.0 : std::pow(s, p.gamma[static_cast<std::size_t>(c)]));
        sum += p.brightness[static_cast<std::size_t>(c)] * (p.black_level + (1.0 - p.black_level) * lin);
    }
    return sum / 3.0;
}

// The light of projector p's image for `signal`, defocused (RigProjector::blur_px): Gaussian, +-4 sigma,
// zero beyond the image's border.
cv::Mat1f defocused_light(const RigProjector& p, const cv::Mat& signal) {
    cv::Mat1f out(signal.rows, signal.cols);
    for (int y = 0; y < signal.rows; ++y) {
        for (int x = 0; x < signal.cols; ++x) {
            out(y, x) =
                static_cast<float>(projector_light(p, signal.ptr<float>(y) + x * signal.channels(), signal.channels()));
        }
    }
    const int half = static_cast<int>(std::ceil(4.0 * p.blur_px));
    cv::GaussianBlur(out, out, cv::Size(2 * half + 1, 2 * half + 1), p.blur_px, p.blur_px, cv::BORDER_CONSTANT);
    return out;
}

}  // namespace

std::size_t camera_count(const VirtualRig& rig) { return 1 + rig.more_cameras.size(); }

VirtualRig seen_by(const VirtualRig& rig, std::size_t i) {
    if (i >= camera_count(rig)) {
        throw std::out_of_range("rig '" + rig.name + "': camera " + std::to_string(i) + " of " +
                                std::to_string(camera_count(rig)) + " (0.." + std::to_string(camera_count(rig) - 1) +
                                ")");
    }
    VirtualRig r = rig;
    if (i > 0) std::swap(r.camera, r.more_cameras[i - 1]);  // camera i first, the set unchanged
    return r;
}

// The errors the calibration is told the rig with (RigPrior): what it is told must still be a screen and a lens.
void validate_prior(const VirtualRig& rig) {
    const RigScreen& s = rig.screen;
    const RigPrior& e = rig.prior;
    check_range(e.screen_radius_error_m, -0.5 * s.radius_m, 0.5 * s.radius_m, "prior.screen_radius_error_m");
    check_range(e.screen_arc_error_deg, -0.5 * s.arc_deg, std::min(0.5 * s.arc_deg, 360.0 - s.arc_deg),
                "prior.screen_arc_error_deg");
    check_range(e.camera_focal_error, -0.5, 0.5, "prior.camera_focal_error");
    check_range(e.camera_principal_point_error_px.x(), -0.25 * rig.camera.resolution.width,
                0.25 * rig.camera.resolution.width, "prior.camera_principal_point_error_px[0]");
    check_range(e.camera_principal_point_error_px.y(), -0.25 * rig.camera.resolution.height,
                0.25 * rig.camera.resolution.height, "prior.camera_principal_point_error_px[1]");
    for (std::size_t i = 0; i < e.camera_distortion_error.size(); ++i) {
        check_range(e.camera_distortion_error[i], -1.0, 1.0,
                    "prior.camera_distortion_error[" + std::to_string(i) + "]");
    }
}

void validate_rig(const VirtualRig& rig) {
    const RigScreen& s = rig.screen;
    check_range(s.radius_m, 0.1, 100.0, "screen.radius_m");
    check_range(s.arc_deg, 1.0, 360.0, "screen.arc_deg");
    check(std::isfinite(s.bottom_m) && std::isfinite(s.top_m) && s.top_m - s.bottom_m >= 0.01, "screen.top_m",
          "at least 0.01 m above screen.bottom_m");
    check_range(s.bulge_m, -0.02 * s.radius_m, 0.02 * s.radius_m, "screen.bulge_m (2 % of radius_m)");
    // Its largest slope, pi |bulge| / the shorter of the screen's height and arc length, at most 0.2: a
    // slightly bowed screen (and the fixed-point intersection above converges).
    const double span = std::min(s.top_m - s.bottom_m, s.radius_m * s.arc_deg * kDeg);
    check(std::numbers::pi * std::abs(s.bulge_m) <= 0.2 * span, "screen.bulge_m",
          "at most 0.2 / pi of the screen's height and arc length (a slope of 0.2)");
    check(!rig.projectors.empty() && rig.projectors.size() <= 16, "projectors", "1..16 projectors");
    check_range(rig.ambient, 0.0, 10.0, "ambient");
    for (std::size_t k = 0; k < rig.projectors.size(); ++k) {
        const RigProjector& p = rig.projectors[k];
        const std::string f = "projectors[" + std::to_string(k) + "] '" + p.id + "'";
        check(!p.id.empty(), f + ".id", "non-empty");
        validate_size(p.resolution, f + ".resolution");
        validate_intrinsics(p.intrinsics, p.resolution, f);
        validate_projector_distortion(p, f);
        validate_pose(p.pose, s, f);
        for (double g : p.gamma) check_range(g, 0.1, 10.0, f + ".gamma");
        for (double b : p.brightness) check_range(b, 1e-3, 100.0, f + ".brightness");
        check_range(p.black_level, 0.0, 0.5, f + ".black_level");
        check_range(p.falloff, 0.0, 0.45, f + ".falloff");
        check_range(p.blur_px, 0.0, 10.0, f + ".blur_px");
    }
    check(rig.more_cameras.size() <= 7, "cameras", "1..8 cameras");
    validate_camera(rig.camera, s, "camera");
    for (std::size_t i = 0; i < rig.more_cameras.size(); ++i) {
        validate_camera(rig.more_cameras[i], s, "cameras[" + std::to_string(i + 1) + "]");
    }
    validate_prior(rig);
}

Eigen::Matrix3d device_to_screen(const RigPose& pose) {
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(pose.yaw_deg * kDeg, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(pose.pitch_deg * kDeg, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(pose.roll_deg * kDeg, Eigen::Vector3d::UnitZ()))
                                  .toRotationMatrix();
    // Device x right = screen +x, y down = -y, forward = -z at zero angles.
    return r * Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
}

double projector_falloff(const RigProjector& p, double x, double y) {
    const double half_diagonal = 0.5 * std::hypot(p.resolution.width, p.resolution.height);
    const double rho2 =
        (std::pow(x - p.intrinsics.cx_px, 2) + std::pow(y - p.intrinsics.cy_px, 2)) / (half_diagonal * half_diagonal);
    return 1.0 - p.falloff * std::min(rho2, 2.0);
}

Eigen::Vector2d distort(const std::array<double, 5>& k, double x, double y) {
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
    return {x * radial + 2.0 * k[2] * x * y + k[3] * (r2 + 2.0 * x * x),
            y * radial + k[2] * (r2 + 2.0 * y * y) + 2.0 * k[3] * x * y};
}

Eigen::Vector2d undistort(const std::array<double, 5>& k, double xd, double yd) {
    double x = xd;
    double y = yd;
    for (int i = 0; i < 200; ++i) {
        const double r2 = x * x + y * y;
        const double radial = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
        const double nx = (xd - 2.0 * k[2] * x * y - k[3] * (r2 + 2.0 * x * x)) / radial;
        const double ny = (yd - k[2] * (r2 + 2.0 * y * y) - 2.0 * k[3] * x * y) / radial;
        const bool done = std::abs(nx - x) + std::abs(ny - y) < 1e-14;
        x = nx;
        y = ny;
        if (done) break;
    }
    return {x, y};
}

double camera_vignetting(const RigCamera& c, double x, double y) {
    if (c.vignetting == 0.0) return 1.0;
    const double half_diagonal = 0.5 * std::hypot(c.resolution.width, c.resolution.height);
    const double rho2 =
        (std::pow(x - c.intrinsics.cx_px, 2) + std::pow(y - c.intrinsics.cy_px, 2)) / (half_diagonal * half_diagonal);
    return 1.0 - c.vignetting * std::min(rho2, 2.0);
}

std::optional<ScreenPoint> projector_to_screen(const VirtualRig& rig, int k, double x, double y) {
    const RigProjector& p = rig.projectors.at(static_cast<std::size_t>(k));
    const RigIntrinsics& in = p.intrinsics;
    Eigen::Vector3d d_dev((x - in.cx_px) / in.fx_px, (y - in.cy_px) / in.fy_px, 1.0);
    if (in.distortion != std::array<double, 5>{}) {
        const Eigen::Vector2d u = undistort(in.distortion, d_dev.x(), d_dev.y());
        const Eigen::Vector2d back = distort(in.distortion, u.x(), u.y());
        if (!((back - d_dev.head<2>()).norm() < 1e-10)) return std::nullopt;  // not converged: no ground truth
        d_dev.head<2>() = u;
    }
    const auto hit = hit_screen(rig.screen, p.pose.position_m, device_to_screen(p.pose) * d_dev);
    if (!hit) return std::nullopt;
    return on_screen(rig.screen, *hit);
}

std::optional<Eigen::Vector2d> screen_to_projector(const VirtualRig& rig, int k, ScreenPoint s) {
    const RigProjector& p = rig.projectors.at(static_cast<std::size_t>(k));
    const Eigen::Vector3d d =
        device_to_screen(p.pose).transpose() * (screen_position(rig.screen, s) - p.pose.position_m);
    if (d.z() <= 1e-9) return std::nullopt;
    const RigIntrinsics& in = p.intrinsics;
    Eigen::Vector2d n(d.x() / d.z(), d.y() / d.z());
    if (in.distortion != std::array<double, 5>{}) {
        // Far outside the image the polynomial folds back: only rays within the validated radius count.
        if (n.norm() > 1.2 * corner_radius(p)) return std::nullopt;
        n = distort(in.distortion, n.x(), n.y());
    }
    const Eigen::Vector2d xy(in.fx_px * n.x() + in.cx_px, in.fy_px * n.y() + in.cy_px);
    if (!(xy.x() >= 0.0 && xy.x() < p.resolution.width && xy.y() >= 0.0 && xy.y() < p.resolution.height)) {
        return std::nullopt;
    }
    return xy;
}

Eigen::Vector2d content_of(const RigScreen& screen, ScreenPoint p) {
    const double arc = screen.arc_deg * kDeg;
    return {(p.theta_rad + arc / 2.0) / arc, (screen.top_m - p.h_m) / (screen.top_m - screen.bottom_m)};
}

ScreenPoint screen_of(const RigScreen& screen, Eigen::Vector2d uv) {
    const double arc = screen.arc_deg * kDeg;
    return {uv.x() * arc - arc / 2.0, screen.top_m - uv.y() * (screen.top_m - screen.bottom_m)};
}

CameraSimulator::CameraSimulator(const VirtualRig& rig) : rig_(rig) {
    validate_rig(rig_);
    const RigCamera& cam = rig_.camera;
    const int ss = cam.supersample;
    samples_w_ = cam.resolution.width * ss;
    samples_h_ = cam.resolution.height * ss;
    const std::size_t n = static_cast<std::size_t>(samples_w_) * static_cast<std::size_t>(samples_h_);
    // Normalised distorted coordinates of every sample, undistorted by OpenCV's iterative inverse.
    std::vector<cv::Point2d> distorted(n);
    for (int y = 0; y < samples_h_; ++y) {
        for (int x = 0; x < samples_w_; ++x) {
            const double px = (x + 0.5) / ss;
            const double py = (y + 0.5) / ss;
            distorted[static_cast<std::size_t>(y) * samples_w_ + x] = {
                (px - cam.intrinsics.cx_px) / cam.intrinsics.fx_px, (py - cam.intrinsics.cy_px) / cam.intrinsics.fy_px};
        }
    }
    std::vector<cv::Point2d> ideal(n);
    cv::undistortPoints(distorted, ideal, cv::Matx33d::eye(), cam.intrinsics.distortion, cv::noArray(), cv::noArray(),
                        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-14));
    on_screen_.assign(n, 0);
    hit_.assign(rig_.projectors.size(), std::vector<std::int32_t>(n, -1));
    const Eigen::Matrix3d r = device_to_screen(cam.pose);
    cv::parallel_for_(cv::Range(0, samples_h_), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            for (int x = 0; x < samples_w_; ++x) {
                const std::size_t i = static_cast<std::size_t>(y) * samples_w_ + x;
                const Eigen::Vector3d d = r * Eigen::Vector3d(ideal[i].x, ideal[i].y, 1.0);
                const auto hit = hit_screen(rig_.screen, cam.pose.position_m, d);
                const auto s = hit ? on_screen(rig_.screen, *hit) : std::nullopt;
                if (!s) continue;
                on_screen_[i] = 1;
                for (std::size_t k = 0; k < rig_.projectors.size(); ++k) {
                    const auto xy = screen_to_projector(rig_, static_cast<int>(k), *s);
                    if (!xy) continue;
                    const int w = rig_.projectors[k].resolution.width;
                    hit_[k][i] = static_cast<std::int32_t>(std::floor(xy->y())) * w +
                                 static_cast<std::int32_t>(std::floor(xy->x()));
                }
            }
        }
    });
}

cv::Mat1f CameraSimulator::capture(const std::vector<cv::Mat>& signals, std::uint64_t frame) const {
    const std::size_t np = rig_.projectors.size();
    if (signals.size() != np) {
        throw std::invalid_argument("capture: " + std::to_string(signals.size()) + " signal images for " +
                                    std::to_string(np) + " projectors");
    }
    for (std::size_t k = 0; k < np; ++k) {
        const ImageSize r = rig_.projectors[k].resolution;
        const cv::Mat& s = signals[k];
        if (s.empty()) continue;
        if ((s.type() != CV_32FC1 && s.type() != CV_32FC3) || s.cols != r.width || s.rows != r.height ||
            !s.isContinuous()) {
            throw std::invalid_argument("capture: signals[" + std::to_string(k) +
                                        "] must be a continuous CV_32FC1 or CV_32FC3 of " + std::to_string(r.width) +
                                        "x" + std::to_string(r.height));
        }
    }
    const auto light = [&](std::size_t k, const float* v, int channels) {
        return projector_light(rig_.projectors[k], v, channels);
    };
    // Defocus (RigProjector::blur_px): each lit projector's light image, blurred; looked up in place of `light`.
    std::vector<cv::Mat1f> blurred(np);
    for (std::size_t k = 0; k < np; ++k) {
        if (rig_.projectors[k].blur_px > 0.0 && !signals[k].empty())
            blurred[k] = defocused_light(rig_.projectors[k], signals[k]);
    }
    const int ss = rig_.camera.supersample;
    const ImageSize res = rig_.camera.resolution;
    cv::Mat1f img(res.height, res.width, 0.0f);
    cv::parallel_for_(cv::Range(0, res.height), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            for (int x = 0; x < res.width; ++x) {
                double acc = 0.0;
                for (int sy = 0; sy < ss; ++sy) {
                    for (int sx = 0; sx < ss; ++sx) {
                        const std::size_t i = static_cast<std::size_t>(y * ss + sy) * samples_w_ + (x * ss + sx);
                        double l = on_screen_[i] ? rig_.ambient : 0.3 * rig_.ambient;
                        for (std::size_t k = 0; k < np; ++k) {
                            const std::int32_t h = hit_[k][i];
                            if (h < 0) continue;
                            const float zero = 0.0f;
                            const cv::Mat& s = signals[k];
                            const RigProjector& p = rig_.projectors[k];
                            const double f = p.falloff == 0.0 ? 1.0
                                                              : projector_falloff(p, h % p.resolution.width + 0.5,
                                                                                  h / p.resolution.width + 0.5);
                            if (!blurred[k].empty()) {
                                l += f * blurred[k](h / p.resolution.width, h % p.resolution.width);
                                continue;
                            }
                            l += f * (s.empty() ? light(k, &zero, 1)
                                                : light(k, s.ptr<float>() + static_cast<std::size_t>(h) * s.channels(),
                                                        s.channels()));
                        }
                        acc += l;
                    }
                }
                const double v = camera_vignetting(rig_.camera, x + 0.5, y + 0.5);
                img(y, x) = static_cast<float>(v == 1.0 ? acc / (ss * ss) : v * acc / (ss * ss));
            }
        }
    });
    const RigCamera& cam = rig_.camera;
    if (cam.blur_sigma_px > 0.0)
        cv::GaussianBlur(img, img, cv::Size(0, 0), cam.blur_sigma_px, cam.blur_sigma_px, cv::BORDER_REPLICATE);
    img *= cam.exposure * cam.gain;
    if (cam.auto_exposure) {
        const double mean = cv::mean(img)[0];
        if (mean > 0.0) img *= kAutoExposureTarget / mean;
    }
    cv::Mat1f noise(img.size());
    cv::RNG rng(cam.seed * 0x9E3779B97F4A7C15ULL + frame * 0xD1B54A32D192ED03ULL + 1);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
    const double levels = std::ldexp(1.0, cam.bits) - 1.0;
    for (int y = 0; y < img.rows; ++y) {
        for (int x = 0; x < img.cols; ++x) {
            const double v = img(y, x);
            const double sigma =
                std::sqrt(cam.read_noise * cam.read_noise + cam.shot_noise * cam.shot_noise * std::max(v, 0.0));
            const double q = std::round(std::clamp(v + sigma * noise(y, x), 0.0, 1.0) * levels) / levels;
            img(y, x) = static_cast<float>(q);
        }
    }
    return img;
}

void CameraSimulator::set_exposure(double exposure) {
    check_range(exposure, 1e-3, 100.0, "camera.exposure");
    rig_.camera.exposure = exposure;
}

double CameraSimulator::camera_coverage(int k) const {
    const std::vector<std::int32_t>& hits = hit_.at(static_cast<std::size_t>(k));
    const ImageSize r = rig_.projectors[static_cast<std::size_t>(k)].resolution;
    // Projector pixels in 8x8 blocks that some camera sample sees, over all blocks.
    const int bw = (r.width + 7) / 8;
    const int bh = (r.height + 7) / 8;
    std::vector<std::uint8_t> seen(static_cast<std::size_t>(bw) * bh, 0);
    for (std::int32_t h : hits) {
        if (h < 0) continue;
        seen[static_cast<std::size_t>((h / r.width) / 8) * bw + (h % r.width) / 8] = 1;
    }
    return static_cast<double>(std::count(seen.begin(), seen.end(), 1)) / static_cast<double>(seen.size());
}

}  // namespace mogao::rig
