// SPDX-License-Identifier: Apache-2.0
// The virtual rig against independent geometry: round trips projector <-> screen, a lit projector
// block seen where cv::projectPoints puts it in the camera, and rig-file errors.
#include "appliance/rig/virtual_rig.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "appliance/rig/opencv_camera_model.h"
#include "appliance/rig/rig_file.h"

namespace mogao::rig {
namespace {

VirtualRig standard() { return load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml"); }

TEST(VirtualRig, ProjectorScreenRoundTrip) {
    const VirtualRig rig = standard();
    int landed = 0;
    int total = 0;
    for (int k = 0; k < 3; ++k) {
        for (double y = 0.5; y < 1080; y += 53.0) {
            for (double x = 0.5; x < 1920; x += 71.0) {
                ++total;
                const auto s = projector_to_screen(rig, k, x, y);
                if (!s) continue;
                ++landed;
                const auto back = screen_to_projector(rig, k, *s);
                ASSERT_TRUE(back.has_value());
                EXPECT_NEAR(back->x(), x, 1e-6);
                EXPECT_NEAR(back->y(), y, 1e-6);
                const Eigen::Vector2d uv = content_of(rig.screen, *s);
                const ScreenPoint s2 = screen_of(rig.screen, uv);
                EXPECT_NEAR(s2.theta_rad, s->theta_rad, 1e-12);
                EXPECT_NEAR(s2.h_m, s->h_m, 1e-12);
            }
        }
    }
    // Most of each image lands on the screen; the rest overfills its edges (71 % measured).
    EXPECT_GT(landed, total * 6 / 10);
    EXPECT_LT(landed, total * 9 / 10);
}

// A bowed screen (RigScreen::bulge_m): the ray of a projector pixel ends on the bowed surface, at
// the distance from the axis the formula gives (written out here again: bulge at the middle, none on
// the frame), and the round trip projector -> screen -> projector still holds; the pixel lands at
// another (theta, h) than on the cylinder, by about the bulge times the ray's slope across the screen.
TEST(VirtualRig, BowedScreenIsHitOnItsOwnSurface) {
    VirtualRig rig = standard();
    rig.screen.bulge_m = 0.05;
    const VirtualRig cylinder = standard();
    const RigScreen& sc = rig.screen;
    const double arc = sc.arc_deg * std::numbers::pi / 180.0;
    double largest_move_m = 0.0;
    for (int k = 0; k < 3; ++k) {
        const RigProjector& p = rig.projectors[static_cast<std::size_t>(k)];
        for (double y = 0.5; y < 1080; y += 97.0) {
            for (double x = 0.5; x < 1920; x += 131.0) {
                const auto s = projector_to_screen(rig, k, x, y);
                const auto s0 = projector_to_screen(cylinder, k, x, y);
                if (!s || !s0) continue;
                const double r =
                    sc.radius_m + sc.bulge_m * std::cos(std::numbers::pi * s->theta_rad / arc) *
                                      std::sin(std::numbers::pi * (s->h_m - sc.bottom_m) / (sc.top_m - sc.bottom_m));
                // The hit is on the projector's ray at distance r from the axis.
                const Eigen::Vector3d hit(r * std::sin(s->theta_rad), s->h_m, -r * std::cos(s->theta_rad));
                const Eigen::Vector3d d = device_to_screen(p.pose).transpose() * (hit - p.pose.position_m);
                ASSERT_GT(d.z(), 0.0);
                EXPECT_NEAR(p.intrinsics.fx_px * d.x() / d.z() + p.intrinsics.cx_px, x, 1e-6);
                EXPECT_NEAR(p.intrinsics.fy_px * d.y() / d.z() + p.intrinsics.cy_px, y, 1e-6);
                const auto back = screen_to_projector(rig, k, *s);
                ASSERT_TRUE(back.has_value());
                EXPECT_NEAR(back->x(), x, 1e-6);
                EXPECT_NEAR(back->y(), y, 1e-6);
                largest_move_m = std::max(largest_move_m,
                                          std::hypot(sc.radius_m * (s->theta_rad - s0->theta_rad), s->h_m - s0->h_m));
            }
        }
    }
    // A 5 cm bow moves content by centimetres on the screen: what a calibration assuming the cylinder
    // must cope with (rigs/bulge.toml); nothing moves by more than the bow itself.
    EXPECT_GT(largest_move_m, 0.005);
    EXPECT_LT(largest_move_m, 0.05);
    rig.screen.bulge_m = 0.07;  // over 2 % of 3 m
    EXPECT_THROW(
        {
            try {
                validate_rig(rig);
            } catch (const std::invalid_argument& e) {
                EXPECT_NE(std::string(e.what()).find("screen.bulge_m"), std::string::npos) << e.what();
                throw;
            }
        },
        std::invalid_argument);
}

TEST(VirtualRig, StandardRigCoversTheScreenWithOverlap) {
    const VirtualRig rig = standard();
    // Content corners and the middle of each overlap: covered by one, resp. two projectors.
    const auto covering = [&](double u, double v) {
        int n = 0;
        for (int k = 0; k < 3; ++k) n += screen_to_projector(rig, k, screen_of(rig.screen, {u, v})).has_value();
        return n;
    };
    EXPECT_EQ(covering(0.001, 0.001), 1);
    EXPECT_EQ(covering(0.999, 0.999), 1);
    EXPECT_EQ(covering(0.5, 0.5), 1);
    EXPECT_EQ(covering(0.3, 0.5), 2);
    EXPECT_EQ(covering(0.7, 0.5), 2);
}

// A lit 40x40 block in the middle of each projector's image appears in the camera image where OpenCV's
// projectPoints, given the rig camera's pose and distortion, puts the screen point it lands on.
void expect_blocks_where_the_camera_model_projects_them(VirtualRig rig) {
    rig.camera.read_noise = 0.0;
    rig.camera.shot_noise = 0.0;
    const CameraSimulator sim(rig);
    for (int k = 0; k < 3; ++k) {
        const double px = 960.0;
        const double py = 540.0;
        const auto s = projector_to_screen(rig, k, px, py);
        ASSERT_TRUE(s.has_value());
        const cv::Point2d image =
            opencv_camera_image(rig.camera, screen_position(rig.screen, *s)) - cv::Point2d(0.5, 0.5);
        std::vector<cv::Mat> signals(3);
        signals[static_cast<std::size_t>(k)] = cv::Mat1f(1080, 1920, 0.0f);
        cv::rectangle(signals[static_cast<std::size_t>(k)], cv::Rect(940, 520, 40, 40), 1.0, cv::FILLED);
        const cv::Mat1f img = sim.capture(signals, 0);
        cv::Point peak;
        cv::Mat1f smooth;
        cv::GaussianBlur(img, smooth, cv::Size(0, 0), 3.0);
        cv::minMaxLoc(smooth, nullptr, nullptr, nullptr, &peak);
        EXPECT_NEAR(peak.x, image.x, 1.5) << "projector " << k;
        EXPECT_NEAR(peak.y, image.y, 1.5) << "projector " << k;
    }
}

TEST(VirtualRig, LitBlockAppearsWhereTheCameraModelProjectsIt) {
    expect_blocks_where_the_camera_model_projects_them(standard());
}

// Several cameras film the same room: camera 1, half a metre to the left and turned 12 degrees,
// sees each block where its own model puts it (and elsewhere than camera 0 does).
TEST(VirtualRig, EveryCameraSeesTheRoomFromItsOwnPose) {
    VirtualRig rig = standard();
    RigCamera second = rig.camera;
    second.pose.position_m.x() -= 0.5;
    second.pose.yaw_deg += 12.0;
    second.seed = 7;
    rig.more_cameras.push_back(second);
    ASSERT_EQ(camera_count(rig), 2u);
    expect_blocks_where_the_camera_model_projects_them(seen_by(rig, 0));
    expect_blocks_where_the_camera_model_projects_them(seen_by(rig, 1));
    EXPECT_EQ(seen_by(rig, 1).camera.pose.yaw_deg, second.pose.yaw_deg);
    EXPECT_THROW((void)seen_by(rig, 2), std::out_of_range);
}

// The lens fall-off dims a block off the principal point by 1 - falloff rho^2 (rho over half the
// diagonal, written out here again) and leaves one on it as it was.
TEST(VirtualRig, LensFalloffDimsTheImageAwayFromThePrincipalPoint) {
    VirtualRig flat = standard();
    flat.camera.read_noise = 0.0;
    flat.camera.shot_noise = 0.0;
    flat.camera.bits = 16;
    flat.ambient = 0.0;
    VirtualRig dim = flat;
    dim.projectors[1].falloff = 0.3;
    const CameraSimulator sim_flat(flat);
    const CameraSimulator sim_dim(dim);
    const RigIntrinsics& in = flat.projectors[1].intrinsics;
    const double half_diagonal = 0.5 * std::hypot(1920.0, 1080.0);
    for (const cv::Point2d c :
         {cv::Point2d(in.cx_px, in.cy_px), cv::Point2d(400.0, 300.0), cv::Point2d(1500.0, 850.0)}) {
        std::vector<cv::Mat> signals(3);
        signals[1] = cv::Mat1f(1080, 1920, 0.0f);
        cv::rectangle(signals[1], cv::Rect(static_cast<int>(c.x) - 10, static_cast<int>(c.y) - 10, 20, 20), 1.0,
                      cv::FILLED);
        const std::vector<cv::Mat> off(3);
        const double lit_flat = cv::sum(sim_flat.capture(signals, 0) - sim_flat.capture(off, 0))[0];
        const double lit_dim = cv::sum(sim_dim.capture(signals, 0) - sim_dim.capture(off, 0))[0];
        const double rho2 = (std::pow(c.x - in.cx_px, 2) + std::pow(c.y - in.cy_px, 2)) / std::pow(half_diagonal, 2);
        EXPECT_NEAR(lit_dim / lit_flat, 1.0 - 0.3 * rho2, 0.01) << c;
        EXPECT_NEAR(projector_falloff(dim.projectors[1], c.x, c.y), 1.0 - 0.3 * rho2, 1e-12);
    }
    dim.projectors[1].falloff = 0.5;
    EXPECT_THROW(validate_rig(dim), std::invalid_argument);
}

// A projector's lens distortion (OpenCV's model about its lens-shifted principal point): its image position of
// a screen point is where cv::projectPoints puts it (OpenCV's matrix has the pixel centre at integers), the
// round trip through projector_to_screen holds, and the distortion moves the image by tens of pixels.
TEST(VirtualRig, ProjectorDistortionIsOpenCvsModel) {
    const VirtualRig pinhole = standard();
    VirtualRig rig = pinhole;
    rig.projectors[0].intrinsics.distortion = {-0.04, 0.01, 0.002, -0.001, 0.003};
    rig.projectors[2].intrinsics.distortion = {0.03, -0.01, -0.0015, 0.001, 0.0};
    validate_rig(rig);
    double largest_shift = 0.0;
    int compared = 0;
    for (const int k : {0, 2}) {
        const RigProjector& p = rig.projectors[static_cast<std::size_t>(k)];
        const Eigen::Matrix3d world_to_device = device_to_screen(p.pose).transpose();
        cv::Mat rvec;
        cv::Rodrigues(cv::Matx33d(world_to_device.data()).t(), rvec);  // Eigen is column-major
        const Eigen::Vector3d t = -world_to_device * p.pose.position_m;
        const cv::Matx33d kmat(p.intrinsics.fx_px, 0.0, p.intrinsics.cx_px - 0.5, 0.0, p.intrinsics.fy_px,
                               p.intrinsics.cy_px - 0.5, 0.0, 0.0, 1.0);
        for (double th = -70.0; th <= 70.0; th += 5.0) {
            for (double h = 0.85; h < 2.3; h += 0.1) {
                const ScreenPoint s{th * std::numbers::pi / 180.0, h};
                const auto xy = screen_to_projector(rig, k, s);
                if (!xy) continue;
                const double r = rig.screen.radius_m;
                const std::vector<cv::Point3d> world{{r * std::sin(s.theta_rad), h, -r * std::cos(s.theta_rad)}};
                std::vector<cv::Point2d> image;
                cv::projectPoints(world, rvec, cv::Vec3d(t.x(), t.y(), t.z()), kmat, p.intrinsics.distortion, image);
                EXPECT_NEAR(xy->x(), image[0].x + 0.5, 1e-6);
                EXPECT_NEAR(xy->y(), image[0].y + 0.5, 1e-6);
                const auto back = projector_to_screen(rig, k, xy->x(), xy->y());
                ASSERT_TRUE(back.has_value());
                EXPECT_NEAR(back->theta_rad, s.theta_rad, 1e-9);
                EXPECT_NEAR(back->h_m, s.h_m, 1e-9);
                if (const auto flat = screen_to_projector(pinhole, k, s))
                    largest_shift = std::max(largest_shift, (*flat - *xy).norm());
                ++compared;
            }
        }
    }
    EXPECT_GT(compared, 200);
    EXPECT_GT(largest_shift, 5.0);  // 9.4 px at these points
}

// The standard rig filmed exactly: no camera noise or blur, 16 bits, an unclipped exposure, no ambient light.
VirtualRig exact_camera_rig() {
    VirtualRig rig = standard();
    rig.camera.read_noise = 0.0;
    rig.camera.shot_noise = 0.0;
    rig.camera.bits = 16;
    rig.camera.blur_sigma_px = 0.0;
    rig.camera.exposure = 0.5;  // unclipped
    rig.ambient = 0.0;
    return rig;
}

// Defocus (blur_px) is a Gaussian of the projector's light: with a linear response and no black level the
// rig shows a block defocused as the sharp rig shows the block blurred beforehand, and it keeps the light.
TEST(VirtualRig, DefocusIsAGaussianOfTheProjectorsLight) {
    VirtualRig sharp = exact_camera_rig();
    for (RigProjector& p : sharp.projectors) {
        p.gamma = {1.0, 1.0, 1.0};
        p.black_level = 0.0;
    }
    sharp.camera.supersample = 2;  // the camera integrates: its sum is about the light's integral
    VirtualRig blurred = sharp;
    blurred.projectors[1].blur_px = 2.5;
    std::vector<cv::Mat> signals(3);
    cv::Mat1f block(1080, 1920, 0.0f);
    cv::rectangle(block, cv::Rect(900, 500, 48, 48), 1.0, cv::FILLED);
    signals[1] = block;
    const cv::Mat1f defocused = CameraSimulator(blurred).capture(signals, 0);
    const cv::Mat1f in_focus = CameraSimulator(sharp).capture(signals, 0);
    cv::Mat1f pre_blurred;
    cv::GaussianBlur(block, pre_blurred, cv::Size(21, 21), 2.5, 2.5, cv::BORDER_CONSTANT);
    signals[1] = pre_blurred;
    const cv::Mat1f expected = CameraSimulator(sharp).capture(signals, 0);
    EXPECT_LT(cv::norm(defocused, expected, cv::NORM_INF), 1e-4);
    EXPECT_NEAR(cv::sum(defocused)[0] / cv::sum(in_focus)[0], 1.0, 0.02);
    EXPECT_GT(cv::norm(defocused, in_focus, cv::NORM_INF), 0.02);  // the block's edges spread
}

// A defocused projector's light spreads past its image's edge, as a lens spreads it (defocus_margin): with the
// other projectors dark and no black level or ambient, the camera pixels just outside the middle projector's image
// on the screen see none of its light when it is sharp and some when it is defocused, and about as much light
// reaches the camera either way.
TEST(VirtualRig, ADefocusedProjectorsLightSpreadsPastItsImagesEdge) {
    VirtualRig sharp = exact_camera_rig();
    for (RigProjector& p : sharp.projectors) p.black_level = 0.0;
    VirtualRig blurred = sharp;
    blurred.projectors[1].blur_px = 3.0;
    std::vector<cv::Mat> signals(3);
    signals[1] = cv::Mat1f(1080, 1920, 1.0F);
    const cv::Mat1f in_focus = CameraSimulator(sharp).capture(signals, 0);
    const cv::Mat1f defocused = CameraSimulator(blurred).capture(signals, 0);
    int spread = 0;
    for (int y = 0; y < in_focus.rows; ++y) {
        for (int x = 0; x < in_focus.cols; ++x) spread += in_focus(y, x) == 0.0F && defocused(y, x) > 1e-3F ? 1 : 0;
    }
    EXPECT_GT(spread, 100) << "camera pixels lit only past the image's edge";
    EXPECT_NEAR(cv::sum(defocused)[0] / cv::sum(in_focus)[0], 1.0, 0.005);
}

// Camera vignetting dims every camera pixel by 1 - v min(rho^2, 2) (rho over half the diagonal from the
// principal point, written out here again): 20 % at a corner of a centred lens.
TEST(VirtualRig, CameraVignettingFollowsItsRadialLaw) {
    VirtualRig flat = standard();
    flat.camera.read_noise = 0.0;
    flat.camera.shot_noise = 0.0;
    flat.camera.bits = 16;
    flat.camera.blur_sigma_px = 0.0;
    flat.ambient = 0.5;
    VirtualRig dim = flat;
    dim.camera.vignetting = 0.2;
    const std::vector<cv::Mat> off(3);
    const cv::Mat1f a = CameraSimulator(flat).capture(off, 0);
    const cv::Mat1f b = CameraSimulator(dim).capture(off, 0);
    const RigIntrinsics& in = flat.camera.intrinsics;
    const double half_diagonal = 0.5 * std::hypot(1280.0, 720.0);
    int checked = 0;
    for (int y = 0; y < 720; y += 37) {
        for (int x = 0; x < 1280; x += 41) {
            if (a(y, x) < 0.1f) continue;
            const double rho2 =
                (std::pow(x + 0.5 - in.cx_px, 2) + std::pow(y + 0.5 - in.cy_px, 2)) / (half_diagonal * half_diagonal);
            EXPECT_NEAR(b(y, x) / a(y, x), 1.0 - 0.2 * rho2, 2e-4) << x << ", " << y;
            ++checked;
        }
    }
    EXPECT_GT(checked, 300);
    EXPECT_NEAR(camera_vignetting(dim.camera, 0.0, 0.0), 0.8, 0.01);  // the principal point is near the centre
}

TEST(VirtualRig, CaptureIsDeterministicAndNoisy) {
    const CameraSimulator sim(standard());
    const std::vector<cv::Mat> off(3);
    const cv::Mat1f a = sim.capture(off, 1);
    const cv::Mat1f b = sim.capture(off, 1);
    const cv::Mat1f c = sim.capture(off, 2);
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0.0);
    EXPECT_THROW((void)sim.capture(std::vector<cv::Mat>(2), 0), std::invalid_argument);
}

TEST(VirtualRig, LockedExposureScalesLightAndAutoExposureMetersEveryImage) {
    VirtualRig rig = standard();
    rig.camera.read_noise = 0.0;
    rig.camera.shot_noise = 0.0;
    rig.camera.bits = 16;
    CameraSimulator sim(rig);
    const std::vector<cv::Mat> off(3);
    const double dark = cv::mean(sim.capture(off, 0))[0];
    sim.set_exposure(20.0);
    EXPECT_NEAR(cv::mean(sim.capture(off, 0))[0], 20.0 * dark, 1e-3);  // linear in the exposure
    EXPECT_THROW(sim.set_exposure(0.0), std::invalid_argument);

    const cv::Mat1f locked_black = CameraSimulator(rig).capture(off, 0);  // exposure 1, unclipped
    rig.camera.auto_exposure = true;
    const CameraSimulator metered(rig);
    std::vector<cv::Mat> white(3);
    for (int k = 0; k < 3; ++k) white[static_cast<std::size_t>(k)] = cv::Mat1f(1080, 1920, 1.0f);
    // The meter scales the linear image to the target mean, then the sensor clips at 1 (most of
    // the standard rig's frame is dark, so its lit screen clips even for black content). Black
    // comes out so and white barely brighter: the images are not comparable, where the locked
    // camera sees white far brighter than black.
    cv::Mat1f expected;
    locked_black.convertTo(expected, CV_32F, kAutoExposureTarget / cv::mean(locked_black)[0]);
    cv::min(expected, 1.0, expected);
    const double auto_black = cv::mean(metered.capture(off, 0))[0];
    EXPECT_NEAR(auto_black, cv::mean(expected)[0], 1e-3);
    EXPECT_GT(auto_black, 0.5 * kAutoExposureTarget);
    EXPECT_LT(cv::mean(metered.capture(white, 0))[0] / auto_black, 1.5);
    sim.set_exposure(1.0);
    EXPECT_GT(cv::mean(sim.capture(white, 0))[0] / cv::mean(sim.capture(off, 0))[0], 10.0);
    EXPECT_TRUE(parse_rig("[camera]\nauto_exposure = true\n[[projectors]]\n", "x.toml").camera.auto_exposure);
}

TEST(RigFile, ErrorsNameTheField) {
    const auto message = [](const std::string& text) {
        try {
            (void)parse_rig(text, "bad.toml");
        } catch (const RigError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message("[screen]\nradius_m = 3\n").find("missing [camera]"), std::string::npos);
    EXPECT_NE(message("[camera]\n[[projectors]]\nthrow_ratio = 1\nfoo = 2\n").find("projectors[0].foo: unknown key"),
              std::string::npos);
    EXPECT_NE(message("[camera]\nposition_m = [0, 1, 5]\n[[projectors]]\n")
                  .find("camera.position_m must be inside the cylinder"),
              std::string::npos);
    EXPECT_NE(message("[camera]\nbits = 40\n[[projectors]]\n").find("camera.bits must be 1..16"), std::string::npos);
    // A seed as the unseen-rig draws give it (up to 2^30) loads; one past an int names the limit.
    EXPECT_EQ(parse_rig("[camera]\nseed = 1055676711\n[[projectors]]\n", "x.toml").camera.seed, 1055676711U);
    EXPECT_NE(message("[camera]\nseed = 3000000000\n[[projectors]]\n")
                  .find("camera.seed: must be an integer in [-2147483648, 2147483647]"),
              std::string::npos);
    EXPECT_NE(
        message("[camera]\n[[projectors]]\ngamma = [2.2, 2.2]\n").find("projectors[0].gamma: must be an array of 3"),
        std::string::npos);
    EXPECT_NE(message("[camera\n").find("not valid TOML"), std::string::npos);
    // toml11 read out of bounds on a literal string that is not UTF-8 (common/toml_nesting.h).
    EXPECT_NE(message("[camera]\nid = 'c\xFF'\n[[projectors]]\n").find("line 2: byte 8 of the line is not UTF-8"),
              std::string::npos);
    EXPECT_NE(
        message("[camera]\nauto_exposure = 1\n[[projectors]]\n").find("camera.auto_exposure: must be true or false"),
        std::string::npos);
    EXPECT_NE(
        message("[camera]\n[[projectors]]\n[prior]\nscreen_radius_error_m = 2.0\n").find("prior.screen_radius_error_m"),
        std::string::npos);
    // Several cameras: [[cameras]], each validated under its own name; not beside [camera].
    EXPECT_NE(message("[camera]\n[[cameras]]\n[[projectors]]\n").find("either [camera] or [[cameras]]"),
              std::string::npos);
    EXPECT_NE(message("[[cameras]]\n[[cameras]]\nbits = 0\n[[projectors]]\n").find("cameras[1].bits must be 1..16"),
              std::string::npos);
    EXPECT_NE(message("[screen]\nbulge_m = 0.5\n[camera]\n[[projectors]]\n").find("screen.bulge_m"), std::string::npos);
    // Projector lens distortion and defocus, camera vignetting: each key and its range named.
    EXPECT_NE(message("[camera]\n[[projectors]]\ndistortion = [0, 0, 0.5, 0, 0]\n")
                  .find("projectors[0] 'proj0'.distortion[2] must be in [-0.100000, 0.100000]"),
              std::string::npos);
    EXPECT_NE(message("[camera]\n[[projectors]]\ndistortion = [-1, 0, 0, 0, 0]\n")
                  .find("projectors[0] 'proj0'.distortion must be one-to-one"),
              std::string::npos);
    EXPECT_NE(message("[camera]\n[[projectors]]\ndistortion = [0, 0]\n").find("distortion: must be an array of 5"),
              std::string::npos);
    EXPECT_NE(message("[camera]\n[[projectors]]\nblur_px = 20\n").find("projectors[0] 'proj0'.blur_px must be in [0"),
              std::string::npos);
    EXPECT_NE(message("[camera]\nvignetting = 0.6\n[[projectors]]\n").find("camera.vignetting must be in [0"),
              std::string::npos);
    const VirtualRig lens = parse_rig(
        "[camera]\nvignetting = 0.2\n[[projectors]]\ndistortion = [-0.04, 0.01, 0.001, -0.002, 0]\nblur_px = 0.7\n",
        "lens.toml");
    EXPECT_EQ(lens.projectors[0].intrinsics.distortion, (std::array<double, 5>{-0.04, 0.01, 0.001, -0.002, 0.0}));
    EXPECT_EQ(lens.projectors[0].blur_px, 0.7);
    EXPECT_EQ(lens.camera.vignetting, 0.2);
    const VirtualRig old = standard();  // old rigs: none of them
    EXPECT_EQ(old.projectors[0].intrinsics.distortion, (std::array<double, 5>{}));
    EXPECT_EQ(old.projectors[0].blur_px, 0.0);
    EXPECT_EQ(old.camera.vignetting, 0.0);
    EXPECT_EQ(
        camera_count(parse_rig("[[cameras]]\n[[cameras]]\nposition_m = [0.5, 1.6, 1.0]\n[[projectors]]\n", "two")), 2u);
    EXPECT_THROW((void)load_rig("/nonexistent/rig.toml"), RigError);
    // toml11 recurses once per level without a limit: 20000 levels crashed the reader.
    const std::string deep = std::string(20000, '[') + std::string(20000, ']');
    EXPECT_NE(message("[camera]\n[[projectors]]\ngamma = " + deep + "\n")
                  .find("line 3: tables or arrays nested deeper than 32 levels"),
              std::string::npos);
}

// The camera's intrinsics as a chessboard leaves them: [prior] principal point and distortion errors, read
// and range-checked by name.
// The error parse_rig gives for a rig whose [prior] holds `prior` ("no error" when none).
std::string prior_error(const std::string& prior) {
    try {
        (void)parse_rig("[camera]\n[[projectors]]\n[prior]\n" + prior + "\n", "bad.toml");
    } catch (const RigError& e) {
        return std::string(e.what());
    }
    return std::string("no error");
}

TEST(RigFile, CameraPriorErrorsAreReadAndChecked) {
    const VirtualRig rig = parse_rig(
        "[camera]\n[[projectors]]\n[prior]\ncamera_focal_error = 0.01\ncamera_principal_point_error_px = [7, -9]\n"
        "camera_distortion_error = [0.01, -0.004, 0, 0, 0.001]\n",
        "prior.toml");
    EXPECT_EQ(rig.prior.camera_focal_error, 0.01);
    EXPECT_EQ(rig.prior.camera_principal_point_error_px, Eigen::Vector2d(7.0, -9.0));
    EXPECT_EQ(rig.prior.camera_distortion_error, (std::array<double, 5>{0.01, -0.004, 0.0, 0.0, 0.001}));
    EXPECT_NE(
        prior_error("camera_principal_point_error_px = [500, 0]").find("prior.camera_principal_point_error_px[0]"),
        std::string::npos);
    EXPECT_NE(prior_error("camera_distortion_error = [0, 2, 0, 0, 0]").find("prior.camera_distortion_error[1]"),
              std::string::npos);
    EXPECT_NE(prior_error("camera_distortion_error = [0, 0]").find("camera_distortion_error: must be an array of 5"),
              std::string::npos);
    EXPECT_NE(prior_error("camera_focal_error = 0.9").find("prior.camera_focal_error"), std::string::npos);
}

// The screen's heights as a tape measured them ([prior] screen_bottom_error_m, screen_top_error_m): read, checked
// by name against a tenth of the screen's height, and told only to the calibration: the simulator films the true
// screen, so a rig with the errors gives the very same images as one without.
TEST(RigFile, ScreenHeightErrorsAreToldNotFilmed) {
    const VirtualRig rig = parse_rig(
        "[camera]\nposition_m = [0, 1.6, 1.2]\n[[projectors]]\n[prior]\nscreen_bottom_error_m = 0.02\n"
        "screen_top_error_m = -0.015\n",
        "heights.toml");
    EXPECT_EQ(rig.prior.screen_bottom_error_m, 0.02);
    EXPECT_EQ(rig.prior.screen_top_error_m, -0.015);
    EXPECT_EQ(rig.screen.bottom_m, 0.8);  // the truth stays
    EXPECT_EQ(rig.screen.top_m, 2.3);
    // The standard screen is 1.5 m high: +-0.15 m.
    EXPECT_NE(prior_error("screen_bottom_error_m = 0.2")
                  .find("bad.toml': rig: prior.screen_bottom_error_m (0.1 x the screen's height) must be in "
                        "[-0.150000, 0.150000] (got 0.200000)"),
              std::string::npos);
    EXPECT_NE(prior_error("screen_top_error_m = -0.151").find("prior.screen_top_error_m"), std::string::npos);
    EXPECT_EQ(prior_error("screen_top_error_m = -0.149"), "no error");
    VirtualRig truth = standard();
    VirtualRig told = truth;
    told.prior.screen_bottom_error_m = 0.02;
    told.prior.screen_top_error_m = -0.02;
    std::vector<cv::Mat> signals(3);
    signals[1] = cv::Mat1f(1080, 1920, 1.0f);
    EXPECT_EQ(
        cv::norm(CameraSimulator(truth).capture(signals, 3), CameraSimulator(told).capture(signals, 3), cv::NORM_INF),
        0.0);
    // The installation rig carries both errors.
    const VirtualRig install = load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/realistic-install.toml");
    EXPECT_NE(install.prior.screen_bottom_error_m, 0.0);
    EXPECT_NE(install.prior.screen_top_error_m, install.prior.screen_bottom_error_m);
    EXPECT_GT(install.camera.mjpeg_quality, 0);
}

// Motion-JPEG frames (camera.mjpeg_quality): the rig's frame is its raw 8-bit frame as a JPEG codec of quality q
// leaves it. Checked against OpenCV's own JPEG codec (cv::imencode / cv::imdecode of the raw frame, R = G = B, at
// the same quality and 4:2:0): the same quantisation tables, so most pixels decode alike and the compression
// error has the same size; TurboJPEG's encoder uses the fast integer DCT where OpenCV's uses the accurate one, so
// a coefficient rounded the other way changes a block here and there.
TEST(VirtualRig, MjpegFramesAreTheRawFramesThroughAJpegCodec) {
    VirtualRig raw = standard();
    VirtualRig mjpeg = raw;
    mjpeg.camera.mjpeg_quality = 60;
    std::vector<cv::Mat> signals(3);
    cv::Mat1f checker(1080, 1920, 0.0f);
    for (int y = 0; y < 1080; y += 64) {
        for (int x = (y / 64) % 2 * 64; x < 1920; x += 128) cv::rectangle(checker, cv::Rect(x, y, 64, 64), 1.0, -1);
    }
    signals[1] = checker;
    const cv::Mat1f a = CameraSimulator(raw).capture(signals, 5);
    const cv::Mat1f b = CameraSimulator(mjpeg).capture(signals, 5);
    cv::Mat a8;
    a.convertTo(a8, CV_8U, 255.0);
    cv::Mat bgr;
    cv::cvtColor(a8, bgr, cv::COLOR_GRAY2BGR);
    std::vector<std::uint8_t> jpeg;
    ASSERT_TRUE(cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 60}));  // libjpeg's default: 4:2:0
    std::vector<cv::Mat> channels;
    cv::split(cv::imdecode(jpeg, cv::IMREAD_COLOR), channels);
    cv::Mat1f expected;
    channels[1].convertTo(expected, CV_32F, 1.0 / 255.0);
    const double n = static_cast<double>(b.total());
    const int differing = cv::countNonZero(cv::abs(b - expected) > 0.5 / 255.0);
    const double ours = cv::norm(a, b, cv::NORM_L2) / std::sqrt(n);
    const double opencv = cv::norm(a, expected, cv::NORM_L2) / std::sqrt(n);
    std::printf("MJPEG q60: %d of %.0f pixels differ from OpenCV's codec; rms error %.3f (OpenCV's %.3f) levels\n",
                differing, n, ours * 255.0, opencv * 255.0);
    EXPECT_LT(differing, n / 20);
    EXPECT_GT(ours, 0.3 / 255.0);  // the compression is there
    EXPECT_NEAR(ours / opencv, 1.0, 0.1);
    EXPECT_GT(cv::norm(a, b, cv::NORM_INF), 8.0 / 255.0);                                   // ringing at the edges
    EXPECT_EQ(cv::norm(CameraSimulator(mjpeg).capture(signals, 5), b, cv::NORM_INF), 0.0);  // deterministic
    const auto message = [](const std::string& camera) {
        try {
            (void)parse_rig("[camera]\n" + camera + "\n[[projectors]]\n", "bad.toml");
        } catch (const RigError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(parse_rig("[camera]\nmjpeg_quality = 80\n[[projectors]]\n", "q.toml").camera.mjpeg_quality, 80);
    EXPECT_NE(message("mjpeg_quality = 101").find("camera.mjpeg_quality must be 0..100"), std::string::npos);
    EXPECT_NE(message("mjpeg_quality = 80\nbits = 10").find("camera.mjpeg_quality must be 0 unless bits = 8"),
              std::string::npos);
}

// The camera's timing (camera.straddle): read from the rig file, refused outside [0, 1] naming the field.
TEST(RigFile, CameraStraddleIsReadAndRangeChecked) {
    EXPECT_EQ(parse_rig("[camera]\nstraddle = 0.25\n[[projectors]]\n", "s.toml").camera.straddle, 0.25);
    EXPECT_EQ(parse_rig("[camera]\n[[projectors]]\n", "s.toml").camera.straddle, 0.0);
    try {
        (void)parse_rig("[camera]\nstraddle = 1.5\n[[projectors]]\n", "bad.toml");
        ADD_FAILURE() << "straddle = 1.5 was accepted";
    } catch (const RigError& e) {
        EXPECT_NE(std::string(e.what()).find("camera.straddle"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mogao::rig
