// SPDX-License-Identifier: Apache-2.0
// The à-trous denoiser on synthetic frames with known edges: it removes noise, keeps normal and
// depth edges and albedo texture, is the identity when told to be, and names the field of bad input.
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/denoise/atrous_filter.h"

namespace mogao {
namespace {

constexpr int kW = 96, kH = 64;

// Ground truth: irradiance piecewise constant over three surfaces that share no guide values:
//   x <  48, y <  32: wall A, normal +z, depth 3 m, irradiance 1.0
//   x >= 48, y <  32: wall B, normal +x (a normal edge at x = 48, same depth), irradiance 0.25
//   y >= 32         : floor, normal +z, depth 6 m (a depth edge at y = 32, same normal as A), irradiance 0.5
// and sky (hit 0, radiance 0.3) in the bottom-right 16x16 corner. Albedo: wall A is a 4-pixel
// checker of 0.8 / 0.2 (texture the filter must keep), the rest 0.6 grey.
struct Synthetic {
    RgbFloatImage truth{ImageSize{kW, kH}};
    RgbFloatImage noisy{ImageSize{kW, kH}};
    GuideBuffers guides{ImageSize{kW, kH}};
};

float irradiance_at(int x, int y) { return y >= 32 ? 0.5f : (x < 48 ? 1.0f : 0.25f); }

Synthetic make_synthetic(float noise_sigma, unsigned seed = 7) {
    Synthetic s;
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.0f, 1.0f);
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            const std::size_t i = s.guides.pixel(x, y);
            const bool sky = x >= kW - 16 && y >= kH - 16;
            for (int c = 0; c < 3; ++c) {
                float value = 0.3f;
                if (!sky) {
                    const bool wall_a = x < 48 && y < 32;
                    const float albedo = wall_a ? (((x / 4 + y / 4) % 2) != 0 ? 0.8f : 0.2f) : 0.6f;
                    s.guides.albedo[3 * i + c] = albedo;
                    value = albedo * irradiance_at(x, y);
                }
                s.truth.at(x, y)[c] = value;
                // Monte Carlo-like noise: proportional to the signal; the sky is noise-free.
                s.noisy.at(x, y)[c] = sky ? value : std::max(0.0f, value * (1.0f + noise_sigma * noise(rng)));
            }
            if (sky) continue;
            s.guides.hit[i] = 1;
            s.guides.depth[i] = y >= 32 ? 6.0f : 3.0f;
            const bool wall_b = x >= 48 && y < 32;
            s.guides.normal[3 * i + (wall_b ? 0 : 2)] = 1.0f;
        }
    }
    return s;
}

double linear_psnr(const RgbFloatImage& a, const RgbFloatImage& b, double peak = 1.0) {
    double se = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        const double d = double(a.pixels[i]) - double(b.pixels[i]);
        se += d * d;
    }
    return 10.0 * std::log10(peak * peak / (se / double(a.pixels.size())));
}

// Mean of the irradiance (radiance / albedo) over the pixels of one column/row segment.
double mean_irradiance(const RgbFloatImage& image, const GuideBuffers& guides, int x0, int x1, int y0, int y1) {
    double sum = 0.0;
    int n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const std::size_t i = guides.pixel(x, y);
            for (int c = 0; c < 3; ++c) sum += image.at(x, y)[c] / guides.albedo[3 * i + c];
            n += 3;
        }
    return sum / n;
}

