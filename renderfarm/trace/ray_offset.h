// SPDX-License-Identifier: Apache-2.0
// Self-intersection avoidance for secondary rays: move a hit point off its surface before
// tracing a new ray from it.
//
// Source: C. Wächter and N. Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
// Ray Tracing Gems (2019), chapter 6, listing 6-1. The point is moved along the geometric normal
// by a fixed number of float ULPs per component (int_scale * n), which scales with the magnitude
// of the coordinate and so stays robust from millimetres to kilometres; components within
// `origin` of zero, where ULPs are tiny, are moved by a fixed float distance (float_scale * n).
//
// Inputs: p = hit point (float, the frame the rays are traced in), n = unit geometric normal on
// the side the new ray leaves from (flip it first for rays going through the surface).
// Secondary rays then start at the returned point with tnear = 0.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

namespace mogao {

namespace ray_offset_constants {
inline constexpr float kOrigin = 1.0f / 32.0f;         // below this |coordinate|, use the float offset
inline constexpr float kFloatScale = 1.0f / 65536.0f;  // metres per unit normal near zero
inline constexpr float kIntScale = 256.0f;             // ULPs per unit normal elsewhere
}  // namespace ray_offset_constants

[[nodiscard]] inline float offset_component(float p, float n) {
    using namespace ray_offset_constants;
    if (std::fabs(p) < kOrigin) return p + kFloatScale * n;
    const auto ulps = static_cast<std::int32_t>(kIntScale * n);
    // Adding ULPs to the bit pattern moves away from zero for positive p and toward -inf for
    // negative p (sign-magnitude), hence the sign flip for negative coordinates.
    const std::int32_t bits = std::bit_cast<std::int32_t>(p) + (p < 0.0f ? -ulps : ulps);
    return std::bit_cast<float>(bits);
}

[[nodiscard]] inline Eigen::Vector3f offset_ray_origin(const Eigen::Vector3f& p, const Eigen::Vector3f& n) {
    return {offset_component(p.x(), n.x()), offset_component(p.y(), n.y()), offset_component(p.z(), n.z())};
}

}  // namespace mogao
