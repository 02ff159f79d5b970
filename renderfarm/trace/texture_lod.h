// SPDX-License-Identifier: Apache-2.0
// Texture level of detail from ray cones: Akenine-Möller, Nelson, Lin, Rüther, "Texture Level of
// Detail Strategies for Real-Time Ray Tracing", Ray Tracing Gems (2019), ch. 20, §20.3.4.
//
// A camera ray is the axis of a cone whose spread angle γ is one pixel's (eq. 20.30:
// γ = atan(2 tan(fov/2) / H) for a pinhole); at distance t its width is w = γ t (the cone starts
// at the eye, width 0). At a triangle hit the level of detail is (eq. 20.34)
//   λ = Δ0 + log2(w) - log2(|n·d|),   Δ0 = ½ log2(t_a / p_a),
// t_a = W H |(uv1 - uv0) x (uv2 - uv0)| (texel-space area, level-0 size W x H), p_a =
// |(P1 - P0) x (P2 - P0)| (world-space area, metres²), n the geometric normal, d the unit ray
// direction: λ is log2 of the footprint's width in level-0 texels, what Texture::sample(uv, lod)
// takes.
//
// Our choices, each a documented approximation:
//  * Several samples per pixel share the pixel: the spread is scaled by max(1/8, 1/√spp), as
//    pbrt-v4 scales its ray differentials (RayIntegrator::EvaluatePixelSample), so that 1 spp is
//    filtered over the whole pixel and many spp are not blurred beyond it.
//  * After a bounce the cone keeps growing with the same spread along the path (w += γ t). The
//    cone of a diffuse or glossy bounce is wider in truth (Ray Tracing Gems §20.3.4 widens it by
//    the surface's curvature; pbrt-v4 approximates it from the camera), so secondary hits are
//    filtered less than they could be: never blurred, at worst noisier.
//  * A cylinder screen's pixels differ in angle across the image; its spread is that of the
//    image's centre pixel seen from the eye (camera_cone_spread).
#pragma once

#include <algorithm>
#include <cmath>

namespace mogao {

// λ of the header. cos_incidence = |n·d|; texel_area t_a (texels²), world_area p_a (metres²),
// both as the cross products' norms (twice the triangles' areas). Returns 0 (level 0) when the cone
// has no width or an area is not positive; λ may be negative (magnification: level 0).
[[nodiscard]] inline float texture_lod(float cone_width, float cos_incidence, float texel_area, float world_area) {
    if (!(cone_width > 0.0f) || !(texel_area > 0.0f) || !(world_area > 0.0f)) return 0.0f;
    // A grazing hit would give +inf; 1e-4 caps the stretch at 2^13 (the chain's top anyway).
    const float cos_i = std::max(cos_incidence, 1e-4f);
    return 0.5f * std::log2(texel_area / world_area) + std::log2(cone_width / cos_i);
}

}  // namespace mogao