TEST(AtrousFilter, RemovesNoiseAndKeepsNormalAndDepthEdges) {
    const Synthetic s = make_synthetic(0.5f);
    const Result<RgbFloatImage> out = denoise_atrous(s.noisy, s.guides);
    ASSERT_TRUE(out.ok()) << out.error().message;
    const double before = linear_psnr(s.noisy, s.truth), after = linear_psnr(*out, s.truth);
    std::printf(
        "synthetic 96x64, 50 %% noise: PSNR noisy %.2f dB, denoised %.2f dB; edge means A|B %.4f %.4f, "
        "A/floor %.4f %.4f\n",
        before, after, mean_irradiance(*out, s.guides, 47, 48, 0, 32), mean_irradiance(*out, s.guides, 48, 49, 0, 32),
        mean_irradiance(*out, s.guides, 0, 48, 31, 32), mean_irradiance(*out, s.guides, 0, 48, 32, 33));
    EXPECT_GE(after, before + 10.0) << "PSNR noisy " << before << " dB, denoised " << after << " dB";

    // Bleeding across an edge biases the columns/rows right beside it toward the other side. Allowed:
    // 2 % of the step between the two sides (noise alone moves a 32-pixel mean by well under 1 %).
    const double step_ab = 1.0 - 0.25, step_floor = 1.0 - 0.5;
    EXPECT_NEAR(mean_irradiance(*out, s.guides, 47, 48, 0, 32), 1.0, 0.02 * step_ab) << "wall A beside B";
    EXPECT_NEAR(mean_irradiance(*out, s.guides, 48, 49, 0, 32), 0.25, 0.02 * step_ab) << "wall B beside A";
    EXPECT_NEAR(mean_irradiance(*out, s.guides, 0, 48, 31, 32), 1.0, 0.02 * step_floor) << "wall A above floor";
    EXPECT_NEAR(mean_irradiance(*out, s.guides, 0, 48, 32, 33), 0.5, 0.02 * step_floor) << "floor below A";
    // Texture: the checker survives (demodulation), so radiance of a bright and a dark texel of
    // wall A stays in the 4:1 albedo ratio within 10 %.
    const double dark = out->at(5, 5)[1], bright = out->at(5 + 4, 5)[1];  // albedo 0.2, 0.8
    EXPECT_NEAR(bright / dark, 4.0, 0.4) << "bright " << bright << " dark " << dark;
    // The sky is passed through.
    EXPECT_EQ(out->at(kW - 1, kH - 1)[0], s.noisy.at(kW - 1, kH - 1)[0]);
}

TEST(AtrousFilter, GuidesAreWhatKeepsTheEdges) {
    // Control for the test above: with every pixel on one plane (same normal and depth) and a
    // colour tolerance far above the noise, the same filter does blur wall A into wall B.
    Synthetic s = make_synthetic(0.5f);
    for (std::size_t i = 0; i < s.guides.hit.size(); ++i) {
        if (s.guides.hit[i] == 0) continue;
        s.guides.depth[i] = 3.0f;
        s.guides.normal[3 * i] = 0.0f, s.guides.normal[3 * i + 1] = 0.0f, s.guides.normal[3 * i + 2] = 1.0f;
    }
    AtrousParams params;
    params.sigma_colour = 1e6f;
    const Result<RgbFloatImage> out = denoise_atrous(s.noisy, s.guides, params);
    ASSERT_TRUE(out.ok()) << out.error().message;
    EXPECT_LT(mean_irradiance(*out, s.guides, 47, 48, 0, 32), 1.0 - 0.1 * 0.75);
}

TEST(AtrousFilter, IdentityWithoutIterationsOrColourTolerance) {
    const Synthetic s = make_synthetic(0.5f);
    AtrousParams none;
    none.iterations = 0;
    const Result<RgbFloatImage> same = denoise_atrous(s.noisy, s.guides, none);
    ASSERT_TRUE(same.ok()) << same.error().message;
    EXPECT_EQ(same->pixels, s.noisy.pixels);

    AtrousParams strict;
    strict.sigma_colour = 0.0f;
    const Result<RgbFloatImage> out = denoise_atrous(s.noisy, s.guides, strict);
    ASSERT_TRUE(out.ok()) << out.error().message;
    for (std::size_t i = 0; i < out->pixels.size(); ++i)
        ASSERT_NEAR(out->pixels[i], s.noisy.pixels[i], 1e-6f * std::max(1.0f, s.noisy.pixels[i])) << "sample " << i;
}

