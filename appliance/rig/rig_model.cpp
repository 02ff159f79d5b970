// SPDX-License-Identifier: Apache-2.0
// The rig description's checks and the geometry it shares with the virtual rig (rig_model.h).
#include "appliance/rig/rig_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

namespace mogao::rig {

// The normalised radius of a projector's image corner farthest from its distortion's centre.
double corner_radius(const RigProjector& p) {
    const RigIntrinsics& in = p.intrinsics;
    const double cx = in.cx_px + p.distortion_centre_px.x();
    const double cy = in.cy_px + p.distortion_centre_px.y();
    double corner = 0.0;
    for (const double x : {0.0, static_cast<double>(p.resolution.width)}) {
        for (const double y : {0.0, static_cast<double>(p.resolution.height)}) {
            corner = std::max(corner, std::hypot((x - cx) / in.fx_px, (y - cy) / in.fy_px));
        }
    }
    return corner;
}

std::optional<double> distortion_fold_radius(const std::array<double, 5>& k, double r_max) {
    for (int i = 0; i <= 100; ++i) {
        const double r = r_max * i / 100.0;
        const double r2 = r * r;
        if (!(1.0 + r2 * (3.0 * k[0] + r2 * (5.0 * k[1] + r2 * 7.0 * k[4])) > 0.0)) return r;
    }
    return std::nullopt;
}

namespace detail {

void check(bool ok, const std::string& field, const std::string& limit) {
    if (!ok) throw std::invalid_argument("rig: " + field + " must be " + limit);
}

void check_range(double v, double lo, double hi, const std::string& field) {
    check(std::isfinite(v) && v >= lo && v <= hi, field,
          "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " + std::to_string(v) + ")");
}

}  // namespace detail

namespace {

using detail::check;
using detail::check_range;

constexpr double kDeg = std::numbers::pi / 180.0;

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

// A projector's distortion (RigProjector::intrinsics.distortion): coefficients within the ranges a
// projection lens has, and the radial map r -> r (1 + k1 r^2 + k2 r^4 + k3 r^6) increasing out to 1.2
// times the normalised radius of the image's farthest corner (one ray per image position).
void validate_projector_distortion(const RigProjector& p, const std::string& f) {
    check_range(p.distortion_centre_px.x(), -0.25 * p.resolution.width, 0.25 * p.resolution.width,
                f + ".distortion_centre_px[0] (a quarter of the image's width)");
    check_range(p.distortion_centre_px.y(), -0.25 * p.resolution.height, 0.25 * p.resolution.height,
                f + ".distortion_centre_px[1] (a quarter of the image's height)");
    const auto& k = p.intrinsics.distortion;
    for (std::size_t i = 0; i < k.size(); ++i) {
        check_range(k[i], -kProjectorDistortionLimits[i], kProjectorDistortionLimits[i],
                    f + ".distortion[" + std::to_string(i) + "]");
    }
    const double corner = corner_radius(p);
    const double r_max = 1.2 * corner;
    const double r2 = r_max * r_max;
    check(!distortion_fold_radius(k, r_max) && r_max * (1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]))) > corner,
          f + ".distortion",
          "one-to-one out to 1.2 times the image's corners (d/dr of r (1 + k1 r^2 + k2 r^4 + k3 r^6) > 0 for r <= " +
              std::to_string(r_max) + ", and that radius mapped beyond the corners' " + std::to_string(corner) + ")");
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
    check_range(c.straddle, 0.0, 1.0, f + ".straddle");
    check(c.mjpeg_quality >= 0 && c.mjpeg_quality <= 100, f + ".mjpeg_quality",
          "0..100 (0 = raw frames; got " + std::to_string(c.mjpeg_quality) + ")");
    check(c.mjpeg_quality == 0 || c.bits == 8, f + ".mjpeg_quality",
          "0 unless bits = 8 (JPEG frames carry 8-bit samples; bits = " + std::to_string(c.bits) + ")");
}

// The errors the calibration is told the rig with (RigPrior): what it is told must still be a screen and a lens.
void validate_prior(const VirtualRig& rig) {
    const RigScreen& s = rig.screen;
    const RigPrior& e = rig.prior;
    check_range(e.screen_radius_error_m, -0.5 * s.radius_m, 0.5 * s.radius_m, "prior.screen_radius_error_m");
    check_range(e.screen_arc_error_deg, -0.5 * s.arc_deg, std::min(0.5 * s.arc_deg, 360.0 - s.arc_deg),
                "prior.screen_arc_error_deg");
    // Heights measured with a tape: each within a tenth of the screen's height (the told screen stays a screen).
    const double height = s.top_m - s.bottom_m;
    check_range(e.screen_bottom_error_m, -0.1 * height, 0.1 * height,
                "prior.screen_bottom_error_m (0.1 x the screen's height)");
    check_range(e.screen_top_error_m, -0.1 * height, 0.1 * height,
                "prior.screen_top_error_m (0.1 x the screen's height)");
    check_range(s.gain + e.screen_gain_error, 1.0, 3.0, "screen.gain + prior.screen_gain_error (the told gain)");
    check_range(s.half_gain_angle_deg + e.screen_half_gain_angle_error_deg, 10.0, 90.0,
                "screen.half_gain_angle_deg + prior.screen_half_gain_angle_error_deg (the told angle)");
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

}  // namespace

void validate_rig(const VirtualRig& rig) {
    const RigScreen& s = rig.screen;
    check_range(s.radius_m, 0.1, 100.0, "screen.radius_m");
    check_range(s.arc_deg, 1.0, 360.0, "screen.arc_deg");
    check(std::isfinite(s.bottom_m) && std::isfinite(s.top_m) && s.top_m - s.bottom_m >= 0.01, "screen.top_m",
          "at least 0.01 m above screen.bottom_m");
    check_range(s.bulge_m, -0.02 * s.radius_m, 0.02 * s.radius_m, "screen.bulge_m (2 % of radius_m)");
    check_range(s.gain, 1.0, 3.0, "screen.gain");
    check_range(s.half_gain_angle_deg, 10.0, 90.0, "screen.half_gain_angle_deg");
    check_range(s.interreflection, 0.0, 1.0, "screen.interreflection");
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
    for (int i = 0; i < 3; ++i) check_range(rig.viewer_m[i], -1e3, 1e3, "viewer_position_m");
    check(std::hypot(rig.viewer_m.x(), rig.viewer_m.z()) < s.radius_m - std::max(0.0, -s.bulge_m), "viewer_position_m",
          "inside the cylinder");
    check(rig.more_cameras.size() <= 7, "cameras", "1..8 cameras");
    validate_camera(rig.camera, s, "camera");
    for (std::size_t i = 0; i < rig.more_cameras.size(); ++i) {
        validate_camera(rig.more_cameras[i], s, "cameras[" + std::to_string(i + 1) + "]");
    }
    validate_prior(rig);
}

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

Eigen::Matrix3d device_to_screen(const RigPose& pose) {
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(pose.yaw_deg * kDeg, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(pose.pitch_deg * kDeg, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(pose.roll_deg * kDeg, Eigen::Vector3d::UnitZ()))
                                  .toRotationMatrix();
    // Device x right = screen +x, y down = -y, forward = -z at zero angles.
    return r * Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
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

}  // namespace mogao::rig
