// SPDX-License-Identifier: Apache-2.0
// The quality tooling (docs/quality.md) against known values: PSNR, relMSE and SSIM on images whose
// error is known in closed form, SSIM's separable filtering against a direct 2-D window sum, FNV-1a
// test vectors, and the reference cache refusing a stale key and a truncated file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "bench/quality/image_metrics.h"
#include "bench/quality/reference_cache.h"

namespace mogao::quality {
namespace {

Rgb8Image constant(ImageSize size, std::uint8_t v) { return Rgb8Image(size, v); }

// SSIM of Wang et al. 2004 by direct 11x11 window sums (no separable filtering), for comparison.
double ssim_direct(const Rgb8Image& a, const Rgb8Image& b) {
    const auto y = [](const Rgb8Image& im, int x, int yy) {
        const std::uint8_t* p = im.at(x, yy);
        return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
    };
    double g[11][11], total = 0;
    for (int i = 0; i < 11; ++i)
        for (int j = 0; j < 11; ++j) total += g[i][j] = std::exp(-((i - 5) * (i - 5) + (j - 5) * (j - 5)) / 4.5);
    const double c1 = 6.5025, c2 = 58.5225;
    double sum = 0;
    int n = 0;
    for (int y0 = 0; y0 + 11 <= a.size.height; ++y0)
        for (int x0 = 0; x0 + 11 <= a.size.width; ++x0, ++n) {
            double ma = 0, mb = 0, saa = 0, sbb = 0, sab = 0;
            for (int i = 0; i < 11; ++i)
                for (int j = 0; j < 11; ++j) {
                    const double w = g[i][j] / total, va = y(a, x0 + j, y0 + i), vb = y(b, x0 + j, y0 + i);
                    ma += w * va, mb += w * vb, saa += w * va * va, sbb += w * vb * vb, sab += w * va * vb;
                }
            const double va = saa - ma * ma, vb = sbb - mb * mb, cov = sab - ma * mb;
            sum += (2 * ma * mb + c1) * (2 * cov + c2) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
        }
    return sum / n;
}

TEST(QualityMetrics, PsnrAndRelativeMseOfKnownErrors) {
    // Every sample off by 10 codes: MSE 100, PSNR = 10 log10(255^2 / 100).
    EXPECT_NEAR(display_psnr_db(constant({16, 12}, 110), constant({16, 12}, 100)), 28.1308036, 1e-6);
    RgbFloatImage x({4, 3}, 2.0f), r({4, 3}, 1.0f);
    EXPECT_NEAR(relative_mse(x, r), 1.0 / 1.01, 1e-12);  // (2-1)^2 / (1 + 1e-2)
    EXPECT_NEAR(relative_mse(x, r, 1.0), 0.5, 1e-12);    // eps 1
    EXPECT_DOUBLE_EQ(relative_mse(r, r), 0.0);
    EXPECT_NEAR(relative_mse_db(0.01), 20.0, 1e-12);
    EXPECT_THROW((void)relative_mse(x, RgbFloatImage({3, 4}, 1.0f)), std::invalid_argument);
}

TEST(QualityMetrics, SsimOfIdenticalOffsetAndInvertedImages) {
    EXPECT_DOUBLE_EQ(ssim_luminance(constant({20, 20}, 90), constant({20, 20}, 90)), 1.0);
    // Flat images: only the luminance term, (2 mu_a mu_b + C1) / (mu_a^2 + mu_b^2 + C1).
    const double c1 = 6.5025;
    EXPECT_NEAR(ssim_luminance(constant({20, 20}, 100), constant({20, 20}, 110)),
                (2 * 100.0 * 110 + c1) / (100.0 * 100 + 110.0 * 110 + c1), 1e-9);
    // A random texture against its negative: structure term near -1.
    std::mt19937 rng(7);
    Rgb8Image a({40, 30}), inverse({40, 30});
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        a.pixels[i] = static_cast<std::uint8_t>(64 + rng() % 128);
        inverse.pixels[i] = static_cast<std::uint8_t>(255 - a.pixels[i]);
    }
    EXPECT_LT(ssim_luminance(a, inverse), -0.5);
    EXPECT_THROW((void)ssim_luminance(constant({10, 30}, 1), constant({10, 30}, 1)), std::invalid_argument);
}

TEST(QualityMetrics, SsimSeparableFilterEqualsDirectWindowSums) {
    std::mt19937 rng(11);
    Rgb8Image a({37, 23}), b({37, 23});
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        a.pixels[i] = static_cast<std::uint8_t>(rng() % 256);
        b.pixels[i] = static_cast<std::uint8_t>(std::clamp<int>(a.pixels[i] + int(rng() % 61) - 30, 0, 255));
    }
    const double separable = ssim_luminance(a, b);
    EXPECT_NEAR(separable, ssim_direct(a, b), 1e-9);
    EXPECT_GT(separable, 0.3);
    EXPECT_LT(separable, 0.99);
}

TEST(QualityMetrics, BilinearResizeOfARamp) {
    RgbFloatImage in({2, 1});
    in.at(1, 0)[0] = 1.0f;
    const RgbFloatImage out = resize_bilinear(in, {4, 1});
    const float expected[] = {0.0f, 0.25f, 0.75f, 1.0f};
    for (int x = 0; x < 4; ++x) EXPECT_FLOAT_EQ(out.at(x, 0)[0], expected[x]) << x;
}

TEST(ReferenceCache, FnvTestVectors) {
    EXPECT_EQ(cache_key(""), "cbf29ce484222325");  // FNV-1a 64 offset basis
    EXPECT_EQ(cache_key("a"), "af63dc4c8601ec8c");
    EXPECT_EQ(cache_key("foobar"), "85944171f73967e8");
}

TEST(ReferenceCache, RoundTripAndRefusesStaleKeyAndTruncatedFile) {
    const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "mogao-quality-cache-test";
    const std::filesystem::path file = dir / "view.ref";
    CachedReference ref{"view walk; size 5x4; renderer abc", 64, 12.5, RgbFloatImage({5, 4}, 0.5f),
                        RgbFloatImage({5, 4}, 0.25f)};
    ref.half_a.at(4, 3)[2] = 7.0f;
    ASSERT_TRUE(save_reference(file, ref).ok());

    Result<CachedReference> same = load_reference(file, ref.description);
    ASSERT_TRUE(same.ok()) << same.error().message;
    EXPECT_EQ(same->spp_per_half, 64);
    EXPECT_EQ(same->half_a.pixels, ref.half_a.pixels);
    EXPECT_EQ(same->half_b.pixels, ref.half_b.pixels);
    EXPECT_FLOAT_EQ(reference_image(*same).at(4, 3)[2], 0.5f * (7.0f + 0.25f));

    Result<CachedReference> stale = load_reference(file, "view walk; size 5x4; renderer abd");
    ASSERT_FALSE(stale.ok());
    EXPECT_EQ(stale.code(), EINVAL);
    EXPECT_NE(stale.error().message.find("stale"), std::string::npos) << stale.error().message;
    EXPECT_NE(stale.error().message.find(file.string()), std::string::npos);

    std::filesystem::resize_file(file, std::filesystem::file_size(file) - 4);
    Result<CachedReference> truncated = load_reference(file, ref.description);
    ASSERT_FALSE(truncated.ok());
    EXPECT_NE(truncated.error().message.find("truncated"), std::string::npos) << truncated.error().message;
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mogao::quality
