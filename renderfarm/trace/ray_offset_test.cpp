// SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "renderfarm/trace/ray_offset.h"

namespace mogao {
namespace {

TEST(RayOffset, MovesToThePositiveSideAtAllMagnitudes) {
    const Eigen::Vector3f normals[] = {Eigen::Vector3f(0.0f, 1.0f, 0.0f), Eigen::Vector3f(0.0f, -1.0f, 0.0f),
                                       Eigen::Vector3f(1.0f, 2.0f, -3.0f).normalized(),
                                       Eigen::Vector3f(-0.6f, -0.48f, 0.64f).normalized(),
                                       Eigen::Vector3f(0.001f, 1.0f, 0.0f).normalized()};
    for (const float magnitude : {1e-6f, 1.0f, 1e5f}) {
        for (const Eigen::Vector3f& sign :
             {Eigen::Vector3f(1, 1, 1), Eigen::Vector3f(-1, 1, -1), Eigen::Vector3f(-1, -1, 1)}) {
            const Eigen::Vector3f p = magnitude * sign.cwiseProduct(Eigen::Vector3f(1.0f, 0.7f, 1.3f));
            for (const Eigen::Vector3f& n : normals) {
                const Eigen::Vector3f q = offset_ray_origin(p, n);
                const double along = (q.cast<double>() - p.cast<double>()).dot(n.cast<double>());
                EXPECT_GT(along, 0.0) << "magnitude " << magnitude << " p " << p.transpose() << " n " << n.transpose();
                // Small: at most 256 ULPs of the largest coordinate plus the near-zero float offset.
                const double ulp = std::ldexp(1.0, std::ilogb(p.cwiseAbs().maxCoeff()) - 23);
                EXPECT_LT((q - p).norm(), 256.0 * 2.0 * ulp + 1e-4) << "magnitude " << magnitude;
            }
        }
    }
}

TEST(RayOffset, OffsetsBeyondTheRoundingErrorOfTheHitPoint) {
    // A hit point computed in float is off the true plane by about one ULP per coordinate; the
    // offset must clear several such errors along the normal.
    const Eigen::Vector3f n(0.0f, 0.0f, 1.0f);
    for (const float z : {0.75f, 3.0f, 1234.5f, -1234.5f}) {
        const Eigen::Vector3f p(0.1f, 0.2f, z);
        const Eigen::Vector3f q = offset_ray_origin(p, n);
        const float ulp = std::nextafter(std::fabs(z), std::numeric_limits<float>::infinity()) - std::fabs(z);
        EXPECT_GE(q.z() - z, 100.0f * ulp) << z;
    }
}

TEST(RayOffset, NearZeroUsesFloatScale) {
    const Eigen::Vector3f q = offset_ray_origin(Eigen::Vector3f::Zero(), Eigen::Vector3f(0.0f, 1.0f, 0.0f));
    EXPECT_EQ(q.x(), 0.0f);
    EXPECT_FLOAT_EQ(q.y(), 1.0f / 65536.0f);
    EXPECT_EQ(q.z(), 0.0f);
}

}  // namespace
}  // namespace mogao
