// SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "renderfarm/trace/camera.h"

namespace mogao {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

void expect_vec_near(const Eigen::Vector3d& got, const Eigen::Vector3d& want, double tol = 1e-12) {
    EXPECT_NEAR(got.x(), want.x(), tol) << "got " << got.transpose() << " want " << want.transpose();
    EXPECT_NEAR(got.y(), want.y(), tol) << "got " << got.transpose() << " want " << want.transpose();
    EXPECT_NEAR(got.z(), want.z(), tol) << "got " << got.transpose() << " want " << want.transpose();
}

ViewRequest pinhole_request(double yaw, double pitch) {
    ViewRequest r;
    r.size = {200, 100};
    r.camera = PinholeCamera{60.0};
    r.pose.eye = {1.0, 2.0, 3.0};
    r.pose.yaw_deg = yaw;
    r.pose.pitch_deg = pitch;
    return r;
}

TEST(PinholeCamera, CentreRayIsForwardAndStartsAtEye) {
    const ViewRequest r = pinhole_request(0.0, 0.0);
    const Ray ray = generate_ray(make_camera_setup(r, r.size), 100.0, 50.0);
    expect_vec_near(ray.origin, r.pose.eye);
    expect_vec_near(ray.direction, {0.0, 0.0, -1.0});
}

TEST(PinholeCamera, YawTurnsLeftAndPitchLooksUp) {
    const ViewRequest left = pinhole_request(90.0, 0.0);
    expect_vec_near(generate_ray(make_camera_setup(left, left.size), 100.0, 50.0).direction, {-1.0, 0.0, 0.0});
    const ViewRequest behind = pinhole_request(180.0, 0.0);
    expect_vec_near(generate_ray(make_camera_setup(behind, behind.size), 100.0, 50.0).direction, {0.0, 0.0, 1.0});
    const ViewRequest up = pinhole_request(0.0, 30.0);
    expect_vec_near(generate_ray(make_camera_setup(up, up.size), 100.0, 50.0).direction,
                    {0.0, std::sin(30.0 * kDeg), -std::cos(30.0 * kDeg)});
    // Yaw then pitch: looking left and up.
    const ViewRequest both = pinhole_request(90.0, 30.0);
    expect_vec_near(generate_ray(make_camera_setup(both, both.size), 100.0, 50.0).direction,
                    {-std::cos(30.0 * kDeg), std::sin(30.0 * kDeg), 0.0});
}

TEST(PinholeCamera, EdgesSpanFieldOfViewWithAspectFromRenderSize) {
    const ViewRequest r = pinhole_request(0.0, 0.0);
    const CameraSetup cam = make_camera_setup(r, r.size);
    const double t = std::tan(30.0 * kDeg);
    // Top edge centre: half the vertical fov above forward.
    expect_vec_near(generate_ray(cam, 100.0, 0.0).direction, Eigen::Vector3d(0.0, t, -1.0).normalized());
    // Right edge centre: aspect 2 widens the horizontal extent, +x is to the right.
    expect_vec_near(generate_ray(cam, 200.0, 50.0).direction, Eigen::Vector3d(2.0 * t, 0.0, -1.0).normalized());
    // Bottom-left corner.
    expect_vec_near(generate_ray(cam, 0.0, 100.0).direction, Eigen::Vector3d(-2.0 * t, -t, -1.0).normalized());
    // A pixel centre is at +0.5: pixel (0, 0) is half a pixel inside the corner.
    const double px = (2.0 * 0.5 / 200.0 - 1.0) * t * 2.0;
    const double py = (1.0 - 2.0 * 0.5 / 100.0) * t;
    expect_vec_near(generate_ray(cam, 0.5, 0.5).direction, Eigen::Vector3d(px, py, -1.0).normalized());
}

ViewRequest cylinder_request(double yaw) {
    ViewRequest r;
    r.size = {360, 120};
    CylinderScreen screen;
    screen.radius_m = 3.0;
    screen.arc_deg = 180.0;
    screen.bottom_m = 0.0;
    screen.top_m = 2.5;
    screen.eye_m = {0.0, 1.6, 0.5};
    r.camera = screen;
    r.pose.eye = {10.0, 1.7, -4.0};
    r.pose.yaw_deg = yaw;
    return r;
}

TEST(CylinderCamera, CornersAndCentreHitTheScreenFromThePhysicalEye) {
    const ViewRequest r = cylinder_request(0.0);
    const CameraSetup cam = make_camera_setup(r, r.size);
    const Eigen::Vector3d eye_m(0.0, 1.6, 0.5);
    // With a 180° arc the left/right edges are at theta = ∓90°: screen points (∓3, y, 0).
    const struct {
        double px, py;
        Eigen::Vector3d screen;
    } cases[] = {
        {0.0, 0.0, {-3.0, 2.5, 0.0}},      // top-left
        {360.0, 0.0, {3.0, 2.5, 0.0}},     // top-right
        {0.0, 120.0, {-3.0, 0.0, 0.0}},    // bottom-left
        {360.0, 120.0, {3.0, 0.0, 0.0}},   // bottom-right
        {180.0, 60.0, {0.0, 1.25, -3.0}},  // centre: middle of the arc, mid height
    };
    for (const auto& c : cases) {
        const Ray ray = generate_ray(cam, c.px, c.py);
        expect_vec_near(ray.origin, r.pose.eye);
        expect_vec_near(ray.direction, (c.screen - eye_m).normalized());
    }
}

TEST(CylinderCamera, PixelCentreFollowsDocumentedFormula) {
    const ViewRequest r = cylinder_request(0.0);
    const CameraSetup cam = make_camera_setup(r, r.size);
    const int u = 17;
    const int v = 100;
    const double theta = (-90.0 + 180.0 * (u + 0.5) / 360.0) * kDeg;
    const double y = 2.5 - 2.5 * (v + 0.5) / 120.0;
    const Eigen::Vector3d s(3.0 * std::sin(theta), y, -3.0 * std::cos(theta));
    expect_vec_near(generate_ray(cam, u + 0.5, v + 0.5).direction, (s - Eigen::Vector3d(0.0, 1.6, 0.5)).normalized());
}

TEST(CylinderCamera, PoseYawRotatesTheScreenFrame) {
    const ViewRequest r = cylinder_request(90.0);
    const CameraSetup cam = make_camera_setup(r, r.size);
    // Centre of the screen is straight ahead-ish (-z, below eye) in the screen frame; yaw 90 turns
    // it to -x.
    const Eigen::Vector3d local = (Eigen::Vector3d(0.0, 1.25, -3.0) - Eigen::Vector3d(0.0, 1.6, 0.5)).normalized();
    expect_vec_near(generate_ray(cam, 180.0, 60.0).direction, {local.z(), local.y(), -local.x()});
    // The right edge (theta = +90°, +x in the screen frame) turns to -z.
    const Eigen::Vector3d right = (Eigen::Vector3d(3.0, 2.5, 0.0) - Eigen::Vector3d(0.0, 1.6, 0.5)).normalized();
    expect_vec_near(generate_ray(cam, 360.0, 0.0).direction, {right.z(), right.y(), -right.x()});
}

// project_to_image inverts generate_ray: a point along the ray of (px, py) projects back to it.
void expect_projection_inverts_rays(const ViewRequest& r) {
    const CameraSetup camera = make_camera_setup(r, r.size);
    for (const double px : {0.0, 0.5, 37.25, 100.0, 199.5}) {
        for (const double py : {0.0, 3.5, 50.0, 99.0}) {
            const Ray ray = generate_ray(camera, px, py);
            for (const double t : {0.3, 2.0, 40.0}) {
                double x = -1.0;
                double y = -1.0;
                ASSERT_TRUE(project_to_image(camera, ray.origin + t * ray.direction, x, y));
                EXPECT_NEAR(x, px, 1e-7) << "t " << t;
                EXPECT_NEAR(y, py, 1e-7) << "t " << t;
            }
        }
    }
}

TEST(PinholeCamera, ProjectionInvertsRays) {
    expect_projection_inverts_rays(pinhole_request(0.0, 0.0));
    expect_projection_inverts_rays(pinhole_request(-35.0, 12.0));
    const ViewRequest r = pinhole_request(0.0, 0.0);
    double x = 0.0;
    double y = 0.0;
    EXPECT_FALSE(project_to_image(make_camera_setup(r, r.size), r.pose.eye + Eigen::Vector3d(0.0, 0.0, 1.0), x, y))
        << "a point behind the camera has no ray";
}

TEST(CylinderCamera, ProjectionInvertsRays) {
    ViewRequest r;
    r.size = {200, 100};
    r.camera = CylinderScreen{3.0, 150.0, 0.2, 2.8, {0.1, 1.6, -0.3}};
    r.pose.eye = {1.0, 1.7, 5.0};
    r.pose.yaw_deg = 20.0;
    r.pose.pitch_deg = -5.0;
    expect_projection_inverts_rays(r);
    CylinderScreen outside{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 3.5}};
    r.camera = outside;
    double x = 0.0;
    double y = 0.0;
    EXPECT_FALSE(project_to_image(make_camera_setup(r, r.size), Eigen::Vector3d(0.0, 1.0, 0.0), x, y))
        << "an eye outside the cylinder has no unique screen point";
}

TEST(PoseRotation, MatchesDocumentedAxes) {
    const Eigen::Matrix3d r = pose_rotation(90.0, 0.0);
    expect_vec_near(r * Eigen::Vector3d(0.0, 0.0, -1.0), {-1.0, 0.0, 0.0});
    expect_vec_near(r * Eigen::Vector3d(1.0, 0.0, 0.0), {0.0, 0.0, -1.0});
}

}  // namespace
}  // namespace mogao