TEST(AtrousFilter, ThreadsDoNotChangeTheResultAndScratchIsReused) {
    const Synthetic s = make_synthetic(0.5f);
    AtrousParams one, three;
    three.threads = 3;
    AtrousDenoiser denoiser;
    RgbFloatImage a, b, c;
    ASSERT_TRUE(denoiser.run(s.noisy, s.guides, one, a).ok());
    ASSERT_TRUE(denoiser.run(s.noisy, s.guides, three, b).ok());
    ASSERT_TRUE(denoiser.run(s.noisy, s.guides, one, c).ok());
    EXPECT_EQ(a.pixels, b.pixels);
    EXPECT_EQ(a.pixels, c.pixels);
}

// The x86-64-v3 build of the tap loops (where this CPU has it) and the baseline build agree to float
// rounding (FMA rounds once), with and without a measured variance; both denoise. On a CPU without
// x86-64-v3 both runs take the baseline build and agree exactly.
TEST(AtrousFilter, BothBuildsOfTheKernelsAgree) {
    const Synthetic s = make_synthetic(0.5f);
    RgbFloatImage variance(s.noisy.size);
    for (std::size_t i = 0; i < variance.pixels.size(); ++i) variance.pixels[i] = 0.01f * float(i % 7);
    AtrousParams automatic, baseline;
    baseline.cpu = CpuLevel::baseline;
    for (const RgbFloatImage* v : std::initializer_list<const RgbFloatImage*>{nullptr, &variance}) {
        AtrousDenoiser denoiser;
        RgbFloatImage a, b;
        ASSERT_TRUE(denoiser.run(s.noisy, s.guides, automatic, a, v).ok());
        ASSERT_TRUE(denoiser.run(s.noisy, s.guides, baseline, b, v).ok());
        ASSERT_EQ(a.pixels.size(), b.pixels.size());
        double worst = 0.0;
        for (std::size_t i = 0; i < a.pixels.size(); ++i) {
            worst = std::max(worst, std::abs(double(a.pixels[i]) - double(b.pixels[i])) /
                                        std::max(1e-3, std::abs(double(b.pixels[i]))));
        }
        EXPECT_LT(worst, 1e-4) << (v ? "measured variance" : "spatial variance")
                               << (use_x86_64_v3(CpuLevel::automatic) ? ", x86-64-v3 against baseline" : "");
        EXPECT_GT(linear_psnr(a, s.truth), linear_psnr(s.noisy, s.truth) + 3.0);
    }
}

TEST(AtrousFilter, NonFiniteSamplesDoNotSpread) {
    Synthetic s = make_synthetic(0.2f);
    s.noisy.at(10, 10)[0] = std::numeric_limits<float>::quiet_NaN();
    s.noisy.at(20, 10)[1] = std::numeric_limits<float>::infinity();
    const Result<RgbFloatImage> out = denoise_atrous(s.noisy, s.guides);
    ASSERT_TRUE(out.ok()) << out.error().message;
    for (float v : out->pixels) ASSERT_TRUE(std::isfinite(v));
}

void expect_error(const RgbFloatImage& image, const GuideBuffers& guides, const AtrousParams& params,
                  const std::string& needle) {
    const Status status = validate_denoise_input(image, guides, params);
    ASSERT_FALSE(status.ok()) << "expected an error naming " << needle;
    EXPECT_EQ(status.code(), EINVAL);
    EXPECT_NE(status.error().message.find(needle), std::string::npos) << status.error().message;
    RgbFloatImage out(ImageSize{1, 1}, 42.0f);
    AtrousDenoiser denoiser;
    EXPECT_FALSE(denoiser.run(image, guides, params, out).ok());
    EXPECT_EQ(out.pixels[0], 42.0f) << "output touched on error";
}

