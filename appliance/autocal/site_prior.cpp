// SPDX-License-Identifier: Apache-2.0
// A rig description as the calibration's prior, and scaled (site_prior.h).
#include "appliance/autocal/site_prior.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Geometry>

namespace mogao::autocal {

namespace {

void scale_device(ImageSize& size, rig::RigIntrinsics& in, double s) {
    const ImageSize old = size;
    size = {std::max(16, static_cast<int>(std::lround(old.width * s))),
            std::max(16, static_cast<int>(std::lround(old.height * s)))};
    const double sx = static_cast<double>(size.width) / old.width;
    const double sy = static_cast<double>(size.height) / old.height;
    in.fx_px *= sx;
    in.fy_px *= sy;
    in.cx_px *= sx;
    in.cy_px *= sy;
}

}  // namespace

rig::VirtualRig scaled_rig(const rig::VirtualRig& rig, double projector_scale, double camera_scale) {
    if (!(projector_scale > 0.0 && projector_scale <= 1.0 && camera_scale > 0.0 && camera_scale <= 1.0)) {
        throw std::invalid_argument("scaled_rig: scales must be in (0, 1]");
    }
    rig::VirtualRig out = rig;
    for (rig::RigProjector& p : out.projectors) {
        const ImageSize before = p.resolution;
        scale_device(p.resolution, p.intrinsics, projector_scale);
        p.blur_px *= projector_scale;  // the same defocus on the screen, in the scaled projector's pixels
        // The same lens: its distortion's centre is in the projector's pixels too.
        p.distortion_centre_px.x() *= static_cast<double>(p.resolution.width) / before.width;
        p.distortion_centre_px.y() *= static_cast<double>(p.resolution.height) / before.height;
    }
    const ImageSize camera_before = out.camera.resolution;
    scale_device(out.camera.resolution, out.camera.intrinsics, camera_scale);
    // The prior's principal point error is in camera pixels: it scales with them.
    out.prior.camera_principal_point_error_px.x() *=
        static_cast<double>(out.camera.resolution.width) / camera_before.width;
    out.prior.camera_principal_point_error_px.y() *=
        static_cast<double>(out.camera.resolution.height) / camera_before.height;
    out.camera.blur_sigma_px *= camera_scale;
    for (rig::RigCamera& c : out.more_cameras) {  // every camera of the rig, not only the calibration's
        scale_device(c.resolution, c.intrinsics, camera_scale);
        c.blur_sigma_px *= camera_scale;
    }
    return out;
}

CalibrationPrior prior_from_rig(const rig::VirtualRig& rig) {
    CalibrationPrior prior;
    const rig::RigPrior& e = rig.prior;
    // A bowed rig screen (bulge_m) is not told: the prior is the cylinder, its heights as the tape measured them.
    prior.screen = {rig.screen.radius_m + e.screen_radius_error_m,
                    rig.screen.arc_deg + e.screen_arc_error_deg,
                    rig.screen.bottom_m + e.screen_bottom_error_m,
                    rig.screen.top_m + e.screen_top_error_m,
                    {},
                    rig.screen.gain + e.screen_gain_error,
                    rig.screen.half_gain_angle_deg + e.screen_half_gain_angle_error_deg,
                    rig.viewer_m};
    const rig::RigCamera& c = rig.camera;
    rig::RigPose pose = c.pose;
    pose.position_m += e.camera_position_error_m;
    pose.yaw_deg += e.camera_angle_error_deg.x();
    pose.pitch_deg += e.camera_angle_error_deg.y();
    pose.roll_deg += e.camera_angle_error_deg.z();
    // The camera's intrinsics as a chessboard calibration leaves them: focal, principal point and
    // distortion each off by the prior's errors (the simulator films with the true lens).
    const double cf = 1.0 + e.camera_focal_error;
    std::array<double, 5> distortion = c.intrinsics.distortion;
    for (std::size_t i = 0; i < distortion.size(); ++i) distortion[i] += e.camera_distortion_error[i];
    prior.camera = {"camera",
                    c.resolution,
                    c.intrinsics.fx_px * cf,
                    c.intrinsics.fy_px * cf,
                    c.intrinsics.cx_px + e.camera_principal_point_error_px.x(),
                    c.intrinsics.cy_px + e.camera_principal_point_error_px.y(),
                    distortion,
                    rig::device_to_screen(pose),
                    pose.position_m,
                    {}};
    const double pf = 1.0 + e.projector_focal_error;
    for (const rig::RigProjector& p : rig.projectors) {
        prior.projectors.push_back({p.id,
                                    p.resolution,
                                    p.intrinsics.fx_px * pf,
                                    p.intrinsics.fy_px * pf,
                                    p.intrinsics.cx_px,
                                    p.intrinsics.cy_px,
                                    {},
                                    Eigen::Matrix3d::Identity(),
                                    Eigen::Vector3d::Zero(),
                                    {}});  // fall-off unknown before the colour step measures it
    }
    return prior;
}

}  // namespace mogao::autocal
