// SPDX-License-Identifier: Apache-2.0
// The single-precision per-frame forms against camera.h's double-precision functions they replace
// in per-pixel passes: same rays at every pixel centre, same image positions within 1e-3 px.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/frame_projection.h"

namespace mogao {
namespace {

// A grotto-like cylinder view (the live tour's), a cylinder almost all the way round (its screen angles in
// every octant), and a pinhole, each with an off-axis pose.
std::vector<CameraSetup> cameras() {
    ViewRequest cylinder;
    cylinder.size = {480, 270};
    CylinderScreen screen;
    screen.radius_m = 3.0;
    screen.arc_deg = 150.0;
    screen.bottom_m = 0.8;
    screen.top_m = 2.3;
    screen.eye_m = {0.1, 1.6, 0.4};
    cylinder.camera = screen;
    cylinder.pose.eye = {2.0, 1.6, -5.0};
    cylinder.pose.yaw_deg = 37.0;
    cylinder.pose.pitch_deg = -4.0;
    ViewRequest round = cylinder;
    round.size = {960, 160};
    screen.arc_deg = 350.0;
    round.camera = screen;
    ViewRequest pinhole = cylinder;
    pinhole.size = {320, 200};
    pinhole.camera = PinholeCamera{70.0};
    return {make_camera_setup(cylinder, cylinder.size), make_camera_setup(round, round.size),
            make_camera_setup(pinhole, pinhole.size)};
}

TEST(FrameProjection, PixelCentreRaysAreGenerateRaysDirections) {
    for (const CameraSetup& camera : cameras()) {
        const PixelCentreRays rays(camera);
        double worst = 0.0;
        for (int y = 0; y < camera.size.height; ++y) {
            for (int x = 0; x < camera.size.width; ++x) {
                const Eigen::Vector3d want = generate_ray(camera, x + 0.5, y + 0.5).direction;
                worst = std::max(worst, (rays.direction(x, y).cast<double>() - want).norm());
            }
        }
        EXPECT_LT(worst, 1e-6) << "direction error, radians";
    }
}

TEST(FrameProjection, ProjectsWhereProjectToImageDoesWithinAThousandthOfAPixel) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (const CameraSetup& camera : cameras()) {
        const FrameProjection projection(camera);
        double worst = 0.0;
        int projected = 0;
        for (int k = 0; k < 20000; ++k) {
            // Points along the rays of positions across (and a little beyond) the image, 0.2 to 40 m away,
            // and points anywhere around the eye (behind a pinhole, above the cylinder).
            Eigen::Vector3d p;
            if (k % 4 != 0) {
                const Ray ray = generate_ray(camera, (1.2 * unit(rng) - 0.1) * camera.size.width,
                                             (1.2 * unit(rng) - 0.1) * camera.size.height);
                p = ray.origin + (0.2 + 40.0 * unit(rng)) * ray.direction;
            } else {
                p = camera.eye + 10.0 * Eigen::Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
            }
            double want_x = 0.0, want_y = 0.0;
            float got_x = 0.0f, got_y = 0.0f;
            const bool want = project_to_image(camera, p, want_x, want_y);
            ASSERT_EQ(projection.project(p.cast<float>(), got_x, got_y), want) << p.transpose();
            // Where the image is (and a margin): far outside it, positions grow without bound and the
            // float rounding with them; only the answer matters there.
            if (!want || std::abs(want_x / camera.size.width - 0.5) > 0.6 ||
                std::abs(want_y / camera.size.height - 0.5) > 0.6)
                continue;
            ++projected;
            worst = std::max({worst, std::abs(got_x - want_x), std::abs(got_y - want_y)});
        }
        EXPECT_GT(projected, 14000);
        EXPECT_LT(worst, 1e-3) << "pixels";
    }
}

// The depth a frame's guides hold, along a pixel centre's ray and back: the pixel's own centre.
TEST(FrameProjection, APixelsPointAtItsDepthProjectsToItsCentre) {
    for (const CameraSetup& camera : cameras()) {
        const PixelCentreRays rays(camera);
        const FrameProjection projection(camera);
        for (const auto& [x, y] : {std::pair{0, 0}, {17, 123}, {camera.size.width - 1, camera.size.height - 1}}) {
            float px = 0.0f, py = 0.0f;
            ASSERT_TRUE(projection.project(rays.point(x, y, 7.5f), px, py));
            EXPECT_NEAR(px, static_cast<float>(x) + 0.5f, 1e-3f);
            EXPECT_NEAR(py, static_cast<float>(y) + 0.5f, 1e-3f);
        }
    }
}

// The row forms (vectorised, fused multiply-adds where the CPU has them) against the scalar ones
// at every pixel of every row: the same points within float rounding, the same answer of
// project(), the same positions within 1e-3 px where the image is.
TEST(FrameProjection, RowFormsMatchTheScalarOnes) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> depth_of(0.2f, 40.0f);
    for (const CameraSetup& camera : cameras()) {
        const PixelCentreRays rays(camera);
        // The camera a step away, as the temporal pass projects into the previous frame's.
        CameraSetup previous = camera;
        previous.eye += Eigen::Vector3d(0.3, -0.05, 0.4);
        const FrameProjection projection(previous);
        const auto w = static_cast<std::size_t>(camera.size.width);
        std::vector<float> depth(w), x(w), y(w), z(w), px(w), py(w);
        std::vector<std::uint8_t> ok(w);
        int agreed = 0, compared = 0;
        for (int row = 0; row < camera.size.height; row += 7) {
            for (float& d : depth) d = depth_of(rng);
            rays.points_row(row, depth.data(), camera.size.width, x.data(), y.data(), z.data());
            projection.project_row(x.data(), y.data(), z.data(), camera.size.width, px.data(), py.data(), ok.data());
            for (std::size_t i = 0; i < w; ++i) {
                const Eigen::Vector3f want = rays.point(static_cast<int>(i), row, depth[i]);
                ASSERT_LT((Eigen::Vector3f(x[i], y[i], z[i]) - want).norm(), 1e-5f * (1.0f + want.norm())) << i;
                float want_x = 0.0f, want_y = 0.0f;
                const bool want_ok = projection.project(Eigen::Vector3f(x[i], y[i], z[i]), want_x, want_y);
                ASSERT_EQ(ok[i] != 0, want_ok) << "row " << row << " pixel " << i;
                ++compared;
                if (!want_ok || std::abs(want_x / static_cast<float>(camera.size.width) - 0.5f) > 0.6f ||
                    std::abs(want_y / static_cast<float>(camera.size.height) - 0.5f) > 0.6f)
                    continue;
                ++agreed;
                ASSERT_NEAR(px[i], want_x, 1e-3f) << "row " << row << " pixel " << i;
                ASSERT_NEAR(py[i], want_y, 1e-3f) << "row " << row << " pixel " << i;
            }
        }
        EXPECT_GT(agreed, compared / 3);
    }
}

}  // namespace
}  // namespace mogao
