// SPDX-License-Identifier: Apache-2.0
// Guide buffers (a "G-buffer") for the denoiser: what the first camera hit of each pixel is, so the
// filter can tell a noisy pixel from an edge.
//
// Layout: same grid as the frame they guide (RgbFloatImage, common/image.h): row-major, top row
// first, pixel (x, y) centred at (x + 0.5, y + 0.5) of the render size. Two sources fill them: the
// renderer itself, from the camera ray of each pixel's first sample (Renderer::render with guides,
// renderer.h: at 1 spp exactly the ray whose radiance they guide), or the denoiser's guide pass, one
// primary ray through each pixel centre (renderfarm/denoise/guide_pass.h). Per pixel:
//   hit     1 = the camera ray hit a surface, 0 = it hit nothing (the sky). Sky pixels are passed
//           through by the filter and never mixed with surface pixels.
//   albedo  linear RGB diffuse reflectance of the hit, each channel in [0, 1] (material albedo times
//           the mesh's tint, renderfarm/trace/render_scene.h); 0 for the sky.
//   normal  unit shading normal in world coordinates, facing the camera ray; 0 for the sky.
//   depth   distance from the eye to the hit along the unit camera ray, metres (> 0); 0 for the sky.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/image.h"
#include "common/pixel_rect.h"

namespace mogao {

struct GuideBuffers {
    ImageSize size;
    std::vector<std::uint8_t> hit;  // W*H
    std::vector<float> albedo;      // W*H*3, interleaved R, G, B
    std::vector<float> normal;      // W*H*3, interleaved x, y, z
    std::vector<float> depth;       // W*H

    GuideBuffers() = default;
    // All pixels "sky" (hit 0, zero albedo, normal and depth).
    explicit GuideBuffers(ImageSize s)
        : size(s),
          hit(static_cast<std::size_t>(s.pixel_count()), 0),
          albedo(static_cast<std::size_t>(s.pixel_count()) * 3, 0.0f),
          normal(static_cast<std::size_t>(s.pixel_count()) * 3, 0.0f),
          depth(static_cast<std::size_t>(s.pixel_count()), 0.0f) {}

    // Pixel i saw a surface: albedo and normal 3 floats each (as above), depth metres.
    void set_surface(std::size_t i, const float* albedo_rgb, const float* normal_xyz, float depth_m) {
        hit[i] = 1;
        depth[i] = depth_m;
        for (std::size_t c = 0; c < 3; ++c) {
            albedo[3 * i + c] = albedo_rgb[c];
            normal[3 * i + c] = normal_xyz[c];
        }
    }
    // Pixel i saw the sky: zero hit, depth, albedo and normal.
    void set_sky(std::size_t i) {
        hit[i] = 0;
        depth[i] = 0.0f;
        for (std::size_t c = 0; c < 3; ++c) albedo[3 * i + c] = normal[3 * i + c] = 0.0f;
    }

    [[nodiscard]] std::size_t pixel(int x, int y) const {
        return static_cast<std::size_t>(y) * static_cast<std::size_t>(size.width) + static_cast<std::size_t>(x);
    }
};

}  // namespace mogao
