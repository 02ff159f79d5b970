// SPDX-License-Identifier: Apache-2.0
// A base-colour texture of a mesh, and its filtered lookup.
//
// Storage: the decoded image as 8-bit sRGB (common/image.h Rgb8Image: row 0 = top row of the
// file's image, 3 bytes per texel), 3 bytes per texel instead of 12 (a 4096² scan texture is
// 48 MiB, not 192 MiB). Texels are decoded to linear (IEC 61966-2-1 EOTF, a 256-entry table)
// before filtering, so filtering averages light, not codes.
//
// Coordinates: uv with (0, 0) at the top-left corner of the image and (1, 1) at the bottom-right
// (assimp with aiProcess_FlipUVs gives this for glTF and OBJ alike); texel (i, j) covers
// [i, i+1)/W x [j, j+1)/H, its centre at ((i + 0.5)/W, (j + 0.5)/H). Outside [0, 1] the wrap
// mode applies per axis: repeat (the glTF default, GL_REPEAT) or clamp-to-edge.
//
// Filtering: bilinear between the four texel centres around uv (OpenGL 4.6 core spec §8.14.2,
// GL_LINEAR). Limitation: no mip-mapping, so a texture minified far below its resolution (a
// 4096² texture on an object a few hundred pixels tall) is point-sampled per ray: it aliases at
// 1 spp, and only averages out as the pixel's jittered samples grow (each sample lands on another
// texel). The footprint of a camera ray is not tracked (no ray differentials).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <Eigen/Core>

#include "common/image.h"
#include "common/srgb.h"

namespace mogao {

enum class TextureWrap { repeat, clamp };

struct Texture {
    std::string source;  // file (or "<mesh file>#<embedded index>"), for messages
    Rgb8Image image;     // sRGB8, non-empty
    TextureWrap wrap_u = TextureWrap::repeat;
    TextureWrap wrap_v = TextureWrap::repeat;

    // Linear RGB at uv (see header): bilinear, with the wrap modes. Non-finite uv gives texel (0, 0).
    [[nodiscard]] Eigen::Vector3f sample(const Eigen::Vector2f& uv) const;
};

// sRGB8 code -> linear value in [0, 1], IEC 61966-2-1.
[[nodiscard]] const std::array<float, 256>& srgb8_to_linear_table();

// Inline: the trace stage uses Scene/Mesh/Texture header-only (renderfarm/trace/CMakeLists.txt).

namespace texture_detail {

inline int wrap_index(int i, int n, TextureWrap mode) {
    if (mode == TextureWrap::clamp) return std::clamp(i, 0, n - 1);
    const int r = i % n;
    return r < 0 ? r + n : r;
}

}  // namespace texture_detail

inline const std::array<float, 256>& srgb8_to_linear_table() { return srgb8_decode_table(); }

inline Eigen::Vector3f Texture::sample(const Eigen::Vector2f& uv) const {
    const int w = image.size.width;
    const int h = image.size.height;
    const float x = uv.allFinite() ? uv.x() * static_cast<float>(w) - 0.5f : 0.0f;
    const float y = uv.allFinite() ? uv.y() * static_cast<float>(h) - 0.5f : 0.0f;
    // Large |uv| (a repeat over millions of tiles) would overflow int: keep the fraction only.
    const float fx0 = std::floor(x);
    const float fy0 = std::floor(y);
    const float tx = x - fx0;
    const float ty = y - fy0;
    const auto start = [](float f, int n, TextureWrap mode) {
        const float limit = static_cast<float>(n);
        return static_cast<int>(mode == TextureWrap::clamp ? std::clamp(f, -1.0f, limit) : std::fmod(f, limit));
    };
    const int x0 = start(fx0, w, wrap_u);
    const int y0 = start(fy0, h, wrap_v);
    const auto& lut = srgb8_to_linear_table();
    const auto texel = [&](int i, int j) {
        const std::uint8_t* p =
            image.at(texture_detail::wrap_index(i, w, wrap_u), texture_detail::wrap_index(j, h, wrap_v));
        return Eigen::Vector3f(lut[p[0]], lut[p[1]], lut[p[2]]);
    };
    return (1.0f - ty) * ((1.0f - tx) * texel(x0, y0) + tx * texel(x0 + 1, y0)) +
           ty * ((1.0f - tx) * texel(x0, y0 + 1) + tx * texel(x0 + 1, y0 + 1));
}

}  // namespace mogao
