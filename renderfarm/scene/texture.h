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
// GL_LINEAR) on one level of a mip chain, and trilinear between two levels (§8.14.3,
// GL_LINEAR_MIPMAP_LINEAR) when the caller gives a level of detail. The chain (make_mip_chain in
// texture_mips.cpp, built when a texture is loaded) halves each side per level (floor, at least 1;
// an odd side's last texel joins the last 2-texel box) down to 1x1, box-filtering linear light,
// each level stored as sRGB8 like level 0 (as pbrt-v4's MIPMap keeps its image's format).
// The level of detail is the caller's: the trace stage computes it from a ray cone
// (renderfarm/trace/texture_lod.h). A texture without a chain (mips empty) samples level 0 only.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/image.h"
#include "common/srgb.h"

namespace mogao {

enum class TextureWrap { repeat, clamp };

struct Texture {
    std::string source;           // file (or "<mesh file>#<embedded index>"), for messages
    Rgb8Image image;              // level 0: sRGB8, non-empty
    std::vector<Rgb8Image> mips;  // levels 1..n (see header); empty: level 0 only
    TextureWrap wrap_u = TextureWrap::repeat;
    TextureWrap wrap_v = TextureWrap::repeat;

    // Linear RGB at uv on level 0 (see header): bilinear, with the wrap modes. Non-finite uv gives
    // texel (0, 0).
    [[nodiscard]] Eigen::Vector3f sample(const Eigen::Vector2f& uv) const;
    // Linear RGB at uv filtered for level of detail `lod` = log2 of the footprint's width in level-0
    // texels: lod <= 0 (or NaN) is sample(uv) exactly; above it, trilinear between levels
    // floor(lod) and floor(lod) + 1, clamped to the last level.
    [[nodiscard]] Eigen::Vector3f sample(const Eigen::Vector2f& uv, float lod) const;
    [[nodiscard]] int levels() const { return 1 + static_cast<int>(mips.size()); }
};

// Levels 1..n of `level0`'s mip chain (see header); empty for a 1x1 image. Throws
// std::invalid_argument for an empty image.
[[nodiscard]] std::vector<Rgb8Image> make_mip_chain(const Rgb8Image& level0);

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

namespace texture_detail {

inline Eigen::Vector3f bilinear(const Rgb8Image& image, const Eigen::Vector2f& uv, TextureWrap wrap_u,
                                TextureWrap wrap_v) {
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
        const std::uint8_t* p = image.at(wrap_index(i, w, wrap_u), wrap_index(j, h, wrap_v));
        return Eigen::Vector3f(lut[p[0]], lut[p[1]], lut[p[2]]);
    };
    return (1.0f - ty) * ((1.0f - tx) * texel(x0, y0) + tx * texel(x0 + 1, y0)) +
           ty * ((1.0f - tx) * texel(x0, y0 + 1) + tx * texel(x0 + 1, y0 + 1));
}

}  // namespace texture_detail

inline Eigen::Vector3f Texture::sample(const Eigen::Vector2f& uv) const {
    return texture_detail::bilinear(image, uv, wrap_u, wrap_v);
}

inline Eigen::Vector3f Texture::sample(const Eigen::Vector2f& uv, float lod) const {
    if (!(lod > 0.0f) || mips.empty()) return sample(uv);
    const float top = static_cast<float>(mips.size());
    const float level = std::min(lod, top);
    const int lower = static_cast<int>(level);  // level >= 0
    const float f = level - static_cast<float>(lower);
    const auto at = [&](int l) {
        return texture_detail::bilinear(l == 0 ? image : mips[static_cast<std::size_t>(l - 1)], uv, wrap_u, wrap_v);
    };
    const Eigen::Vector3f a = at(lower);
    return f > 0.0f ? Eigen::Vector3f((1.0f - f) * a + f * at(lower + 1)) : a;
}

}  // namespace mogao
