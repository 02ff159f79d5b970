// SPDX-License-Identifier: Apache-2.0
// Phase shifting (phase_shift.h) against positions known by construction: a camera pixel that sees
// a box footprint of projector pixels through a gamma-2.2 response.
#include "appliance/autocal/phase_shift.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

namespace mogao::autocal {
namespace {

// Light a camera pixel receives from a column pattern: the mean over projector pixels
// [centre - footprint/2, centre + footprint/2) of signal^gamma, as the virtual rig's projectors give it.
double seen(const cv::Mat1f& pattern, double centre, int footprint, double gamma) {
    double sum = 0.0;
    const int first = static_cast<int>(std::floor(centre - footprint / 2.0));
    for (int x = first; x < first + footprint; ++x) sum += std::pow(pattern(0, x), gamma);
    return sum / footprint;
}

TEST(PhaseShift, RecoversThePositionThroughTheProjectorsResponse) {
    const ImageSize size{256, 1};
    const double period = 32.0;
    for (const int shifts : {4, 8}) {
        std::vector<cv::Mat1f> patterns;
        for (int i = 0; i < shifts; ++i) patterns.push_back(phase_shift_pattern(size, false, period, shifts, i, 2.2));
        double worst = 0.0;
        // Camera pixels centred on projector pixel centres x + 0.5, each seeing 5 projector pixels.
        for (int x = 40; x < 200; ++x) {
            std::vector<cv::Mat1f> images;
            for (int i = 0; i < shifts; ++i)
                images.emplace_back(1, 1, static_cast<float>(seen(patterns[i], x + 0.5, 5, 2.2)));
            const PhaseImage p = decode_phase(images, period);
            const double truth = x + 0.5;
            const double got = unwrap_position(truth + 7.0, p.position(0, 0), period);  // a Gray position 7 px off
            worst = std::max(worst, std::abs(got - truth));
        }
        EXPECT_LT(worst, 0.01) << shifts << " shifts";
    }
}

// A projector whose response is 2.0 where 2.2 was assumed leaves harmonics; 8 shifts reject more
// of them than 4 (Bruning et al.: the N-step estimator is blind to harmonics up to N - 2).
TEST(PhaseShift, AWrongGammaCostsLessWithMoreShifts) {
    const ImageSize size{256, 1};
    const double period = 32.0;
    double worst[2] = {0.0, 0.0};
    int slot = 0;
    for (const int shifts : {4, 8}) {
        std::vector<cv::Mat1f> patterns;
        for (int i = 0; i < shifts; ++i) patterns.push_back(phase_shift_pattern(size, false, period, shifts, i, 2.2));
        for (int x = 40; x < 200; ++x) {
            std::vector<cv::Mat1f> images;
            for (int i = 0; i < shifts; ++i)
                images.emplace_back(1, 1, static_cast<float>(seen(patterns[i], x + 0.5, 1, 2.0)));
            const double got = unwrap_position(x + 0.5, decode_phase(images, period).position(0, 0), period);
            worst[slot] = std::max(worst[slot], std::abs(got - (x + 0.5)));
        }
        ++slot;
    }
    std::printf("gamma 2.0 seen as 2.2: worst error 4 shifts %.3f px, 8 shifts %.4f px\n", worst[0], worst[1]);
    EXPECT_LT(worst[0], 0.5);
    EXPECT_LT(worst[1], 0.5 * worst[0]);
}

// A camera that clips: the sinusoid's peak reads full scale. Filmed with the white at 0.95 `overdrive` times
// full scale, the N-step estimator is biased by the clipped peak's harmonics; leaving
// the clipped images out (Chen & Zhang 2016) is not, as long as 3 of the 8 remain.
TEST(PhaseShift, ImagesTheCameraClippedAreLeftOut) {
    const ImageSize size{256, 1};
    const double period = 32.0;
    const int shifts = 8;
    std::vector<cv::Mat1f> patterns;
    for (int i = 0; i < shifts; ++i) patterns.push_back(phase_shift_pattern(size, false, period, shifts, i, 2.2));
    for (const double overdrive : {1.0, 1.5, 2.2, 3.0}) {
        double worst_all = 0.0;
        double worst_unclipped = 0.0;
        int clipped = 0;
        for (int x = 40; x < 200; ++x) {
            std::vector<cv::Mat1f> images;
            for (int i = 0; i < shifts; ++i) {
                const double light = 0.02 + 0.95 * overdrive * seen(patterns[i], x + 0.5, 3, 2.2);
                images.emplace_back(1, 1, static_cast<float>(std::min(light, 1.0)));
            }
            const double truth = x + 0.5;
            const PhaseImage all = decode_phase(images, period);
            const PhaseImage unclipped = decode_phase(images, period, 0.98f);
            clipped += unclipped.clipped_pixels;
            ASSERT_GT(unclipped.modulation(0, 0), 0.0f) << overdrive << " at " << x;
            worst_all = std::max(worst_all, std::abs(unwrap_position(truth, all.position(0, 0), period) - truth));
            worst_unclipped =
                std::max(worst_unclipped, std::abs(unwrap_position(truth, unclipped.position(0, 0), period) - truth));
            if (unclipped.clipped_pixels == 0) {
                EXPECT_NEAR(unclipped.noise_gain(0, 0), 0.5, 1e-6);
            } else {
                EXPECT_GT(unclipped.noise_gain(0, 0), 0.5);  // fewer images: more noise per phase
            }
        }
        std::printf("overdrive %.1f: %d of 160 pixels clip, worst error all images %.3f px, unclipped only %.4f px\n",
                    overdrive, clipped, worst_all, worst_unclipped);
        EXPECT_LT(worst_unclipped, 0.05) << overdrive;
        if (overdrive >= 2.0) {
            EXPECT_GT(worst_all, 4.0 * worst_unclipped) << overdrive;
        }
        if (overdrive == 1.0) {
            EXPECT_EQ(clipped, 0);
        }
    }
}

// Fewer than 3 unclipped images cannot fix a sinusoid: no modulation, so the pixel is not refined.
TEST(PhaseShift, APixelClippedInAllButTwoImagesHasNoModulation) {
    std::vector<cv::Mat1f> images;
    for (int i = 0; i < 8; ++i) images.emplace_back(1, 1, i < 2 ? 0.3f + 0.1f * static_cast<float>(i) : 1.0f);
    const PhaseImage p = decode_phase(images, 32.0, 0.98f);
    EXPECT_EQ(p.modulation(0, 0), 0.0f);
    EXPECT_TRUE(std::isinf(p.noise_gain(0, 0)));
    EXPECT_EQ(p.clipped_pixels, 1);
}

TEST(PhaseShift, UnwrappingMovesTheGrayPositionByLessThanHalfAPeriod) {
    EXPECT_DOUBLE_EQ(unwrap_position(100.0, 5.0, 32.0), 101.0);  // 96 + 5
    EXPECT_DOUBLE_EQ(unwrap_position(100.0, 31.0, 32.0), 95.0);  // 64 + 31
    EXPECT_DOUBLE_EQ(unwrap_position(15.9, 0.5, 32.0), 0.5);     // 15.4 away: the same period
    EXPECT_DOUBLE_EQ(unwrap_position(16.6, 0.5, 32.0), 32.5);    // 16.1 away: the next one
}

TEST(PhaseShift, NoiseEstimateMatchesTheNoiseAdded) {
    std::mt19937 rng(7);
    std::normal_distribution<float> noise(0.0f, 0.02f);
    const ImageSize size{400, 100};
    std::vector<cv::Mat1f> images;
    for (int i = 0; i < 4; ++i) {
        cv::Mat1f img = phase_shift_pattern(size, false, 32.0, 4, i, 1.0);
        img = img * 0.5f + 0.1f;
        for (float& v : img) v += noise(rng);
        images.push_back(img);
    }
    const double sigma = phase_image_noise(images, cv::Mat1b(100, 400, 1));
    EXPECT_NEAR(sigma, 0.02, 0.002);
    // Clipped pixels break the identity the estimate rests on, and are left out of it: the rest still measure
    // the noise (1.75 times the images', as they are).
    std::vector<cv::Mat1f> clipped;
    for (const cv::Mat1f& m : images) clipped.emplace_back(cv::Mat1f(cv::min(m * 1.75f, 1.0f)));
    EXPECT_NEAR(phase_image_noise(clipped, cv::Mat1b(100, 400, 1), 0.98f), 0.035, 0.005);
    EXPECT_EQ(phase_image_noise(images, cv::Mat1b(100, 400, uchar{0})), 0.0);
}

TEST(PhaseShift, BadArgumentsAreRefused) {
    EXPECT_THROW((void)phase_shift_pattern({16, 16}, false, 8.0, 2, 0, 2.2), std::invalid_argument);
    EXPECT_THROW((void)phase_shift_pattern({16, 16}, false, 8.0, 4, 4, 2.2), std::invalid_argument);
    EXPECT_THROW((void)phase_shift_pattern({16, 16}, false, 1.0, 4, 0, 2.2), std::invalid_argument);
    EXPECT_THROW((void)phase_shift_pattern({16, 16}, false, 8.0, 4, 0, 0.0), std::invalid_argument);
    EXPECT_THROW((void)decode_phase({cv::Mat1f(2, 2), cv::Mat1f(2, 2)}, 8.0), std::invalid_argument);
    EXPECT_THROW((void)decode_phase({cv::Mat1f(2, 2), cv::Mat1f(2, 2), cv::Mat1f(3, 2)}, 8.0), std::invalid_argument);
}

}  // namespace
}  // namespace mogao::autocal
