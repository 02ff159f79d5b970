// SPDX-License-Identifier: Apache-2.0
// Temporal accumulation (temporal_accumulation.h) on analytic scenes: a wall seen by a pinhole
// camera, with guides computed exactly, so what is reprojected where is known.
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "renderfarm/denoise/temporal_accumulation.h"

namespace mogao {
namespace {

constexpr ImageSize kSize{48, 32};

CameraSetup camera_at(double yaw_deg, ImageSize size = kSize) {
    ViewRequest r;
    r.size = size;
    r.camera = PinholeCamera{60.0};
    r.pose.eye = {0.0, 1.5, 0.0};
    r.pose.yaw_deg = yaw_deg;
    return make_camera_setup(r, size);
}

// The wall z = -wall_z seen by `camera`: guides, and each pixel's world hit point.
struct Seen {
    GuideBuffers guides;
    std::vector<Eigen::Vector3d> points;
};
Seen wall(const CameraSetup& camera, double wall_z) {
    Seen s{GuideBuffers(camera.size), {}};
    for (int y = 0; y < camera.size.height; ++y) {
        for (int x = 0; x < camera.size.width; ++x) {
            const Ray ray = generate_ray(camera, x + 0.5, y + 0.5);
            const double t = (ray.origin.z() + wall_z) / -ray.direction.z();
            const std::size_t i = s.guides.pixel(x, y);
            s.guides.hit[i] = 1;
            s.guides.depth[i] = static_cast<float>(t);
            s.guides.normal[3 * i + 2] = 1.0f;
            s.points.push_back(ray.origin + t * ray.direction);
        }
    }
    return s;
}

// Radiance that belongs to the surface: a smooth pattern of the world point, plus noise.
RgbFloatImage shade(const Seen& s, double noise, std::mt19937& rng) {
    std::normal_distribution<float> gauss(0.0f, static_cast<float>(noise));
    RgbFloatImage f(s.guides.size);
    for (std::size_t i = 0; i < s.points.size(); ++i) {
        const auto v = static_cast<float>(1.0 + 0.5 * std::sin(2.0 * s.points[i].x()));
        for (int c = 0; c < 3; ++c) f.pixels[3 * i + static_cast<std::size_t>(c)] = v + gauss(rng);
    }
    return f;
}

double rms_error(const RgbFloatImage& f, const Seen& s) {
    std::mt19937 none(0);
    const RgbFloatImage truth = shade(s, 0.0, none);
    double sum = 0.0;
    for (std::size_t i = 0; i < f.pixels.size(); ++i) sum += std::pow(f.pixels[i] - truth.pixels[i], 2);
    return std::sqrt(sum / static_cast<double>(f.pixels.size()));
}

TEST(TemporalAccumulation, AStillViewIsTheRunningMeanThenAnExponentialAverage) {
    const CameraSetup camera = camera_at(0.0);
    const Seen seen = wall(camera, 3.0);
    TemporalHistory history;
    std::vector<RgbFloatImage> frames;
    std::mt19937 rng(1);
    RgbFloatImage out;
    for (int k = 0; k < 5; ++k) {  // a = 1/(n+1) >= alpha for the first 5 frames: exact means
        frames.push_back(shade(seen, 0.1, rng));
        out = history.accumulate(frames.back(), seen.guides, camera, {});
    }
    for (const std::size_t i : {std::size_t{0}, std::size_t{700}, out.pixels.size() - 1}) {
        float mean = 0.0f;
        for (const RgbFloatImage& f : frames) mean += f.pixels[i] / 5.0f;
        EXPECT_NEAR(out.pixels[i], mean, 1e-5f) << "value " << i;
    }
    for (int k = 0; k < 20; ++k) out = history.accumulate(shade(seen, 0.1, rng), seen.guides, camera, {});
    // Exponential average with alpha 0.2: noise variance a/(2-a) = 1/9 of one frame's.
    EXPECT_LT(rms_error(out, seen), 0.1 / 2.5);
}

TEST(TemporalAccumulation, AMovingViewFindsEachPointWhereThePreviousCameraSawIt) {
    TemporalHistory history;
    std::mt19937 rng(2);
    TemporalStats stats;
    RgbFloatImage out;
    Seen seen;
    for (int k = 0; k < 12; ++k) {  // turning 1.5 degrees a frame, sizes changing as the target scales
        const CameraSetup camera = camera_at(1.5 * k, k % 3 == 0 ? kSize : ImageSize{36, 24});
        seen = wall(camera, 3.0);
        out = history.accumulate(shade(seen, 0.1, rng), seen.guides, camera, {}, &stats);
    }
    EXPECT_GT(stats.reprojected, stats.surface_pixels * 8 / 10) << "most points were on screen a frame ago";
    const double error = rms_error(out, seen);
    EXPECT_LT(error, 0.1 / 2.0) << "the reprojected average is the pattern at the right place, with less noise";

    // The same frames, each reprojected to the pixel it had (a camera that did not move): the
    // pattern smears and the error is far larger.
    TemporalHistory wrong;
    rng.seed(2);
    for (int k = 0; k < 12; ++k) {
        const CameraSetup moved = camera_at(1.5 * k, kSize);
        const Seen s = wall(moved, 3.0);
        out = wrong.accumulate(shade(s, 0.1, rng), s.guides, camera_at(0.0), {});
        seen = s;
    }
    EXPECT_GT(rms_error(out, seen), 2.0 * error);
}

TEST(TemporalAccumulation, DisoccludedPixelsKeepTheirOwnValue) {
    const CameraSetup camera = camera_at(0.0);
    const Seen near = wall(camera, 1.0);  // an object right in front, then gone
    const Seen far = wall(camera, 3.0);
    TemporalHistory history;
    std::mt19937 rng(3);
    (void)history.accumulate(shade(near, 0.1, rng), near.guides, camera, {});
    const RgbFloatImage current = shade(far, 0.1, rng);
    TemporalStats stats;
    const RgbFloatImage out = history.accumulate(current, far.guides, camera, {}, &stats);
    EXPECT_EQ(stats.reprojected, 0u);
    EXPECT_EQ(out.pixels, current.pixels);
}

TEST(TemporalAccumulation, RefusesBadParamsAndMismatchedGuidesNamingThem) {
    const CameraSetup camera = camera_at(0.0);
    const Seen seen = wall(camera, 3.0);
    std::mt19937 rng(4);
    const RgbFloatImage frame = shade(seen, 0.0, rng);
    TemporalHistory history;
    const auto message = [&](const TemporalParams& p, const GuideBuffers& g) {
        try {
            (void)history.accumulate(frame, g, camera, p);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message({0.0f}, seen.guides).find("alpha"), std::string::npos);
    EXPECT_NE(message({0.2f, -1.0f}, seen.guides).find("plane_tolerance"), std::string::npos);
    EXPECT_NE(message({0.2f, 0.01f, 2.0f}, seen.guides).find("normal_min_cos"), std::string::npos);
    EXPECT_NE(message({}, GuideBuffers(ImageSize{4, 4})).find("guides 4x4"), std::string::npos);
    EXPECT_TRUE(history.empty()) << "a refused frame leaves the history as it was";
}

}  // namespace
}  // namespace mogao
