// SPDX-License-Identifier: Apache-2.0
#include <set>

#include <gtest/gtest.h>

#include "renderfarm/trace/rng.h"
#include "renderfarm/trace/sampling.h"

namespace mogao {
namespace {

TEST(PixelRng, DeterministicAndDecorrelated) {
    const std::uint64_t key = frame_key(1, 0);
    PixelRng a(key, 3, 4, 0);
    PixelRng b(key, 3, 4, 0);
    for (int i = 0; i < 100; ++i) ASSERT_EQ(a.next(), b.next());

    std::set<float> first_values;
    for (int x = 0; x < 16; ++x) {
        for (int y = 0; y < 16; ++y) {
            for (int s = 0; s < 4; ++s) first_values.insert(PixelRng(key, x, y, s).next());
        }
    }
    EXPECT_GT(first_values.size(), 1000u);  // 1024 streams, (almost) all distinct
    EXPECT_NE(PixelRng(frame_key(1, 0), 0, 0, 0).next(), PixelRng(frame_key(2, 0), 0, 0, 0).next());
    EXPECT_NE(PixelRng(frame_key(1, 0), 0, 0, 0).next(), PixelRng(frame_key(1, 1), 0, 0, 0).next());
}

TEST(PixelRng, UniformInUnitInterval) {
    PixelRng rng(frame_key(7, 7), 10, 20, 3);
    double sum = 0.0;
    int low = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        const float u = rng.next();
        ASSERT_GE(u, 0.0f);
        ASSERT_LT(u, 1.0f);
        sum += u;
        low += u < 0.25f ? 1 : 0;
    }
    EXPECT_NEAR(sum / n, 0.5, 0.01);
    EXPECT_NEAR(static_cast<double>(low) / n, 0.25, 0.01);
}

TEST(Sampling, CosineHemisphereHasCosineMean) {
    // E[cosθ] for pdf cosθ/π is 2/3.
    const Eigen::Vector3f n = Eigen::Vector3f(0.3f, -0.5f, 0.8f).normalized();
    const Frame frame(n);
    PixelRng rng(frame_key(3, 0), 0, 0, 0);
    double sum = 0.0;
    const int count = 100000;
    for (int i = 0; i < count; ++i) {
        const float u1 = rng.next();
        const float u2 = rng.next();
        const Eigen::Vector3f w = cosine_hemisphere(frame, u1, u2);
        ASSERT_NEAR(w.norm(), 1.0f, 1e-4f);
        ASSERT_GE(w.dot(n), -1e-6f);
        sum += w.dot(n);
    }
    EXPECT_NEAR(sum / count, 2.0 / 3.0, 0.005);
}

}  // namespace
}  // namespace mogao
