// SPDX-License-Identifier: Apache-2.0
// One rank's share of a frame: render its rects tile by tile, time every tile, and pack the
// sRGB8 pixels for the admin. This is the measured input of the PBT (schedule/).
//
// Memory: a rank holds only its share. Each tile is rendered into a window of the tile's size
// (Renderer::render with an origin) and copied straight into the packed buffer, so no rank
// allocates a full-frame film: a request for a huge frame costs each rank its rects' bytes, not
// the frame's (issue: "allocates only its share of the frame on each rank").
//
// Tiles are cost-map cells (cell_size x cell_size pixels, aligned to the global image grid) clipped
// to each rect, so a tile's time maps onto exactly one cell. Pixels are packed rect by rect, row by
// row, RGB8 — the order unpack_rects() expects — or, for PackedPixels::linear, three native
// floats per pixel of linear radiance (before exposure and tone map) in the same order, for the
// admin's progressive accumulation (unpack_linear_rects()). PackedPixels::linear_guided adds the
// denoiser's guides of each pixel (renderfarm/denoise/guide_buffers.h) from a GuidePass sharing the
// renderer's BVH: ten native floats per pixel, radiance R, G, B, albedo R, G, B, normal x, y, z,
// depth (metres; 0 = sky), in the same order (unpack_guided_rects()).
#pragma once

#include <cstdint>
#include <vector>

#include "common/image.h"
#include "renderfarm/denoise/guide_buffers.h"
#include "renderfarm/denoise/guide_pass.h"
#include "renderfarm/schedule/cost_map.h"
#include "renderfarm/trace/film.h"
#include "renderfarm/trace/renderer.h"

namespace mogao {

enum class PackedPixels { srgb8, linear, linear_guided };

struct TilePassResult {
    std::vector<std::uint8_t> packed_pixels;
    std::vector<TileTime> tile_times;  // wall-clock seconds per tile
    std::uint64_t rays = 0;
    double render_seconds = 0.0;  // wall time of the whole pass on this rank
    double cpu_seconds = 0.0;     // thread CPU time of all render threads (CLOCK_THREAD_CPUTIME_ID)
};

// Renders `rects` of the frame begun on `renderer` with `threads` worker threads (>= 1); for
// PackedPixels::linear_guided also the guides of the same pixels with `guides` (begun on the same
// request after the renderer; its time counts in the tile's). Throws what the renderer throws
// (std::invalid_argument for rects outside the image), std::invalid_argument for linear_guided
// without a guide pass, std::runtime_error naming the guide pass's error.
[[nodiscard]] TilePassResult render_tile_pass(const Renderer& renderer, const std::vector<PixelRect>& rects,
                                              int cell_size, int threads, float exposure,
                                              ToneMap tone_map = ToneMap::clamp,
                                              PackedPixels format = PackedPixels::srgb8,
                                              const GuidePass* guides = nullptr);

// Copies packed pixels of `rects` into `frame`. Throws std::invalid_argument when the byte count
// does not match the rects or a rect lies outside the frame.
void unpack_rects(const std::vector<PixelRect>& rects, const std::vector<std::uint8_t>& packed, Rgb8Image& frame);

// The same for PackedPixels::linear into a linear radiance frame.
void unpack_linear_rects(const std::vector<PixelRect>& rects, const std::vector<std::uint8_t>& packed,
                         RgbFloatImage& frame);

// The same for PackedPixels::linear_guided into a linear radiance frame and its guides (both of the
// frame's size; guides.hit = depth > 0).
void unpack_guided_rects(const std::vector<PixelRect>& rects, const std::vector<std::uint8_t>& packed,
                         RgbFloatImage& frame, GuideBuffers& guides);

// Bytes of `rects` packed: 3 per pixel (srgb8), 3 floats per pixel (linear), 10 (linear_guided).
[[nodiscard]] std::size_t packed_size(const std::vector<PixelRect>& rects, PackedPixels format = PackedPixels::srgb8);

}  // namespace mogao
