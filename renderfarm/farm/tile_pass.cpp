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

std::size_t bytes_per_pixel(PackedPixels format) { return format == PackedPixels::linear ? 3 * sizeof(float) : 3; }

// A tile and where its rect's pixels start in the packed buffer.
struct TileJob {
    PixelRect tile;
    PixelRect rect;           // the assigned rect the tile lies in
    std::size_t rect_offset;  // byte offset of that rect's first pixel in the packed buffer
};

std::vector<TileJob> split_into_cells(const std::vector<PixelRect>& rects, int cell, PackedPixels format) {
    std::vector<TileJob> tiles;
    std::size_t offset = 0;
    for (const PixelRect& r : rects) {
        if (r.empty()) continue;
        for (int y = (r.y0 / cell) * cell; y < r.y1; y += cell)
            for (int x = (r.x0 / cell) * cell; x < r.x1; x += cell)
                tiles.push_back({intersect(r, PixelRect{x, y, x + cell, y + cell}), r, offset});
        offset += static_cast<std::size_t>(r.area()) * bytes_per_pixel(format);
    }
    return tiles;
}

// A tile's pixels, rendered into a window of the tile's own size (never a whole frame: a rank
// holds only its share) and copied into the packed buffer at the tile's place in its rect.
class TileWriter {
public:
    TileWriter(float exposure, ToneMap tone_map, PackedPixels format)
        : exposure_(exposure), tone_map_(tone_map), format_(format) {}

    TileStats render(const Renderer& renderer, const TileJob& job, std::vector<std::uint8_t>& packed) {
        const ImageSize size{job.tile.width(), job.tile.height()};
        resize(radiance_, size);
        const TileStats stats = renderer.render(job.tile, radiance_, job.tile.x0, job.tile.y0);
        if (format_ == PackedPixels::srgb8) {
            resize(display_, size);
            to_srgb8(radiance_, PixelRect::whole(size), exposure_, display_, tone_map_);
            copy_rows(job, display_, packed);
        } else {
            copy_rows(job, radiance_, packed);
        }
        return stats;
    }

private:
    template <typename Image>
    static void resize(Image& image, ImageSize size) {  // keeps the capacity: no allocation per tile
        image.size = size;
        image.pixels.resize(static_cast<std::size_t>(size.pixel_count()) * 3);
    }

    template <typename Image>
    void copy_rows(const TileJob& job, const Image& window, std::vector<std::uint8_t>& packed) const {
        const std::size_t bpp = bytes_per_pixel(format_);
        const std::size_t row = static_cast<std::size_t>(job.tile.width()) * bpp;
        for (int y = job.tile.y0; y < job.tile.y1; ++y) {
            const std::size_t at =
                job.rect_offset +
                (static_cast<std::size_t>(y - job.rect.y0) * job.rect.width() + (job.tile.x0 - job.rect.x0)) * bpp;
            std::memcpy(packed.data() + at, window.at(0, y - job.tile.y0), row);
        }
    }

    float exposure_;
    ToneMap tone_map_;
    PackedPixels format_;
    RgbFloatImage radiance_;
    Rgb8Image display_;
};

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
    const std::vector<TileJob> tiles = split_into_cells(rects, cell_size, format);
    result.tile_times.resize(tiles.size());
    result.packed_pixels.resize(packed_size(rects, format));

    std::atomic<std::size_t> next{0};
    std::atomic<std::uint64_t> rays{0};
    std::exception_ptr failure;
    std::mutex failure_mutex;
    double cpu_seconds = 0.0;
    const auto worker = [&] {
        const double cpu_start = thread_cpu_seconds();
        try {
            TileWriter writer(exposure, tone_map, format);
            for (std::size_t i = next++; i < tiles.size(); i = next++) {
                const auto t0 = Clock::now();
                const TileStats stats = writer.render(renderer, tiles[i], result.packed_pixels);
                result.tile_times[i] = {tiles[i].tile, std::chrono::duration<double>(Clock::now() - t0).count()};
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
