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
// denoiser's guides of each pixel (renderfarm/trace/guide_buffers.h), from a GuidePass sharing the
// renderer's BVH (a second primary ray per pixel centre; what the farm uses), or without one from
// the camera ray of each pixel's first sample (Renderer::render with guides: no ray more):
// ten native floats per pixel, radiance R, G, B, albedo R, G, B, normal x, y, z, depth (metres;
// 0 = sky), in the same order (unpack_guided_rects()).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "common/image.h"
#include "renderfarm/denoise/guide_pass.h"
#include "renderfarm/schedule/cost_map.h"
#include "renderfarm/trace/film.h"
#include "renderfarm/trace/guide_buffers.h"
#include "renderfarm/trace/renderer.h"

namespace mogao {

enum class PackedPixels { srgb8, linear, linear_guided };

// Progress reports and the time budget of a pass (frame_dispatcher.h: the render ranks' heartbeat
// and the admin's cut, rank_liveness.h). With a control, every tile is rendered on `threads`
// worker threads and the calling thread only calls `poll` (it may talk MPI there): first at once,
// then about every `beat_s` until the workers are done, with the tiles finished so far and the
// pass's tile count. `poll` returning true cuts the pass: tiles not begun yet are rendered coarse,
// one traced pixel (the block's centre, the value the full pass would give it, renderer.h) per
// `cut_block` x `cut_block` block of the global grid, copied to the whole block (for
// PackedPixels::linear_guided its guides too, unless a guide pass traces them per pixel). Tiles
// begun before the cut finish at full quality. A coarse tile's time is reported scaled by its
// pixels over its traced pixels (an estimate of its full cost, for the PBT).
struct TilePassControl {
    std::function<bool(std::size_t done, std::size_t total)> poll;
    double beat_s = 0.1;  // > 0
    int cut_block = 8;    // >= 1
};

struct TilePassResult {
    std::vector<std::uint8_t> packed_pixels;
    std::vector<TileTime> tile_times;  // wall-clock seconds per tile
    std::uint64_t rays = 0;
    double render_seconds = 0.0;        // wall time of the whole pass on this rank
    double cpu_seconds = 0.0;           // thread CPU time of all render threads (CLOCK_THREAD_CPUTIME_ID)
    std::size_t tiles_cut = 0;          // tiles rendered coarse after a cut (TilePassControl)
    double cut_at_seconds = 0.0;        // when the pass was cut, from its start (0: not cut)
    std::size_t tiles_done_at_cut = 0;  // tiles finished at full quality when it was cut
};

// Renders `rects` of the frame begun on `renderer` with `threads` worker threads (>= 1); for
// PackedPixels::linear_guided also the guides of the same pixels: the renderer's own, or with
// `guides` when given (begun on the same request after the renderer; its time counts in the
// tile's). Throws what the renderer throws (std::invalid_argument for rects outside the image),
// std::runtime_error naming the guide pass's error; `control` (may be null:
// no progress reports, no cut, the calling thread renders too): std::invalid_argument for a bad
// beat_s or cut_block, and what its poll throws (after the workers stopped).
[[nodiscard]] TilePassResult render_tile_pass(const Renderer& renderer, const std::vector<PixelRect>& rects,
                                              int cell_size, int threads, float exposure,
                                              ToneMap tone_map = ToneMap::clamp,
                                              PackedPixels format = PackedPixels::srgb8,
                                              const GuidePass* guides = nullptr,
                                              const TilePassControl* control = nullptr);

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
