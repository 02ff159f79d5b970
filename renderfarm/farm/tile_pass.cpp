// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/tile_pass.h"
#include "common/thread_clock.h"

#include <atomic>
#include <chrono>
#include <cstring>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <time.h>

namespace mogao {
namespace {

using Clock = std::chrono::steady_clock;

std::vector<PixelRect> split_into_cells(const std::vector<PixelRect>& rects, int cell) {
    std::vector<PixelRect> tiles;
    for (const PixelRect& r : rects) {
        if (r.empty()) continue;
        for (int y = (r.y0 / cell) * cell; y < r.y1; y += cell)
            for (int x = (r.x0 / cell) * cell; x < r.x1; x += cell)
                tiles.push_back(intersect(r, PixelRect{x, y, x + cell, y + cell}));
    }
    return tiles;
}

std::size_t bytes_per_pixel(PackedPixels format) { return format == PackedPixels::linear ? 3 * sizeof(float) : 3; }

// Copies the rows of `rects` out of `image` (one of the two frame types) into `out`, rect by rect.
template <typename Image>
std::vector<std::uint8_t> pack(const std::vector<PixelRect>& rects, const Image& image, PackedPixels format) {
    std::vector<std::uint8_t> out(packed_size(rects, format));
    std::uint8_t* cursor = out.data();
    for (const PixelRect& r : rects) {
        for (int y = r.y0; y < r.y1; ++y) {
            const std::size_t row = static_cast<std::size_t>(r.width()) * bytes_per_pixel(format);
            std::memcpy(cursor, image.at(r.x0, y), row);
            cursor += row;
        }
    }
    return out;
}

template <typename Image>
void unpack(const std::vector<PixelRect>& rects, const std::vector<std::uint8_t>& packed, PackedPixels format,
            Image& frame) {
    if (packed.size() != packed_size(rects, format))
        throw std::invalid_argument("packed pixel count does not match the assigned rects");
    const std::uint8_t* in = packed.data();
    for (const PixelRect& r : rects) {
        if (r.empty()) continue;
        if (r.x0 < 0 || r.y0 < 0 || r.x1 > frame.size.width || r.y1 > frame.size.height)
            throw std::invalid_argument("rect outside the frame");
        for (int y = r.y0; y < r.y1; ++y) {
            const std::size_t row = static_cast<std::size_t>(r.width()) * bytes_per_pixel(format);
            std::memcpy(frame.at(r.x0, y), in, row);
            in += row;
        }
    }
}

}  // namespace

std::size_t packed_size(const std::vector<PixelRect>& rects, PackedPixels format) {
    std::size_t bytes = 0;
    for (const PixelRect& r : rects) bytes += static_cast<std::size_t>(r.area()) * bytes_per_pixel(format);
    return bytes;
}

TilePassResult render_tile_pass(const Renderer& renderer, const std::vector<PixelRect>& rects, int cell_size,
                                int threads, float exposure, ToneMap tone_map, PackedPixels format) {
    if (cell_size < 1) throw std::invalid_argument("cell_size must be >= 1");
    const auto start = Clock::now();
    const ImageSize size = renderer.render_size();
    for (const PixelRect& r : rects)
        if (!r.empty() && (r.x0 < 0 || r.y0 < 0 || r.x1 > size.width || r.y1 > size.height))
            throw std::invalid_argument("rect outside the render size");

    TilePassResult result;
    const std::vector<PixelRect> tiles = split_into_cells(rects, cell_size);
    result.tile_times.resize(tiles.size());
    RgbFloatImage radiance(size);
    Rgb8Image display(format == PackedPixels::srgb8 ? size : ImageSize{0, 0});

    std::atomic<std::size_t> next{0};
    std::atomic<std::uint64_t> rays{0};
    std::exception_ptr failure;
    std::mutex failure_mutex;
    double cpu_seconds = 0.0;
    const auto worker = [&] {
        const double cpu_start = thread_cpu_seconds();
        try {
            for (std::size_t i = next++; i < tiles.size(); i = next++) {
                const auto t0 = Clock::now();
                const TileStats stats = renderer.render(tiles[i], radiance);
                if (format == PackedPixels::srgb8) to_srgb8(radiance, tiles[i], exposure, display, tone_map);
                result.tile_times[i] = {tiles[i], std::chrono::duration<double>(Clock::now() - t0).count()};
                rays += stats.rays;
            }
        } catch (...) {
            const std::lock_guard lock(failure_mutex);
            if (!failure) failure = std::current_exception();
            next = tiles.size();
        }
        const std::lock_guard lock(failure_mutex);
        cpu_seconds += thread_cpu_seconds() - cpu_start;
    };
    {
        std::vector<std::jthread> pool;
        for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
        worker();
    }
    if (failure) std::rethrow_exception(failure);

    result.packed_pixels =
        format == PackedPixels::linear ? pack(rects, radiance, format) : pack(rects, display, format);
    result.rays = rays;
    result.cpu_seconds = cpu_seconds;
    result.render_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return result;
}

void unpack_rects(const std::vector<PixelRect>& rects, const std::vector<std::uint8_t>& packed, Rgb8Image& frame) {
    unpack(rects, packed, PackedPixels::srgb8, frame);
}

void unpack_linear_rects(const std::vector<PixelRect>& rects, const std::vector<std::uint8_t>& packed,
                         RgbFloatImage& frame) {
    unpack(rects, packed, PackedPixels::linear, frame);
}

}  // namespace mogao
