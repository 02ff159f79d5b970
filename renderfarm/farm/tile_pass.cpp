// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/tile_pass.h"
#include "common/thread_clock.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <time.h>

namespace mogao {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::size_t kGuidedFloats = 10;  // radiance 3, albedo 3, normal 3, depth 1

std::size_t bytes_per_pixel(PackedPixels format) {
    switch (format) {
        case PackedPixels::srgb8:
            return 3;
        case PackedPixels::linear:
            return 3 * sizeof(float);
        case PackedPixels::linear_guided:
            return kGuidedFloats * sizeof(float);
    }
    return 3;
}

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
    TileWriter(float exposure, ToneMap tone_map, PackedPixels format, const GuidePass* guides)
        : exposure_(exposure), tone_map_(tone_map), format_(format), guide_pass_(guides) {}

    // The tile at full quality; `coarse_block` > 0: one traced pixel per block (TilePassControl).
    TileStats render(const Renderer& renderer, const TileJob& job, std::vector<std::uint8_t>& packed,
                     int coarse_block = 0) {
        const ImageSize size{job.tile.width(), job.tile.height()};
        resize(radiance_, size);
        const bool own_guides = format_ == PackedPixels::linear_guided && guide_pass_ == nullptr;
        if (format_ == PackedPixels::linear_guided) resize_guides(guides_, size);
        TileStats stats;
        if (coarse_block > 0) {
            stats = render_coarse(renderer, job.tile, coarse_block, own_guides);
        } else if (own_guides) {
            stats = renderer.render(job.tile, radiance_, job.tile.x0, job.tile.y0, guides_);
        } else {
            stats = renderer.render(job.tile, radiance_, job.tile.x0, job.tile.y0);
        }
        pack(job, packed);
        return stats;
    }

private:
    // One pixel per block x block block of the global grid inside `tile`, traced at the block's
    // centre and copied to the block's pixels of the tile's window (its guides too, with
    // `with_guides`: the block is one flat patch to the denoiser, as it is in the radiance).
    TileStats render_coarse(const Renderer& renderer, const PixelRect& tile, int block, bool with_guides) {
        TileStats stats;
        resize(one_, ImageSize{1, 1});
        if (with_guides) resize_guides(one_guides_, ImageSize{1, 1});
        for (int by = (tile.y0 / block) * block; by < tile.y1; by += block) {
            for (int bx = (tile.x0 / block) * block; bx < tile.x1; bx += block) {
                const PixelRect b = intersect(tile, PixelRect{bx, by, bx + block, by + block});
                const int x = b.x0 + (b.width() - 1) / 2, y = b.y0 + (b.height() - 1) / 2;
                const PixelRect centre{x, y, x + 1, y + 1};
                stats.rays += with_guides ? renderer.render(centre, one_, x, y, one_guides_).rays
                                          : renderer.render(centre, one_, x, y).rays;
                for (int py = b.y0; py < b.y1; ++py) {
                    for (int px = b.x0; px < b.x1; ++px) {
                        std::copy_n(one_.at(0, 0), 3, radiance_.at(px - tile.x0, py - tile.y0));
                        if (with_guides) copy_guide(one_guides_, 0, guides_, guides_.pixel(px - tile.x0, py - tile.y0));
                    }
                }
            }
        }
        return stats;
    }

    static void resize_guides(GuideBuffers& guides, ImageSize size) {  // keeps the capacity
        const auto n = static_cast<std::size_t>(size.pixel_count());
        guides.size = size;
        guides.hit.resize(n), guides.depth.resize(n), guides.albedo.resize(3 * n), guides.normal.resize(3 * n);
    }

    static void copy_guide(const GuideBuffers& from, std::size_t i, GuideBuffers& to, std::size_t j) {
        to.hit[j] = from.hit[i];
        to.depth[j] = from.depth[i];
        std::copy_n(from.albedo.data() + 3 * i, 3, to.albedo.data() + 3 * j);
        std::copy_n(from.normal.data() + 3 * i, 3, to.normal.data() + 3 * j);
    }

    void pack(const TileJob& job, std::vector<std::uint8_t>& packed) {
        const ImageSize size{job.tile.width(), job.tile.height()};
        if (format_ == PackedPixels::linear_guided) {
            if (guide_pass_ != nullptr) render_guides(job);
            copy_guided_rows(job, packed);
        } else if (format_ == PackedPixels::srgb8) {
            resize(display_, size);
            to_srgb8(radiance_, PixelRect::whole(size), exposure_, display_, tone_map_);
            copy_rows(job, display_, packed);
        } else {
            copy_rows(job, radiance_, packed);
        }
    }

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

    // The guide pass's guides of the tile (a baseline: pixel centres, a second primary ray each).
    void render_guides(const TileJob& job) {
        if (Status st = guide_pass_->render(job.tile, guides_, job.tile.x0, job.tile.y0); !st.ok())
            throw std::runtime_error(st.error().message);
    }

