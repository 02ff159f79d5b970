// SPDX-License-Identifier: Apache-2.0
// The pixel sampler (sobol.h): its points are (0,m,2)-nets, it integrates a smooth function with
// a much smaller error than white noise (and converges faster), and the renderer's pixel jitter
// is unbiased for spp that is not a rectangle count (a pixel half covered reads half).
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/rng.h"
#include "renderfarm/trace/sobol.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

TEST(Sobol, UnscrambledDimensionsMatchTheSequence) {
    // Sobol' dimension 1 for indices 0..7 (direction numbers m = 1, 3, 5 of Joe & Kuo, x 2^32;
    // index order, not Gray-code order).
    const std::uint32_t expected[] = {0x00000000u, 0x80000000u, 0xC0000000u, 0x40000000u,
                                      0xA0000000u, 0x20000000u, 0x60000000u, 0xE0000000u};
    for (std::uint32_t i = 0; i < 8; ++i) EXPECT_EQ(sobol_dimension1(i), expected[i]) << i;
    EXPECT_EQ(reverse_bits32(1u), 0x80000000u);
    EXPECT_EQ(reverse_bits32(0x80000001u), 0x80000001u);
}

// The byte-table generator is the bitwise one, and owen_sobol_2d's x is the nested scramble of the
// reversed shuffled index (its two inner reversals cancelled), over indices of every magnitude.
TEST(Sobol, TableAndCancelledReversalsGiveTheBitwiseValues) {
    std::uint64_t state = 12345;
    for (int i = 0; i < 200000; ++i) {
        state = mix64(state + 0x9e3779b97f4a7c15ULL);
        const auto index = static_cast<std::uint32_t>(i < 1000 ? i : state);
        ASSERT_EQ(sobol_dimension1(index), sobol_dimension1_bitwise(index)) << index;
        const auto seed = static_cast<std::uint32_t>(state >> 32);
        ASSERT_EQ(reverse_bits32(laine_karras_permutation(index, seed)),
                  nested_uniform_scramble(reverse_bits32(index), seed))
            << index;
    }
}

// Every elementary interval of area 2^-m holds exactly one of the first 2^m points of a pixel's
// pair, for every shape 2^-i x 2^-(m-i), in any pixel and pair, also when the pair is drawn
// `count` times per sample (points sample * count + k).
TEST(Sobol, PixelPointsAreZeroMTwoNets) {
    const std::uint64_t key = frame_key(11, 3);
    for (int pixel = 0; pixel < 16; ++pixel) {
        for (const int count : {1, 4}) {
            for (int m = 0; m <= 8; ++m) {
                const int n = 1 << m;
                std::vector<Eigen::Vector2f> points;
                for (int s = 0; s < n / count || (count > n && s == 0); ++s) {
                    PixelSampler sampler(key, pixel, 2 * pixel + 1, s);
                    (void)sampler.take();  // skip the jitter pair: test the second pair
                    const PixelSampler::Pair pair = sampler.take();
                    for (int k = 0; k < count && static_cast<int>(points.size()) < n; ++k)
                        points.push_back(pair.point(k, count));
                }
                ASSERT_EQ(static_cast<int>(points.size()), n);
                for (int i = 0; i <= m; ++i) {
                    std::vector<int> cells(static_cast<std::size_t>(n), 0);
                    for (const Eigen::Vector2f& p : points) {
                        const int cx = static_cast<int>(p.x() * static_cast<float>(1 << i));
                        const int cy = static_cast<int>(p.y() * static_cast<float>(1 << (m - i)));
                        ++cells[static_cast<std::size_t>(cy * (1 << i) + cx)];
                    }
                    for (const int c : cells) ASSERT_EQ(c, 1) << "pixel " << pixel << " m " << m << " i " << i;
                }
            }
        }
    }
}

