// SPDX-License-Identifier: Apache-2.0
// The screen's own effects in the virtual rig against independent figures: a gain screen's lobe (its angle
// written out here again), one bounce of screen-to-screen light against the configuration factor of a
// cylinder's wall (Siegel & Howell) and against a brute-force integral over a projector's image, and a lens
// whose distortion is centred off its principal point.
#include "appliance/rig/screen_light.h"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "appliance/rig/opencv_camera_model.h"
#include "appliance/rig/rig_file.h"
#include "appliance/rig/virtual_rig.h"

namespace mogao::rig {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

VirtualRig quiet_standard() {
    VirtualRig rig = load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml");
    rig.camera.read_noise = 0.0;
    rig.camera.shot_noise = 0.0;
    rig.camera.bits = 16;
    rig.camera.blur_sigma_px = 0.0;
    rig.ambient = 0.0;
    return rig;
}

// The camera pixel that sees screen point s (OpenCV's camera model, opencv_camera_model.h).
cv::Point camera_pixel(const VirtualRig& rig, ScreenPoint s) {
    const cv::Point2d p = opencv_camera_image(rig.camera, screen_position(rig.screen, s));
    return {static_cast<int>(std::floor(p.x)), static_cast<int>(std::floor(p.y))};
}

TEST(ScreenGain, PeaksInTheMirrorDirectionAndHalvesAtTheHalfGainAngle) {
    RigScreen screen;
    screen.gain = 1.5;
    screen.half_gain_angle_deg = 30.0;
    const ScreenPoint s{0.0, 1.55};
    const Eigen::Vector3d x(0.0, 1.55, -screen.radius_m);
    const Eigen::Vector3d source(0.0, 1.55, 0.0);  // normal incidence: the mirror direction is back along +z
    EXPECT_NEAR(screen_gain(screen, s, source, source), 1.5, 1e-12);
    const Eigen::Vector3d at_half = x + 2.0 * Eigen::Vector3d(std::sin(30.0 * kDeg), 0.0, std::cos(30.0 * kDeg));
    EXPECT_NEAR(screen_gain(screen, s, source, at_half), 0.75, 1e-9);
    const Eigen::Vector3d at_60 = x + 2.0 * Eigen::Vector3d(0.0, std::sin(60.0 * kDeg), std::cos(60.0 * kDeg));
    EXPECT_NEAR(screen_gain(screen, s, source, at_60), 1.5 / 16.0, 1e-9);
    screen.gain = 1.0;
    EXPECT_EQ(screen_gain(screen, s, source, at_60), 1.0);
}

// A point at mid-height of a whole cylinder's inside (radius R, height H) sees its wall with the configuration
// factor 1 - 2 F_end, F_end = (X^2 + 2) / (2 sqrt(X^2 + 4)) - X / 2, X = H / (2 R) (element on the inside of a
// cylinder to its end disc: Siegel & Howell, "Thermal Radiation Heat Transfer", configuration factor catalogue).
TEST(ScreenBounce, AWholeCylinderSeesItsWallWithTheCatalogueFactor) {
    RigScreen screen;
    screen.radius_m = 3.0;
    screen.arc_deg = 360.0;
    screen.bottom_m = 0.0;
    screen.top_m = 3.0;
    screen.interreflection = 1.0;
    const ScreenBounce bounce(screen);
    EXPECT_LE(bounce.patches(), 4096);
    const std::vector<double> bounced =
        bounce.bounce(std::vector<double>(static_cast<std::size_t>(bounce.patches()), 1.0));
    const double x = 0.5;
    const double wall = 1.0 - 2.0 * ((x * x + 2.0) / (2.0 * std::sqrt(x * x + 4.0)) - x / 2.0);  // 0.4086
    EXPECT_NEAR(bounce.at(bounced, {0.3, 1.5}), wall, 0.015 * wall);
    screen.interreflection = 0.5;
    const ScreenBounce half(screen);
    EXPECT_NEAR(half.at(half.bounce(std::vector<double>(static_cast<std::size_t>(half.patches()), 1.0)), {0.3, 1.5}),
                wall / 2.0, 0.015 * wall);
    EXPECT_THROW((void)bounce.bounce({1.0, 2.0}), std::invalid_argument);
}

// Projector 0 alone at full white: where it does not reach, the camera sees only the screen's own light, which
// matches rho times the integral of cos cos / (pi d^2) over the screen area projector 0 lights, summed here over
// its 16 x 16 pixel blocks (each block's area from its corners on the screen).
TEST(ScreenBounce, TheCameraSeesTheLightAProjectorThrowsAcrossTheScreen) {
    VirtualRig rig = quiet_standard();
    for (RigProjector& p : rig.projectors) p.black_level = 0.0;
    rig.screen.interreflection = 0.8;
    std::vector<cv::Mat> signals(3);
    signals[0] = cv::Mat1f(1080, 1920, 1.0F);
    const cv::Mat1f img = CameraSimulator(rig).capture(signals, 0);
    const ScreenPoint s{55.0 * kDeg, 1.5};  // far right: projector 2's part only
    ASSERT_FALSE(screen_to_projector(rig, 0, s).has_value());
    const Eigen::Vector3d x = screen_position(rig.screen, s);
    const Eigen::Vector3d n(-std::sin(s.theta_rad), 0.0, std::cos(s.theta_rad));
    double expected = 0.0;
    constexpr int kBlock = 16;
    for (int by = 0; by < 1080; by += kBlock) {
        for (int bx = 0; bx < 1920; bx += kBlock) {
            const auto c = projector_to_screen(rig, 0, bx + kBlock / 2.0, by + kBlock / 2.0);
            const auto a = projector_to_screen(rig, 0, bx, by);
            const auto b = projector_to_screen(rig, 0, bx + kBlock, by);
            const auto d = projector_to_screen(rig, 0, bx, by + kBlock);
            if (!c || !a || !b || !d) continue;
            const Eigen::Vector3d q = screen_position(rig.screen, *c);
            const Eigen::Vector3d m(-std::sin(c->theta_rad), 0.0, std::cos(c->theta_rad));
            const double area = (screen_position(rig.screen, *b) - screen_position(rig.screen, *a))
                                    .cross(screen_position(rig.screen, *d) - screen_position(rig.screen, *a))
                                    .norm();
            const Eigen::Vector3d dq = q - x;
            const double d2 = dq.squaredNorm();
            const double cos_i = n.dot(dq) / std::sqrt(d2);
            const double cos_j = -m.dot(dq) / std::sqrt(d2);
            if (cos_i > 0.0 && cos_j > 0.0) expected += cos_i * cos_j * area / (std::numbers::pi * d2);
        }
    }
    expected *= 0.8;
    const cv::Point px = camera_pixel(rig, s);
    ASSERT_TRUE(cv::Rect(0, 0, img.cols, img.rows).contains(px));
    EXPECT_GT(expected, 0.005);
    EXPECT_NEAR(img(px), expected, 0.05 * expected);
    rig.screen.interreflection = 0.0;
    EXPECT_EQ(CameraSimulator(rig).capture(signals, 0)(px), 0.0F);
}

// A gain screen seen by the camera: each camera pixel is the matte screen's light times g 2^-(alpha / b)^2, alpha
// between the camera and projector 1's ray mirrored about the cylinder's normal (written out here again).
TEST(ScreenGain, TheCameraSeesTheLobeFromItsOwnPose) {
    VirtualRig matte = quiet_standard();
    matte.camera.exposure = 0.4;  // unclipped at the lobe's peak
    VirtualRig glossy = matte;
    glossy.screen.gain = 1.4;
    glossy.screen.half_gain_angle_deg = 35.0;
    std::vector<cv::Mat> signals(3);
    signals[1] = cv::Mat1f(1080, 1920, 1.0F);
    const cv::Mat1f a = CameraSimulator(matte).capture(signals, 0);
    const cv::Mat1f b = CameraSimulator(glossy).capture(signals, 0);
    int checked = 0;
    for (double th = -20.0; th <= 20.0; th += 8.0) {
        for (double h = 1.0; h <= 2.1; h += 0.3) {
            const ScreenPoint s{th * kDeg, h};
            const Eigen::Vector3d x = screen_position(matte.screen, s);
            const Eigen::Vector3d n(-std::sin(s.theta_rad), 0.0, std::cos(s.theta_rad));
            const Eigen::Vector3d in = (x - matte.projectors[1].pose.position_m).normalized();
            const Eigen::Vector3d mirrored = in - 2.0 * in.dot(n) * n;
            const double alpha = std::acos(mirrored.dot((matte.camera.pose.position_m - x).normalized())) / kDeg;
            const double g = 1.4 * std::pow(2.0, -std::pow(alpha / 35.0, 2.0));
            const cv::Point px = camera_pixel(matte, s);
            if (a(px) < 0.2F) continue;
            EXPECT_NEAR(b(px) / a(px), g, 0.01 * g) << th << " deg, " << h << " m, alpha " << alpha;
            ++checked;
        }
    }
    EXPECT_GT(checked, 20);
}

// A lens whose distortion is centred off the principal point: the ray through that centre is not moved by the
// distortion (it lands where the pinhole puts it), the round trip holds, and elsewhere the image moves.
TEST(VirtualRig, DistortionCentredOffThePrincipalPoint) {
    VirtualRig rig = quiet_standard();
    rig.projectors[1].intrinsics.distortion = {-0.05, 0.01, 0.0, 0.0, 0.0};
    VirtualRig centred = rig;
    rig.projectors[1].distortion_centre_px = {150.0, -80.0};
    validate_rig(rig);
    const RigIntrinsics& in = rig.projectors[1].intrinsics;
    const double cx = in.cx_px + 150.0;
    const double cy = in.cy_px - 80.0;
    const auto through_centre = projector_to_screen(rig, 1, cx, cy);
    ASSERT_TRUE(through_centre.has_value());
    VirtualRig pinhole = rig;
    pinhole.projectors[1].intrinsics.distortion = {};
    const auto pinhole_hit = projector_to_screen(pinhole, 1, cx, cy);
    ASSERT_TRUE(pinhole_hit.has_value());
    EXPECT_NEAR(through_centre->theta_rad, pinhole_hit->theta_rad, 1e-12);
    EXPECT_NEAR(through_centre->h_m, pinhole_hit->h_m, 1e-12);
    double largest = 0.0;
    int compared = 0;
    for (double x = 40.0; x < 1920.0; x += 160.0) {
        for (double y = 30.0; y < 1080.0; y += 120.0) {
            const auto s = projector_to_screen(rig, 1, x, y);
            if (!s) continue;  // beyond the screen's edge
            ++compared;
            const auto back = screen_to_projector(rig, 1, *s);
            ASSERT_TRUE(back.has_value());
            EXPECT_NEAR(back->x(), x, 1e-7);
            EXPECT_NEAR(back->y(), y, 1e-7);
            if (const auto c = screen_to_projector(centred, 1, *s)) largest = std::max(largest, (*c - *back).norm());
        }
    }
    EXPECT_GT(compared, 80);
    EXPECT_GT(largest, 2.0);
    rig.projectors[1].distortion_centre_px = {600.0, 0.0};
    EXPECT_THROW(validate_rig(rig), std::invalid_argument);
}

TEST(RigFile, ScreenGainInterreflectionViewerAndDistortionCentreAreReadAndChecked) {
    const VirtualRig rig = parse_rig(
        "viewer_position_m = [0.1, 1.7, -0.2]\n[screen]\ngain = 1.3\nhalf_gain_angle_deg = 45\ninterreflection = "
        "0.8\n[camera]\n[[projectors]]\ndistortion_centre_px = [12.0, -7.5]\n",
        "s.toml");
    EXPECT_EQ(rig.screen.gain, 1.3);
    EXPECT_EQ(rig.screen.half_gain_angle_deg, 45.0);
    EXPECT_EQ(rig.screen.interreflection, 0.8);
    EXPECT_EQ(rig.viewer_m, Eigen::Vector3d(0.1, 1.7, -0.2));
    EXPECT_EQ(rig.projectors[0].distortion_centre_px, Eigen::Vector2d(12.0, -7.5));
    const VirtualRig plain = parse_rig("[camera]\n[[projectors]]\n", "s.toml");
    EXPECT_EQ(plain.screen.gain, 1.0);
    EXPECT_EQ(plain.screen.interreflection, 0.0);
    for (const auto& [text, field] : std::vector<std::pair<std::string, std::string>>{
             {"[screen]\ngain = 0.8\n", "screen.gain"},
             {"[screen]\nhalf_gain_angle_deg = 5\n", "screen.half_gain_angle_deg"},
             {"[screen]\ninterreflection = 1.5\n", "screen.interreflection"},
             {"viewer_position_m = [9.0, 1.6, 0.0]\n", "viewer_position_m"}}) {
        try {
            (void)parse_rig(text + "[camera]\n[[projectors]]\n", "bad.toml");
            ADD_FAILURE() << text << " was accepted";
        } catch (const RigError& e) {
            EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace mogao::rig
