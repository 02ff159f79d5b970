// SPDX-License-Identifier: Apache-2.0
// Camera models: image position -> world ray. Pure functions of the view request, no Embree.
//
// Image coordinates are continuous: (px, py) in [0, W] x [0, H] of the render size, x right,
// y down; pixel (x, y) has its centre at (x + 0.5, y + 0.5) (view/pixel_rect.h).
//
// Pose (view/view_request.h): world is right-handed, metres, +y up. The pose rotation is
// R = Ry(yaw) * Rx(pitch): yaw 0 looks along -z, +yaw turns left (counter-clockwise about +y seen
// from above), +pitch looks up. Camera frame columns of R: right (+x), up (+y), back (+z).
//
// Pinhole: vertical field of view fov, aspect = W / H of the render size,
//   d_cam = ( (2 px/W - 1) tan(fov/2) W/H,  (1 - 2 py/H) tan(fov/2),  -1 ),
//   ray = (pose.eye, normalize(R d_cam)).
// Cylinder screen (CylinderScreen in view/view_request.h, physical screen frame):
//   θ = -arc/2 + arc px/W,  y = top - (top - bottom) py/H,  S = (r sinθ, y, -r cosθ),
//   d_screen = S - eye_m   (from the physical eye through the screen point),
//   ray = (pose.eye, normalize(R d_screen))   (the physical eye is placed at pose.eye).
// With px = u + 0.5, py = v + 0.5 these are exactly the documented per-pixel formulas.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/pixel_rect.h"
#include "common/view_request.h"

namespace mogao {

struct Ray {
    Eigen::Vector3d origin;     // world metres
    Eigen::Vector3d direction;  // unit, world
};

// Everything generate_ray needs, precomputed once per frame.
struct CameraSetup {
    CameraModel model;
    ImageSize size;             // render size (after resolution_scale)
    Eigen::Vector3d eye;        // pose.eye, world metres
    Eigen::Matrix3d rotation;   // R = Ry(yaw) Rx(pitch): camera/screen frame -> world
    double tan_half_fov = 0.0;  // pinhole only
};

// Rotation of a pose (see above). Angles in degrees.
[[nodiscard]] Eigen::Matrix3d pose_rotation(double yaw_deg, double pitch_deg);

// Does not validate (see view_validation.h); render_size is the size rays are generated for.
[[nodiscard]] CameraSetup make_camera_setup(const ViewRequest& request, ImageSize render_size);

[[nodiscard]] Ray generate_ray(const CameraSetup& camera, double px, double py);

// The inverse of generate_ray: the image position (px, py) (continuous, the convention above) whose
// ray passes through world point `p` (metres). False when no ray does: `p` behind a pinhole or at
// its eye; for the cylinder screen, `p` straight above or below the eye or the eye outside the
// cylinder (r² <= eye_m.x² + eye_m.z²). A position outside [0, W] x [0, H] (beyond the arc, above
// the top) is returned as it is: the caller decides what is in the image.
// Cylinder: q = Rᵀ(p - eye) = t (S - eye_m) for the screen point S, so S = eye_m + s q with s = 1/t > 0
// the positive root of |e + s q|² = r² over x and z; then θ = atan2(S.x, -S.z), y = S.y.
[[nodiscard]] bool project_to_image(const CameraSetup& camera, const Eigen::Vector3d& p, double& px, double& py);

// The spread angle γ (radians) of one pixel's ray cone (texture_lod.h): pinhole
// atan(2 tan(fov/2) / H) (Ray Tracing Gems eq. 20.30); cylinder screen atan(s / d) with s the larger
// side of a pixel on the screen (metres: (top - bottom) / H, radius arc / W) and d the distance from
// the eye to the screen's centre point (θ = 0, mid-height). Scaled by max(1/8, 1/√spp) for spp > 1.
[[nodiscard]] double camera_cone_spread(const CameraSetup& camera, int spp);

// Cylinder screen: sin θ and cos θ of every column's centre (px = x + 0.5), computed once per
// frame so that rays through column centres (spp 1) need no trigonometry. Empty for a pinhole.
struct CylinderColumns {
    std::vector<double> sin_theta, cos_theta;  // size render width
};
[[nodiscard]] CylinderColumns make_cylinder_columns(const CameraSetup& camera);

// The ray of generate_ray(camera, x + 0.5, py), bit for bit, from the table (x in [0, width)).
// Falls back to generate_ray for a pinhole or an empty table.
[[nodiscard]] Ray generate_column_ray(const CameraSetup& camera, const CylinderColumns& columns, int x, double py);

}  // namespace mogao