TEST(AtrousFilter, BadInputIsNamed) {
    const Synthetic s = make_synthetic(0.1f);
    const AtrousParams ok;
    expect_error(s.noisy, GuideBuffers(ImageSize{kW, kH - 1}), ok, "guides are 96x63, the image is 96x64");
    GuideBuffers short_normal = s.guides;
    short_normal.normal.pop_back();
    expect_error(s.noisy, short_normal, ok, "normal");
    RgbFloatImage short_image = s.noisy;
    short_image.pixels.pop_back();
    expect_error(short_image, s.guides, ok, "W*H*3");
    expect_error(RgbFloatImage{}, GuideBuffers{}, ok, "empty");
    GuideBuffers no_depth = s.guides;
    no_depth.depth[5] = 0.0f;
    expect_error(s.noisy, no_depth, ok, "guides.depth at pixel 5");
    for (const auto& [field, value] :
         {std::pair{"sigma_colour", -1.0f}, std::pair{"sigma_normal", std::numeric_limits<float>::quiet_NaN()},
          std::pair{"sigma_depth", std::numeric_limits<float>::infinity()}}) {
        AtrousParams bad;
        if (std::string(field) == "sigma_colour") bad.sigma_colour = value;
        if (std::string(field) == "sigma_normal") bad.sigma_normal = value;
        if (std::string(field) == "sigma_depth") bad.sigma_depth = value;
        expect_error(s.noisy, s.guides, bad, std::string("params.") + field);
    }
    AtrousParams many;
    many.iterations = 11;
    expect_error(s.noisy, s.guides, many, "params.iterations = 11 is outside [0, 10]");
    AtrousParams threads;
    threads.threads = -1;
    expect_error(s.noisy, s.guides, threads, "params.threads");
}

// A shadow edge inside wall A (irradiance 1.0 left of x = 24, 0.3 right of it: no guide sees it)
// under little noise of known variance, as a well-sampled still view has. The spatial estimate takes
// the step for noise and blurs it; the measured variance keeps it and still removes noise.
struct ShadowEdge {
    Synthetic s;
    RgbFloatImage variance{ImageSize{kW, kH}};
};

ShadowEdge make_shadow_edge(float noise_sigma) {
    ShadowEdge e{make_synthetic(0.0f), RgbFloatImage(ImageSize{kW, kH})};
    std::mt19937 rng(11);
    std::normal_distribution<float> noise(0.0f, 1.0f);
    for (int y = 0; y < 32; ++y) {
        for (int x = 24; x < 48; ++x) {
            for (int c = 0; c < 3; ++c) e.s.truth.at(x, y)[c] *= 0.3f;
        }
    }
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            if (e.s.guides.hit[e.s.guides.pixel(x, y)] == 0) continue;
            for (int c = 0; c < 3; ++c) {
                const float t = e.s.truth.at(x, y)[c];
                e.s.noisy.at(x, y)[c] = t * (1.0f + noise_sigma * noise(rng));
                e.variance.at(x, y)[c] = (noise_sigma * t) * (noise_sigma * t);
            }
        }
    }
    return e;
}

TEST(AtrousFilter, MeasuredVarianceKeepsAShadowEdgeTheSpatialEstimateBlurs) {
    const ShadowEdge e = make_shadow_edge(0.03f);
    AtrousDenoiser denoiser;
    RgbFloatImage spatial, measured;
    ASSERT_TRUE(denoiser.run(e.s.noisy, e.s.guides, AtrousParams{}, spatial).ok());
    ASSERT_TRUE(denoiser.run(e.s.noisy, e.s.guides, AtrousParams{}, measured, &e.variance).ok());
    const double step = 1.0 - 0.3;
    const double spatial_bleed = 1.0 - mean_irradiance(spatial, e.s.guides, 23, 24, 0, 32);
    const double measured_bleed = 1.0 - mean_irradiance(measured, e.s.guides, 23, 24, 0, 32);
    const double noisy_db = linear_psnr(e.s.noisy, e.s.truth), measured_db = linear_psnr(measured, e.s.truth);
    std::printf(
        "shadow edge, 3 %% noise: bleed into the lit side %.4f (spatial) %.4f (measured) of a %.1f step; "
        "PSNR noisy %.2f dB, measured %.2f dB, spatial %.2f dB\n",
        spatial_bleed, measured_bleed, step, noisy_db, measured_db, linear_psnr(spatial, e.s.truth));
    EXPECT_GT(spatial_bleed, 0.05 * step) << "control: the spatial estimate should blur the shadow edge";
    EXPECT_LT(std::abs(measured_bleed), 0.01 * step);
    EXPECT_GT(measured_db, noisy_db + 3.0) << "the measured noise must still be filtered";
}

