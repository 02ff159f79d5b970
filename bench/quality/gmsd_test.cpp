// SPDX-License-Identifier: Apache-2.0
// GMSD (bench/quality/gmsd.h) on synthetic images: a frame rendered small and upsampled (blocks or
// blur) scores worse than a noisy frame of the same PSNR, which is what it is for; identical images
// score 0; bad input is refused.
#include "bench/quality/gmsd.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "common/image_compare.h"

namespace mogao::quality {
namespace {

// A dark room's picture: a dim background with a soft gradient, a few lit rectangles and a fine
// sinusoidal texture (painted detail).
Rgb8Image scene(ImageSize size) {
    Rgb8Image im(size);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            double v = 30 + 0.2 * x + 12 * std::sin(0.9 * x) * std::sin(0.7 * y);
            if ((x / 24 + y / 20) % 3 == 0) v += 70;
            for (int c = 0; c < 3; ++c) im.at(x, y)[c] = std::uint8_t(std::clamp(std::lround(v + 5 * c), 0L, 255L));
        }
    return im;
}

// Box-averaged over k x k blocks, then shown as blocks (nearest) or bilinearly upsampled (blur).
Rgb8Image rendered_small(const Rgb8Image& in, int k, bool bilinear) {
    const int w = in.size.width / k, h = in.size.height / k;
    std::vector<double> small(std::size_t(w) * h * 3, 0.0);
    for (int y = 0; y < h * k; ++y)
        for (int x = 0; x < w * k; ++x)
            for (int c = 0; c < 3; ++c)
                small[(std::size_t(y / k) * w + x / k) * 3 + c] += in.at(x, y)[c] / double(k * k);
    const auto at = [&](int x, int y, int c) {
        return small[(std::size_t(std::clamp(y, 0, h - 1)) * w + std::clamp(x, 0, w - 1)) * 3 + c];
    };
    Rgb8Image out(in.size);
    for (int y = 0; y < in.size.height; ++y)
        for (int x = 0; x < in.size.width; ++x)
            for (int c = 0; c < 3; ++c) {
                double v = at(x / k, y / k, c);
                if (bilinear) {
                    const double fx = (x + 0.5) / k - 0.5, fy = (y + 0.5) / k - 0.5;
                    const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
                    const double wx = fx - x0, wy = fy - y0;
                    v = (at(x0, y0, c) * (1 - wx) + at(x0 + 1, y0, c) * wx) * (1 - wy) +
                        (at(x0, y0 + 1, c) * (1 - wx) + at(x0 + 1, y0 + 1, c) * wx) * wy;
                }
                out.at(x, y)[c] = std::uint8_t(std::clamp(std::lround(v), 0L, 255L));
            }
    return out;
}

Rgb8Image noisy(const Rgb8Image& in, double sigma) {
    std::mt19937 rng(5);
    std::normal_distribution<double> n(0.0, sigma);
    Rgb8Image out = in;
    for (std::uint8_t& v : out.pixels) v = std::uint8_t(std::clamp(std::lround(v + n(rng)), 0L, 255L));
    return out;
}

// White noise whose PSNR against `reference` equals `target_db` (bisection on sigma).
Rgb8Image noisy_at_psnr(const Rgb8Image& reference, double target_db) {
    double lo = 0.1, hi = 80.0;
    for (int i = 0; i < 24; ++i) {
        const double mid = 0.5 * (lo + hi);
        (psnr(noisy(reference, mid), reference) > target_db ? lo : hi) = mid;
    }
    return noisy(reference, 0.5 * (lo + hi));
}

TEST(Gmsd, BlocksAndBlurScoreWorseThanNoiseOfEqualPsnr) {
    const Rgb8Image ref = scene({192, 128});
    for (const bool bilinear : {false, true}) {
        const Rgb8Image small = rendered_small(ref, 4, bilinear);
        const double db = psnr(small, ref);
        const Rgb8Image grain = noisy_at_psnr(ref, db);
        ASSERT_NEAR(psnr(grain, ref), db, 0.1);
        EXPECT_GT(gmsd(small, ref), 1.5 * gmsd(grain, ref))
            << (bilinear ? "blurred" : "blocky") << " frame at " << db << " dB";
    }
}

TEST(Gmsd, IdenticalImagesScoreZeroAndMoreErrorScoresMore) {
    const Rgb8Image ref = scene({64, 48});
    EXPECT_DOUBLE_EQ(gmsd(ref, ref), 0.0);
    EXPECT_LT(gmsd(rendered_small(ref, 2, true), ref), gmsd(rendered_small(ref, 8, true), ref));
}

TEST(Gmsd, RefusesMismatchedAndTinyImages) {
    EXPECT_THROW((void)gmsd(Rgb8Image({8, 8}), Rgb8Image({8, 9})), std::invalid_argument);
    EXPECT_THROW((void)gmsd(Rgb8Image({5, 8}), Rgb8Image({5, 8})), std::invalid_argument);
    Rgb8Image broken({8, 8});
    broken.pixels.pop_back();
    EXPECT_THROW((void)gmsd(broken, Rgb8Image({8, 8})), std::invalid_argument);
}

}  // namespace
}  // namespace mogao::quality