    // Radiance and guides of the tile, kGuidedFloats per pixel, at the tile's place in its rect.
    void copy_guided_rows(const TileJob& job, std::vector<std::uint8_t>& packed) const {
        const int w = job.tile.width();
        std::vector<float> row(static_cast<std::size_t>(w) * kGuidedFloats);
        for (int y = job.tile.y0; y < job.tile.y1; ++y) {
            for (int x = 0; x < w; ++x) {
                const std::size_t i = guides_.pixel(x, y - job.tile.y0);
                float* out = row.data() + static_cast<std::size_t>(x) * kGuidedFloats;
                const float* c = radiance_.at(x, y - job.tile.y0);
                const bool hit = guides_.hit[i] != 0;
                for (std::size_t k = 0; k < 3; ++k) {
                    out[k] = c[k];
                    out[3 + k] = hit ? guides_.albedo[3 * i + k] : 0.0f;
                    out[6 + k] = hit ? guides_.normal[3 * i + k] : 0.0f;
                }
                out[9] = hit ? guides_.depth[i] : 0.0f;
            }
            const std::size_t at = job.rect_offset + (static_cast<std::size_t>(y - job.rect.y0) * job.rect.width() +
                                                      (job.tile.x0 - job.rect.x0)) *
                                                         bytes_per_pixel(format_);
            std::memcpy(packed.data() + at, row.data(), row.size() * sizeof(float));
        }
    }

    float exposure_;
    ToneMap tone_map_;
    PackedPixels format_;
    const GuidePass* guide_pass_;
    RgbFloatImage radiance_;
    RgbFloatImage one_;  // a coarse tile's traced pixel
    Rgb8Image display_;
    GuideBuffers guides_;
    GuideBuffers one_guides_;  // a coarse tile's traced pixel
};

void check_packed(const std::vector<PixelRect>& rects, const std::vector<std::uint8_t>& packed, PackedPixels format,
                  ImageSize frame) {
    if (packed.size() != packed_size(rects, format))
        throw std::invalid_argument("packed pixel count does not match the assigned rects");
    for (const PixelRect& r : rects)
        if (!r.empty() && (r.x0 < 0 || r.y0 < 0 || r.x1 > frame.width || r.y1 > frame.height))
            throw std::invalid_argument("rect outside the frame");
}

template <typename Image>
void unpack(const std::vector<PixelRect>& rects, const std::vector<std::uint8_t>& packed, PackedPixels format,
            Image& frame) {
    check_packed(rects, packed, format, frame.size);
    const std::uint8_t* in = packed.data();
    for (const PixelRect& r : rects) {
        if (r.empty()) continue;
        for (int y = r.y0; y < r.y1; ++y) {
            const std::size_t row = static_cast<std::size_t>(r.width()) * bytes_per_pixel(format);
            std::memcpy(frame.at(r.x0, y), in, row);
            in += row;
        }
    }
}

// What the workers of one pass share.
struct PassState {
    std::atomic<std::size_t> next{0};       // the next tile to take
    std::atomic<std::size_t> done{0};       // tiles finished
    std::atomic<std::size_t> tiles_cut{0};  // of which rendered coarse
    std::atomic<std::uint64_t> rays{0};
    std::atomic<int> coarse_block{0};  // > 0 once the pass is cut
    std::mutex mutex;                  // guards the rest
    std::condition_variable finished;
    int running = 0;  // worker threads still rendering
    std::exception_ptr failure;
    double cpu_seconds = 0.0;
};

void run_worker(const Renderer& renderer, const std::vector<TileJob>& tiles, TileWriter writer, TilePassResult& result,
                PassState& state) {
    const double cpu_start = thread_cpu_seconds();
    try {
        for (std::size_t i = state.next++; i < tiles.size(); i = state.next++) {
            const int block = state.coarse_block;
            const auto t0 = Clock::now();
            const TileStats stats = writer.render(renderer, tiles[i], result.packed_pixels, block);
            double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
            if (block > 0) {  // its full cost, estimated from the pixels traced
                const PixelRect& t = tiles[i].tile;
                const int traced = ((t.x1 - 1) / block - t.x0 / block + 1) * ((t.y1 - 1) / block - t.y0 / block + 1);
                seconds *= double(t.area()) / double(std::max(1, traced));
                ++state.tiles_cut;
            }
            result.tile_times[i] = {tiles[i].tile, seconds};
            state.rays += stats.rays;
            ++state.done;
        }
    } catch (...) {
        const std::lock_guard lock(state.mutex);
        if (!state.failure) state.failure = std::current_exception();
        state.next = tiles.size();
    }
    const std::lock_guard lock(state.mutex);
    state.cpu_seconds += thread_cpu_seconds() - cpu_start;
    --state.running;
    state.finished.notify_all();
}

