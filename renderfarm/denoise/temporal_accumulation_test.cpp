// SPDX-License-Identifier: Apache-2.0
// Temporal accumulation (temporal_accumulation.h) on analytic scenes: a wall seen by a pinhole
// camera, with guides computed exactly, so what is reprojected where is known.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
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

// Radiance that belongs to the surface: a smooth pattern of the world point (`frequency` radians
// per metre), plus noise.
RgbFloatImage shade(const Seen& s, double noise, std::mt19937& rng, double frequency = 2.0) {
    std::normal_distribution<float> gauss(0.0f, static_cast<float>(noise));
    RgbFloatImage f(s.guides.size);
    for (std::size_t i = 0; i < s.points.size(); ++i) {
        const auto v = static_cast<float>(1.0 + 0.5 * std::sin(frequency * s.points[i].x()));
        for (int c = 0; c < 3; ++c) f.pixels[3 * i + static_cast<std::size_t>(c)] = v + gauss(rng);
    }
    return f;
}

// Inside a border of `border` pixels.
double rms_error(const RgbFloatImage& f, const Seen& s, double frequency = 2.0, int border = 0) {
    std::mt19937 none(0);
    const RgbFloatImage truth = shade(s, 0.0, none, frequency);
    double sum = 0.0;
    std::size_t n = 0;
    for (int y = border; y < f.size.height - border; ++y) {
        for (int x = border; x < f.size.width - border; ++x) {
            for (int c = 0; c < 3; ++c) sum += std::pow(f.at(x, y)[c] - truth.at(x, y)[c], 2);
            n += 3;
        }
    }
    return std::sqrt(sum / static_cast<double>(n));
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

// The luminance of pixel i of `f`, demodulated by the albedo `albedo` (the same for every channel).
double demodulated_luminance(const RgbFloatImage& f, std::size_t i, double albedo) {
    return (0.2126 * f.pixels[3 * i] + 0.7152 * f.pixels[3 * i + 1] + 0.0722 * f.pixels[3 * i + 2]) / albedo;
}

// A still view of a noisy wall: the history's luminance variance must be what the blended frame's
// error against the noise-free truth measures (its variance over the pixels), unknown (-1) until four
// frames are in, and 0 on sky.
TEST(TemporalAccumulation, TheLuminanceVarianceIsTheBlendedFramesOwnNoise) {
    const CameraSetup camera = camera_at(0.0);
    Seen seen = wall(camera, 3.0);
    constexpr float kAlbedo = 0.5f;
    std::fill(seen.guides.albedo.begin(), seen.guides.albedo.end(), kAlbedo);
    seen.guides.set_sky(0);
    std::mt19937 rng(3), none(0);
    const RgbFloatImage truth = shade(seen, 0.0, none);
    TemporalHistory history;
    EXPECT_TRUE(history.luminance_variance().empty());
    RgbFloatImage out;
    for (int k = 1; k <= 40; ++k) {
        out = history.accumulate(shade(seen, 0.1, rng), seen.guides, camera, {});
        const std::vector<float>& v = history.luminance_variance();
        ASSERT_EQ(v.size(), static_cast<std::size_t>(kSize.pixel_count()));
        EXPECT_EQ(v[0], 0.0f) << "sky, frame " << k;
        if (k < 4) {
            EXPECT_EQ(v[500], -1.0f) << "a history of " << k << " frames is too short";
        } else {
            EXPECT_GE(v[500], 0.0f) << "frame " << k;
        }
    }
    double estimated = 0.0, measured = 0.0;
    int unknown = 0;
    for (std::size_t i = 1; i < static_cast<std::size_t>(kSize.pixel_count()); ++i) {
        if (history.luminance_variance()[i] < 0.0f) {
            ++unknown;
            continue;
        }
        estimated += history.luminance_variance()[i];
        measured += std::pow(demodulated_luminance(out, i, kAlbedo) - demodulated_luminance(truth, i, kAlbedo), 2);
    }
    const double samples = 0.1 * 0.1 * (0.2126 * 0.2126 + 0.7152 * 0.7152 + 0.0722 * 0.0722) / (kAlbedo * kAlbedo);
    std::printf("blended luminance variance: estimated %.3g, measured %.3g (one frame's %.3g); %d pixels unknown\n",
                estimated, measured, samples * static_cast<double>(kSize.pixel_count() - 1), unknown);
    EXPECT_LE(unknown, kSize.width + kSize.height) << "at most the image's border may lack a history";
    EXPECT_GT(estimated, 0.7 * measured);
    EXPECT_LT(estimated, 1.4 * measured);
    EXPECT_LT(measured, 0.2 * samples * static_cast<double>(kSize.pixel_count() - 1))
        << "control: the blend averages several frames";
    // A NaN or an overflowing sample: unknown there (the filter's spatial estimate), never a non-finite variance.
    RgbFloatImage bad = shade(seen, 0.1, rng);
    bad.pixels[3 * 600] = std::numeric_limits<float>::quiet_NaN();
    bad.pixels[3 * 601 + 1] = 3e30f;
    (void)history.accumulate(bad, seen.guides, camera, {});
    for (const float v : history.luminance_variance()) ASSERT_TRUE(std::isfinite(v));
    EXPECT_EQ(history.luminance_variance()[600], -1.0f);
    EXPECT_EQ(history.luminance_variance()[601], -1.0f);
    // They start again: unknown until four frames are in, then like their neighbours, the image finite.
    for (int k = 1; k <= 4; ++k) {
        out = history.accumulate(shade(seen, 0.1, rng), seen.guides, camera, {});
        const std::vector<float>& v = history.luminance_variance();
        for (const std::size_t i : {std::size_t{600}, std::size_t{601}}) {
            if (k < 4) {
                EXPECT_EQ(v[i], -1.0f) << "pixel " << i << ", frame " << k << " after";
            } else {
                EXPECT_GE(v[i], 0.0f) << "pixel " << i;
                EXPECT_LT(v[i], 10.0f * (v[500] + v[599] + v[602]) / 3.0f) << "pixel " << i;
            }
        }
    }
    for (const float x : out.pixels) ASSERT_TRUE(std::isfinite(x)) << "the history kept a non-finite sample";
    history.clear();
    EXPECT_TRUE(history.luminance_variance().empty());
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

// A sparse frame's pixels off its pattern (view_request.h) marked unshaded, as a render rank sends them.
std::size_t mark_unshaded(RgbFloatImage& frame, int one_in, int phase) {
    std::size_t marked = 0;
    for (int y = 0; y < frame.size.height; ++y) {
        for (int x = 0; x < frame.size.width; ++x) {
            if (shades_pixel(one_in, phase, x, y)) continue;
            frame.at(x, y)[0] = kUnshadedRadiance;
            ++marked;
        }
    }
    return marked;
}

// clear() drops the history (a light that changes, live_frames.h): what it held before (frames of another size, the
// same wall where the next frames have sky) must not show in what it gives after, bit for bit.
TEST(TemporalAccumulation, AClearedHistoryGivesWhatAFreshOneGives) {
    std::mt19937 rng(11);
    TemporalHistory used;
    const ImageSize big{64, 40};
    for (int k = 0; k < 3; ++k) {
        const CameraSetup camera = camera_at(2.0 * k, big);
        const Seen seen = wall(camera, 3.0);  // the same wall: a tap left over would pass every test
        (void)used.accumulate(shade(seen, 0.2, rng, 5.0), seen.guides, camera, {});
    }
    used.clear();
    TemporalHistory fresh;
    std::mt19937 noise(12);
    for (int k = 0; k < 4; ++k) {
        const CameraSetup camera = camera_at(0.5 * k);
        Seen seen = wall(camera, 3.0);
        for (int y = 0; y < kSize.height / 2; ++y)  // the top half-rows sky, where the earlier frames had wall
            for (int x = 0; x < kSize.width; ++x) seen.guides.set_sky(seen.guides.pixel(x, y));
        RgbFloatImage frame = shade(seen, 0.2, noise);
        if (k > 0) mark_unshaded(frame, 4, k);
        const RgbFloatImage from_used = used.accumulate(frame, seen.guides, camera, {}, nullptr, k > 0 ? 4 : 1);
        const RgbFloatImage from_fresh = fresh.accumulate(frame, seen.guides, camera, {}, nullptr, k > 0 ? 4 : 1);
        ASSERT_EQ(from_used.pixels, from_fresh.pixels) << "frame " << k;
    }
}

TEST(TemporalAccumulation, ASparseFrameTakesTheHistoryWhereItDidNotShadeAndFillsWhatIsNew) {
    TemporalHistory history;
    std::mt19937 rng(5);
    const CameraSetup before = camera_at(0.0);
    const Seen seen_before = wall(before, 3.0);
    for (int k = 0; k < 4; ++k) (void)history.accumulate(shade(seen_before, 0.0, rng), seen_before.guides, before, {});
    const CameraSetup after = camera_at(6.0);  // a few new columns at the left edge
    const Seen seen = wall(after, 3.0);
    RgbFloatImage current = shade(seen, 0.0, rng);
    const std::size_t marked = mark_unshaded(current, 4, 1);
    TemporalStats stats;
    const RgbFloatImage out = history.accumulate(current, seen.guides, after, {}, &stats);
    EXPECT_EQ(stats.unshaded, marked);
    EXPECT_GT(stats.filled, 0u) << "the new columns' unshaded pixels";
    EXPECT_LT(stats.filled, marked / 5);
    for (const float v : out.pixels) ASSERT_GE(v, 0.0f) << "no unshaded mark is left";
    EXPECT_LT(rms_error(out, seen, 2.0, 4), 0.01) << "the history is the pattern at the right place";
    EXPECT_LT(rms_error(out, seen), 0.03) << "the new columns filled from their neighbours";

    // Without a history every unshaded pixel is filled from its shaded neighbours.
    TemporalHistory none;
    const RgbFloatImage filled = none.accumulate(current, seen.guides, after, {}, &stats);
    EXPECT_EQ(stats.filled, marked);
    EXPECT_LT(rms_error(filled, seen), 0.05);

    // A frame cut at its budget copies an unshaded pixel over a whole 8x8 block: filled from beyond it.
    RgbFloatImage cut = shade(seen, 0.0, rng);
    for (int y = 8; y < 16; ++y)
        for (int x = 16; x < 24; ++x) cut.at(x, y)[0] = kUnshadedRadiance;
    const RgbFloatImage block = TemporalHistory().accumulate(cut, seen.guides, after, {}, &stats);
    EXPECT_EQ(stats.filled, 64u);
    for (const float v : block.pixels) ASSERT_GT(v, 0.0f) << "a hole left black";
    EXPECT_LT(rms_error(block, seen), 0.05);
}

// A sparse view panning by a quarter of a pixel a frame (resampled every frame, a quarter of each
// frame's pixels shaded, new columns filled): the estimate still follows the blended frame's error
// against the noise-free truth, inside the border the pan brings in.
TEST(TemporalAccumulation, ASparsePanKeepsTheLuminanceVarianceNearTheBlendsError) {
    constexpr float kAlbedo = 0.5f;
    constexpr int kBorder = 6;
    TemporalHistory history;
    std::mt19937 rng(8), none(0);
    RgbFloatImage out;
    Seen seen;
    for (int k = 0; k < 60; ++k) {
        const CameraSetup camera = camera_at(0.43 * k);
        seen = wall(camera, 3.0);
        std::fill(seen.guides.albedo.begin(), seen.guides.albedo.end(), kAlbedo);
        RgbFloatImage current = shade(seen, 0.1, rng);
        const int n = k > 0 ? 4 : 1;
        (void)mark_unshaded(current, n, k % n);
        out = history.accumulate(current, seen.guides, camera, {}, nullptr, n);
    }
    const RgbFloatImage truth = shade(seen, 0.0, none);
    double estimated = 0.0, measured = 0.0;
    int known = 0;
    for (int y = kBorder; y < kSize.height - kBorder; ++y) {
        for (int x = kBorder; x < kSize.width - kBorder; ++x) {
            const std::size_t i = seen.guides.pixel(x, y);
            const float v = history.luminance_variance()[i];
            if (v < 0.0f) continue;
            ++known;
            estimated += v;
            measured += std::pow(demodulated_luminance(out, i, kAlbedo) - demodulated_luminance(truth, i, kAlbedo), 2);
        }
    }
    const int inside = (kSize.width - 2 * kBorder) * (kSize.height - 2 * kBorder);
    std::printf("sparse pan: blended luminance variance estimated %.3g, measured %.3g over %d of %d pixels\n",
                estimated, measured, known, inside);
    EXPECT_GT(known, inside * 9 / 10);
    EXPECT_GT(estimated, 0.5 * measured);
    EXPECT_LT(estimated, 2.0 * measured);
}

// A view turning by a fraction of a pixel each frame, with one pixel in four shaded: bilinear
// resampling blurs the history frame after frame; the Catmull-Rom history keeps the pattern, about as
// well as frames that shade every pixel. Measured inside a border of 4 pixels: the columns the turn
// brings in are filled from their neighbours (ASparseFrameTakesTheHistory... bounds those).
TEST(TemporalAccumulation, TheHistoryStaysSharpWhileTheViewMovesByFractionsOfAPixel) {
    constexpr double kFrequency = 6.0;  // about 10 pixels a period on the wall
    const auto run = [&](bool sharp, int one_in) {
        TemporalParams params;
        params.sharp_history = sharp;
        TemporalHistory history;
        std::mt19937 rng(6);
        RgbFloatImage out;
        Seen seen;
        for (int k = 0; k < 24; ++k) {
            const CameraSetup camera = camera_at(0.43 * k);  // a quarter of a pixel a frame
            seen = wall(camera, 3.0);
            RgbFloatImage current = shade(seen, 0.0, rng, kFrequency);
            const int n = k > 0 ? one_in : 1;
            (void)mark_unshaded(current, n, k % n);
            out = history.accumulate(current, seen.guides, camera, params, nullptr, n);
        }
        return rms_error(out, seen, kFrequency, 4);
    };
    const double bilinear = run(false, 4);
    const double sharp = run(true, 4);
    const double full = run(true, 1);
    EXPECT_LT(sharp, 0.5 * bilinear) << "sharp " << sharp << ", bilinear " << bilinear;
    EXPECT_LT(sharp, 1.5 * full) << "sparse " << sharp << ", every pixel shaded " << full;
}

// Texture (the albedo guide, here a fine pattern on the wall) is taken from each frame's own guides,
// never resampled from the history: a sparse moving view's unshaded pixels are as sharp as its
// shaded ones. Resampled with the light, this texture loses about a third of its contrast (the
// previous test's bilinear case at half its frequency).
TEST(TemporalAccumulation, TextureComesFromEachFramesGuidesNotFromTheHistory) {
    const auto albedo = [](const Eigen::Vector3d& p) { return static_cast<float>(0.5 + 0.4 * std::sin(12.0 * p.x())); };
    TemporalHistory history;
    std::mt19937 rng(7);
    RgbFloatImage out, truth;
    for (int k = 0; k < 24; ++k) {
        const CameraSetup camera = camera_at(0.43 * k);
        Seen seen = wall(camera, 3.0);
        RgbFloatImage current = shade(seen, 0.0, rng);  // the light: smooth
        for (std::size_t i = 0; i < seen.points.size(); ++i) {
            for (std::size_t c = 0; c < 3; ++c) {
                seen.guides.albedo[3 * i + c] = albedo(seen.points[i]);
                current.pixels[3 * i + c] *= albedo(seen.points[i]);
            }
        }
        truth = current;
        const int n = k > 0 ? 4 : 1;
        (void)mark_unshaded(current, n, k % n);
        out = history.accumulate(current, seen.guides, camera, {}, nullptr, n);
    }
    double sum = 0.0;
    std::size_t count = 0;
    for (int y = 4; y < out.size.height - 4; ++y) {
        for (int x = 4; x < out.size.width - 4; ++x, ++count) sum += std::pow(out.at(x, y)[1] - truth.at(x, y)[1], 2);
    }
    EXPECT_LT(std::sqrt(sum / static_cast<double>(count)), 0.01);
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