// ∫∫ exp(-(u² + v²)) du dv over [0,1]² = (√π/2 erf 1)². RMS error over 256 pixels at N samples,
// Owen-scrambled Sobol' against the white-noise hash (rng.h).
double rms_error(int n, bool sobol) {
    const double truth = std::pow(0.5 * std::sqrt(std::numbers::pi) * std::erf(1.0), 2.0);
    double sum2 = 0.0;
    constexpr int kPixels = 256;
    for (int pixel = 0; pixel < kPixels; ++pixel) {
        double sum = 0.0;
        for (int s = 0; s < n; ++s) {
            Eigen::Vector2f u;
            if (sobol) {
                u = PixelSampler(frame_key(5, 0), pixel, 0, s).next2d();
            } else {
                PixelRng rng(frame_key(5, 0), pixel, 0, s);
                u.x() = rng.next();
                u.y() = rng.next();
            }
            sum += std::exp(-(u.x() * u.x() + u.y() * u.y()));
        }
        const double e = sum / n - truth;
        sum2 += e * e;
    }
    return std::sqrt(sum2 / kPixels);
}

TEST(Sobol, ConvergesFasterThanWhiteNoise) {
    const double sobol16 = rms_error(16, true);
    const double sobol256 = rms_error(256, true);
    const double white16 = rms_error(16, false);
    const double white256 = rms_error(256, false);
    std::printf("RMS error  N=16: sobol %.2e white %.2e   N=256: sobol %.2e white %.2e\n", sobol16, white16, sobol256,
                white256);
    // White noise: error ~ N^-1/2 (x 1/4 from 16 to 256). Owen-scrambled nets on a smooth
    // integrand: ~ N^-3/2 (x 1/64); ask for better than N^-1 (x 1/16).
    EXPECT_LT(sobol256, sobol16 / 16.0);
    EXPECT_GT(white256, white16 / 8.0);
    EXPECT_LT(sobol16, white16 / 3.0);
    EXPECT_LT(sobol256, white256 / 10.0);
}

// A pixel half covered by a lit wall (the wall's edge through the middle of the pixel row) must
// read half the wall's radiance on average, for spp = 3, 5, 7 as for 4. Stratified jitter on a
// ceil(sqrt(spp))-column grid put 2 of 3 samples in the upper half (2/3 instead of 1/2).
TEST(Sobol, HalfCoveredPixelsReadHalfForAnySpp) {
    Scene scene;
    scene.source = "edge";
    scene.meshes.push_back(test::make_grid(4, 2000.0f, false));
    Material m;
    m.albedo = Rgb::Ones();
    scene.materials = {m};
    // The grid (y = 0 plane) turned to face +z and moved so its lower edge is at the eye height.
    Instance wall{"wall", 0, 0, Eigen::Affine3d::Identity()};
    wall.object_to_world.translate(Eigen::Vector3d(0.0, 2000.0, -10.0));
    wall.object_to_world.rotate(Eigen::AngleAxisd(std::numbers::pi / 2.0, Eigen::Vector3d::UnitX()));
    scene.instances = {wall};
    DirectionalLight sun;
    sun.direction_to_light = {0.0, 0.0, 1.0};
    sun.irradiance = Rgb::Constant(std::numbers::pi_v<float>);  // wall radiance 1
    sun.cast_shadows = false;
    scene.directional_lights = {sun};
    for (const int spp : {3, 4, 5, 7}) {
        ViewRequest request = test::look_at({0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, {255, 7}, 60.0);
        request.quality.spp = spp;
        Renderer renderer(scene, RendererOptions{"threads=1", true});
        renderer.begin_frame(request);
        RgbFloatImage frame(renderer.render_size());
        renderer.render(PixelRect::whole(frame.size), frame);
        EXPECT_NEAR(frame.at(10, 0)[0], 1.0f, 1e-4f);  // fully on the wall
        EXPECT_EQ(frame.at(10, 6)[0], 0.0f);           // fully below it
        double sum = 0.0;
        for (int x = 0; x < frame.size.width; ++x) sum += frame.at(x, 3)[0];
        const double mean = sum / frame.size.width;
        std::printf("spp %d: half-covered row reads %.4f\n", spp, mean);
        EXPECT_NEAR(mean, 0.5, 0.04) << "spp " << spp;  // 4 sigma of the per-pixel spread / sqrt(255)
    }
}

}  // namespace
}  // namespace mogao