// The calling thread of a controlled pass: polls at once and every beat until the workers are done.
// Asks the control whether to cut; on the first yes the tiles still to take are rendered coarse.
void poll_once(const TilePassControl& control, std::size_t total, Clock::time_point start, PassState& state,
               TilePassResult& result) {
    const std::size_t done = state.done;
    if (control.poll(done, total) && state.coarse_block == 0) {
        result.cut_at_seconds = std::chrono::duration<double>(Clock::now() - start).count();
        result.tiles_done_at_cut = done;
        state.coarse_block = control.cut_block;
    }
}

void poll_until_done(const TilePassControl& control, std::size_t total, Clock::time_point start, PassState& state,
                     TilePassResult& result) {
    const auto beat = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(control.beat_s));
    for (;;) {
        poll_once(control, total, start, state, result);
        std::unique_lock lock(state.mutex);
        if (state.finished.wait_for(lock, beat, [&] { return state.running == 0; })) return;
    }
}

}  // namespace

std::size_t packed_size(const std::vector<PixelRect>& rects, PackedPixels format) {
    std::size_t bytes = 0;
    for (const PixelRect& r : rects) bytes += static_cast<std::size_t>(r.area()) * bytes_per_pixel(format);
    return bytes;
}

TilePassResult render_tile_pass(const Renderer& renderer, const std::vector<PixelRect>& rects, int cell_size,
                                int threads, float exposure, ToneMap tone_map, PackedPixels format,
                                const GuidePass* guides, const TilePassControl* control) {
    if (cell_size < 1) throw std::invalid_argument("cell_size must be >= 1");
    if (control && !(control->beat_s > 0)) throw std::invalid_argument("TilePassControl.beat_s must be > 0");
    if (control && control->cut_block < 1) throw std::invalid_argument("TilePassControl.cut_block must be >= 1");
    const auto start = Clock::now();
    const ImageSize size = renderer.render_size();
    for (const PixelRect& r : rects)
        if (!r.empty() && (r.x0 < 0 || r.y0 < 0 || r.x1 > size.width || r.y1 > size.height))
            throw std::invalid_argument("rect outside the render size");

    TilePassResult result;
    const std::vector<TileJob> tiles = split_into_cells(rects, cell_size, format);
    result.tile_times.resize(tiles.size());
    result.packed_pixels.resize(packed_size(rects, format));

    PassState state;
    const auto worker = [&] {
        run_worker(renderer, tiles, TileWriter(exposure, tone_map, format, guides), result, state);
    };
    std::exception_ptr poll_failure;
    {
        std::vector<std::jthread> pool;
        const int workers = std::max(1, threads);
        state.running = control ? workers : workers - 1;
        // The first poll before any worker starts: a pass that is already over its budget (or
        // told to cut) renders every tile coarse, not whatever the workers took meanwhile.
        if (control) poll_once(*control, tiles.size(), start, state, result);
        for (int t = control ? 0 : 1; t < workers; ++t) pool.emplace_back(worker);
        if (!control) {
            worker();
        } else {
            try {
                poll_until_done(*control, tiles.size(), start, state, result);
            } catch (...) {
                poll_failure = std::current_exception();
                state.next = tiles.size();
            }
        }
    }
    if (state.failure) std::rethrow_exception(state.failure);
    if (poll_failure) std::rethrow_exception(poll_failure);

    result.rays = state.rays;
    result.cpu_seconds = state.cpu_seconds;
    result.tiles_cut = state.tiles_cut;
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

void unpack_guided_rects(const std::vector<PixelRect>& rects, const std::vector<std::uint8_t>& packed,
                         RgbFloatImage& frame, GuideBuffers& guides) {
    if (guides.size != frame.size || guides.hit.size() != static_cast<std::size_t>(frame.size.pixel_count()))
        throw std::invalid_argument("guide buffers do not match the frame's size");
    check_packed(rects, packed, PackedPixels::linear_guided, frame.size);
    const auto* in = reinterpret_cast<const float*>(packed.data());  // packed as native floats
    for (const PixelRect& r : rects) {
        if (r.empty()) continue;
        for (int y = r.y0; y < r.y1; ++y) {
            for (int x = r.x0; x < r.x1; ++x, in += kGuidedFloats) {
                const std::size_t i = guides.pixel(x, y);
                float* c = frame.at(x, y);
                for (std::size_t k = 0; k < 3; ++k) {
                    c[k] = in[k];
                    guides.albedo[3 * i + k] = in[3 + k];
                    guides.normal[3 * i + k] = in[6 + k];
                }
                guides.depth[i] = in[9];
                guides.hit[i] = in[9] > 0.0f ? 1 : 0;
            }
        }
    }
}

}  // namespace mogao