// No noise left: only pixels whose luminance agrees within the filter's ε (1e-6) may mix, so the
// output is the input up to the rare neighbours that agree that closely by chance.
TEST(AtrousFilter, ZeroMeasuredVarianceReturnsTheInput) {
    const ShadowEdge e = make_shadow_edge(0.3f);
    const RgbFloatImage none(ImageSize{kW, kH}, 0.0f);
    AtrousDenoiser denoiser;
    RgbFloatImage out, spatial;
    ASSERT_TRUE(denoiser.run(e.s.noisy, e.s.guides, AtrousParams{}, out, &none).ok());
    ASSERT_TRUE(denoiser.run(e.s.noisy, e.s.guides, AtrousParams{}, spatial).ok());
    EXPECT_GT(linear_psnr(out, e.s.noisy), 70.0);
    EXPECT_LT(linear_psnr(spatial, e.s.noisy), 40.0) << "control: the spatial estimate filters this noise";
}

TEST(AtrousFilter, BadMeasuredVarianceIsNamedAndTheOutputKept) {
    const ShadowEdge e = make_shadow_edge(0.1f);
    RgbFloatImage smaller(ImageSize{kW, kH - 1}, 0.0f), negative = e.variance, nan = e.variance;
    negative.at(3, 1)[2] = -1.0f;
    nan.at(4, 0)[0] = std::numeric_limits<float>::quiet_NaN();
    for (const auto& [variance, needle] :
         {std::pair{&smaller, "variance is 96x63"}, std::pair{&negative, "variance at pixel 99 = -1"},
          std::pair{&nan, "variance at pixel 4 = nan"}}) {
        RgbFloatImage out(ImageSize{1, 1}, 42.0f);
        AtrousDenoiser denoiser;
        const Status st = denoiser.run(e.s.noisy, e.s.guides, AtrousParams{}, out, variance);
        ASSERT_FALSE(st.ok()) << needle;
        EXPECT_EQ(st.code(), EINVAL);
        EXPECT_NE(st.error().message.find(needle), std::string::npos) << st.error().message;
        EXPECT_EQ(out.pixels[0], 42.0f) << "output touched on error";
    }
}

// A given luminance variance (the temporal estimate, temporal_accumulation.h) replaces the spatial
// one where it is >= 0: unknown everywhere is the spatial estimate bit for bit, and the true noise
// keeps the shadow edge the spatial estimate blurs, yet still filters the noise.
TEST(AtrousFilter, GivenLuminanceVarianceReplacesTheSpatialEstimateWhereKnown) {
    const ShadowEdge e = make_shadow_edge(0.03f);
    const auto n = static_cast<std::size_t>(kW * kH);
    const std::vector<float> unknown(n, -1.0f);
    std::vector<float> noise(n, 0.0f);  // the true variance of the demodulated luminance (channels independent)
    for (std::size_t i = 0; i < n; ++i) {
        if (e.s.guides.hit[i] == 0) continue;
        for (int c = 0; c < 3; ++c) {
            const double w = (c == 0 ? 0.2126 : (c == 1 ? 0.7152 : 0.0722)) / e.s.guides.albedo[3 * i + c];
            noise[i] += static_cast<float>(w * w * e.variance.pixels[3 * i + c]);
        }
    }
    AtrousDenoiser denoiser;
    RgbFloatImage spatial, as_unknown, given;
    ASSERT_TRUE(denoiser.run(e.s.noisy, e.s.guides, AtrousParams{}, spatial).ok());
    ASSERT_TRUE(denoiser.run(e.s.noisy, e.s.guides, AtrousParams{}, as_unknown, nullptr, &unknown).ok());
    ASSERT_TRUE(denoiser.run(e.s.noisy, e.s.guides, AtrousParams{}, given, nullptr, &noise).ok());
    EXPECT_EQ(as_unknown.pixels, spatial.pixels);
    const double step = 1.0 - 0.3;
    const double spatial_bleed = 1.0 - mean_irradiance(spatial, e.s.guides, 23, 24, 0, 32);
    const double given_bleed = 1.0 - mean_irradiance(given, e.s.guides, 23, 24, 0, 32);
    std::printf("shadow edge: bleed %.4f (spatial) %.4f (given luminance variance); PSNR noisy %.2f, given %.2f dB\n",
                spatial_bleed, given_bleed, linear_psnr(e.s.noisy, e.s.truth), linear_psnr(given, e.s.truth));
    EXPECT_GT(spatial_bleed, 0.05 * step) << "control: the spatial estimate should blur the shadow edge";
    EXPECT_LT(std::abs(given_bleed), 0.01 * step);
    EXPECT_GT(linear_psnr(given, e.s.truth), linear_psnr(e.s.noisy, e.s.truth) + 3.0);
    // Known at seven pixels in eight, at random, so that nearly every chunk of the tap loops mixes known
    // and unknown ones: finite, and close to the all-given case at the shadow edge (the spatial
    // estimate, computed for the whole chunk, must reach only its unknown pixels).
    std::vector<float> most = noise;
    std::mt19937 pick(5);
    for (float& v : most) v = pick() % 8 != 0 ? v : -1.0f;
    RgbFloatImage mixed;
    ASSERT_TRUE(denoiser.run(e.s.noisy, e.s.guides, AtrousParams{}, mixed, nullptr, &most).ok());
    for (const float v : mixed.pixels) ASSERT_TRUE(std::isfinite(v));
    const double mixed_bleed = 1.0 - mean_irradiance(mixed, e.s.guides, 23, 24, 0, 32);
    std::printf("seven in eight known: bleed %.4f\n", mixed_bleed);
    EXPECT_LT(mixed_bleed, given_bleed + 0.35 * (spatial_bleed - given_bleed));
}

TEST(AtrousFilter, BadLuminanceVarianceIsNamedAndTheOutputKept) {
    const ShadowEdge e = make_shadow_edge(0.1f);
    const auto n = static_cast<std::size_t>(kW * kH);
    std::vector<float> shorter(n - 1, 0.0f), nan(n, 0.0f), fine(n, 0.0f);
    nan[7] = std::numeric_limits<float>::quiet_NaN();
    for (const auto& [variance, colour, needle] :
         {std::tuple{&shorter, false, "luminance_variance holds 6143 values"},
          std::tuple{&nan, false, "luminance_variance at pixel 7 = nan"},
          std::tuple{&fine, true, "variance and luminance_variance are both given"}}) {
        RgbFloatImage out(ImageSize{1, 1}, 42.0f);
        AtrousDenoiser denoiser;
        const Status st =
            denoiser.run(e.s.noisy, e.s.guides, AtrousParams{}, out, colour ? &e.variance : nullptr, variance);
        ASSERT_FALSE(st.ok()) << needle;
        EXPECT_EQ(st.code(), EINVAL);
        EXPECT_NE(st.error().message.find(needle), std::string::npos) << st.error().message;
        EXPECT_EQ(out.pixels[0], 42.0f) << "output touched on error";
    }
}

}  // namespace
}  // namespace mogao
