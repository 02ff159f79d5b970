// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/frame_dispatcher.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <numeric>

#include <time.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "renderfarm/farm/tile_pass.h"
#include "renderfarm/farm/wire_view.h"

namespace mogao {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Waits without spinning: Open MPI busy-polls inside blocking calls, and when the admin shares cores
// with render ranks (one machine, or a 2-core CI box) a spinning admin steals whole time slices from
// them — seen as 4 ms spikes in tile times that mislead the PBT. 100 µs sleeps cost nothing per frame.
void sleep_briefly() {
    timespec pause{0, 100'000};
    nanosleep(&pause, nullptr);
}

void wait_politely(MPI_Request& request) {
    for (int done = 0;;) {
        MPI_Test(&request, &done, MPI_STATUS_IGNORE);
        if (done) return;
        sleep_briefly();
    }
}

MPI_Status probe_politely(int source, int tag) {
    MPI_Status status;
    for (int found = 0;;) {
        MPI_Iprobe(source, tag, MPI_COMM_WORLD, &found, &status);
        if (found) return status;
        sleep_briefly();
    }
}

void broadcast_view(WireView& wire) {
    MPI_Request request;
    MPI_Ibcast(&wire, sizeof wire, MPI_BYTE, 0, MPI_COMM_WORLD, &request);
    wait_politely(request);
}

enum Tag : int { kTagRects = 1, kTagReplyHeader, kTagReplyPixels, kTagReplyTiles };

struct ReplyHeader {
    std::uint64_t frame_id;
    std::uint64_t rays;
    std::uint64_t payload_bytes;  // pixels, or the error message when ok == 0
    std::uint64_t tiles;
    double render_seconds;
    double cpu_seconds;
    std::int32_t ok;
};

// ---- render ranks --------------------------------------------------------------------------------

std::vector<PixelRect> receive_rects() {
    MPI_Status status = probe_politely(0, kTagRects);
    int count = 0;
    MPI_Get_count(&status, MPI_INT, &count);
    std::vector<int> flat(static_cast<std::size_t>(count));
    MPI_Recv(flat.data(), count, MPI_INT, 0, kTagRects, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    std::vector<PixelRect> rects;
    for (std::size_t i = 0; i + 3 < flat.size(); i += 4) rects.push_back({flat[i], flat[i + 1], flat[i + 2], flat[i + 3]});
    return rects;
}

void send_reply(const ReplyHeader& header, const void* payload, std::size_t payload_bytes,
                const std::vector<double>& tiles_flat) {
    MPI_Send(&header, sizeof header, MPI_BYTE, 0, kTagReplyHeader, MPI_COMM_WORLD);
    MPI_Send(payload, static_cast<int>(payload_bytes), MPI_BYTE, 0, kTagReplyPixels, MPI_COMM_WORLD);
    MPI_Send(tiles_flat.data(), static_cast<int>(tiles_flat.size()), MPI_DOUBLE, 0, kTagReplyTiles, MPI_COMM_WORLD);
}

// ---- admin -----------------------------------------------------------------------------------------

struct RankReply {
    ReplyHeader header{};
    std::vector<std::uint8_t> payload;
    std::vector<double> tiles;
};

// One rank's reply (header, payload, tile times), every receive non-blocking under the deadline:
// a rank stopped half-way through its reply (a rendezvous transfer waits for the sender) cannot
// block the admin either.
// `wait(done)` polls `done` until true, under the frame's deadline (FrameDispatcher::poll_until).
RankReply receive_reply(int source, const std::function<void(const std::function<bool()>&)>& wait) {
    const auto receive = [&](void* data, int count, MPI_Datatype type, int tag) {
        MPI_Request request;
        MPI_Irecv(data, count, type, source, tag, MPI_COMM_WORLD, &request);
        wait([&] {
            int done = 0;
            MPI_Test(&request, &done, MPI_STATUS_IGNORE);
            return done != 0;
        });
    };
    RankReply reply;
    receive(&reply.header, sizeof reply.header, MPI_BYTE, kTagReplyHeader);
    reply.payload.resize(reply.header.payload_bytes);
    receive(reply.payload.data(), static_cast<int>(reply.payload.size()), MPI_BYTE, kTagReplyPixels);
    MPI_Status status;
    int found = 0;
    wait([&] {
        MPI_Iprobe(source, kTagReplyTiles, MPI_COMM_WORLD, &found, &status);
        return found != 0;
    });
    int count = 0;
    MPI_Get_count(&status, MPI_DOUBLE, &count);
    reply.tiles.resize(static_cast<std::size_t>(count));
    receive(reply.tiles.data(), count, MPI_DOUBLE, kTagReplyTiles);
    return reply;
}

void unpack_reply(const std::vector<PixelRect>& rects, const std::vector<std::uint8_t>& packed, PackedPixels format,
                  DispatchedFrame& frame) {
    switch (format) {
        case PackedPixels::srgb8:
            unpack_rects(rects, packed, frame.image);
            break;
        case PackedPixels::linear:
            unpack_linear_rects(rects, packed, frame.radiance);
            break;
        case PackedPixels::linear_guided:
            unpack_guided_rects(rects, packed, frame.radiance, frame.guides);
            break;
    }
}

void finish_stats(FrameStats& stats) {
    const auto& t = stats.rank_render_seconds;
    const double max_rank = t.empty() ? 0.0 : *std::max_element(t.begin(), t.end());
    const double mean_rank = t.empty() ? 0.0 : std::accumulate(t.begin(), t.end(), 0.0) / double(t.size());
    stats.balance_efficiency = max_rank > 0 ? mean_rank / max_rank : 1.0;
    stats.rays_per_second = stats.render_phase_seconds > 0 ? double(stats.rays) / stats.render_phase_seconds : 0.0;
}

// What the wire's `linear` field asks for (0 sRGB8, 1 linear, 2 linear with guides).
PackedPixels wire_format(std::int32_t linear) {
    return linear == 2 ? PackedPixels::linear_guided : linear == 1 ? PackedPixels::linear : PackedPixels::srgb8;
}

// Begins the guide pass's frame when `format` needs guides; throws when it cannot.
const GuidePass* begin_guides(GuidePass* guides, PackedPixels format, const ViewRequest& view) {
    if (format != PackedPixels::linear_guided) return nullptr;
    if (!guides) throw std::runtime_error("this farm has no guide pass: it cannot send the denoiser's guides");
    if (Status s = guides->begin_frame(view); !s.ok()) throw std::invalid_argument(s.error().message);
    return guides;
}

}  // namespace

void serve_render_rank(Renderer* renderer, const DispatchSettings& settings, const std::string& load_error,
                       GuidePass* guides) {
    for (;;) {
        WireView wire{};
        broadcast_view(wire);
        if (wire.stop) return;
        const std::vector<PixelRect> rects = receive_rects();
        ReplyHeader header{wire.frame_id, 0, 0, 0, 0.0, 0.0, 1};
        try {
            if (!renderer) throw std::runtime_error(load_error);
            const ViewRequest view = from_wire(wire);
            renderer->begin_frame(view);
            const PackedPixels format = wire_format(wire.linear);
            const TilePassResult pass =
                render_tile_pass(*renderer, rects, settings.cell_size, settings.threads, settings.exposure,
                                 settings.tone_map, format, begin_guides(guides, format, view));
            std::vector<double> tiles_flat;
            tiles_flat.reserve(pass.tile_times.size() * 5);
            for (const TileTime& t : pass.tile_times)
                tiles_flat.insert(tiles_flat.end(), {double(t.rect.x0), double(t.rect.y0), double(t.rect.x1),
                                                     double(t.rect.y1), t.seconds});
            header.rays = pass.rays;
            header.payload_bytes = pass.packed_pixels.size();
            header.tiles = pass.tile_times.size();
            header.render_seconds = pass.render_seconds;
            header.cpu_seconds = pass.cpu_seconds;
            send_reply(header, pass.packed_pixels.data(), pass.packed_pixels.size(), tiles_flat);
        } catch (const std::exception& e) {
            int rank = 0;
            MPI_Comm_rank(MPI_COMM_WORLD, &rank);
            const std::string message = fmt::format("rank {}: frame {}: {}", rank, wire.frame_id, e.what());
            header.ok = 0;
            header.payload_bytes = message.size();
            send_reply(header, message.data(), message.size(), {});
        }
    }
}

FrameDispatcher::FrameDispatcher(const MpiSession& mpi, DispatchSettings settings, Renderer* local,
                                 GuidePass* local_guides)
    : mpi_(mpi),
      settings_(std::move(settings)),
      local_(mpi.size() == 1 ? local : nullptr),
      local_guides_(mpi.size() == 1 ? local_guides : nullptr),
      balancer_(make_load_balancer(settings_.balancer,
                                   settings_.balancer == "roundrobin" ? settings_.roundrobin_tile : settings_.snap)),
      deadline_({settings_.rank_deadline_s, settings_.rank_deadline_min_s, settings_.rank_deadline_factor}) {
    if (mpi.size() == 1 && !local) throw std::invalid_argument("a one-process farm needs a local renderer");
}

FrameDispatcher::~FrameDispatcher() { stop(); }

int FrameDispatcher::render_ranks() const { return std::max(1, mpi_.render_ranks()); }

void FrameDispatcher::stop() {
    if (stopped_) return;
    stopped_ = true;
    if (mpi_.size() < 2 || broken_) return;  // broken: a rank would never take the broadcast
    WireView stop_view{};
    stop_view.stop = 1;
    broadcast_view(stop_view);
}

CostMap& FrameDispatcher::stream_map(std::uint64_t stream, ImageSize size) {
    auto found = predicted_.find(stream);
    if (found == predicted_.end()) {
        if (predicted_.size() >= std::max<std::size_t>(1, settings_.max_streams)) {
            const auto oldest =
                std::min_element(predicted_.begin(), predicted_.end(),
                                 [](const auto& a, const auto& b) { return a.second.last_used < b.second.last_used; });
            predicted_.erase(oldest);
        }
        found = predicted_.insert_or_assign(stream, StreamMap{CostMap::uniform(size, settings_.cell_size), 0}).first;
    } else if (found->second.map.size() != size) {
        // The same stream at another resolution scale: what was dear stays dear.
        found->second.map = found->second.map.total() > 0 ? found->second.map.resampled(size, settings_.cell_size)
                                                          : CostMap::uniform(size, settings_.cell_size);
    }
    found->second.last_used = ++frames_;
    return found->second.map;
}

DispatchedFrame FrameDispatcher::render(const ViewRequest& view, std::uint64_t stream, PackedPixels format) {
    if (broken_) throw RankTimeout("the farm lost a render rank; the MPI job must restart");
    if (stopped_) throw FarmError("the farm was stopped");
    const ImageSize size = render_size(view);
    CostMap& predicted = stream_map(stream, size);
    const Assignment assignment = balancer_->assign(predicted, render_ranks());

    DispatchedFrame frame;
    if (format == PackedPixels::srgb8) {
        frame.image = Rgb8Image(size);
    } else {
        frame.radiance = RgbFloatImage(size);
    }
    if (format == PackedPixels::linear_guided) frame.guides = GuideBuffers(size);
    frame.stats.frame = view.frame_id;
    frame.stats.rank_predicted_seconds = assignment.predicted_cost;
    const auto start = Clock::now();
    std::vector<TileTime> normalised;
    if (!gather(view, assignment, format, frame, normalised))
        throw FarmError(fmt::format("frame {} failed on a render rank", view.frame_id));
    frame.stats.render_phase_seconds = seconds_since(start);
    finish_stats(frame.stats);
    // Re-balance: this frame's measured tile times predict the stream's next frame.
    predicted = CostMap::from_tile_times(size, settings_.cell_size, normalised);
    return frame;
}

// Polls `done()` until it is true; past `deadline` marks the farm broken and throws RankTimeout
// naming `who` (heartbeat about once a second meanwhile).
template <typename Done>
void FrameDispatcher::poll_until(Clock::time_point deadline, const Done& done, const std::string& who,
                                 std::uint64_t frame_id) {
    auto next_beat = Clock::now() + std::chrono::seconds(1);
    while (!done()) {
        const auto now = Clock::now();
        if (now >= deadline) {
            broken_ = true;
            throw RankTimeout(
                fmt::format("render rank(s) {} did not reply to frame {} within {:.1f} s (frame deadline: {} x "
                            "its expected time, {}..{} s): host down, process stopped or link cut",
                            who, frame_id, frame_deadline_s_, settings_.rank_deadline_factor,
                            settings_.rank_deadline_min_s, settings_.rank_deadline_s));
        }
        if (heartbeat_ && now >= next_beat) {
            heartbeat_();
            next_beat = now + std::chrono::seconds(1);
        }
        sleep_briefly();
    }
}

// The next rank whose reply header has arrived.
int FrameDispatcher::probe_reply_until(Clock::time_point deadline, const std::vector<bool>& replied,
                                       std::uint64_t frame_id) {
    MPI_Status status;
    int found = 0;
    std::string silent;
    for (std::size_t r = 0; r < replied.size(); ++r)
        if (!replied[r]) silent += (silent.empty() ? "" : ", ") + std::to_string(r + 1);
    poll_until(
        deadline,
        [&] {
            MPI_Iprobe(MPI_ANY_SOURCE, kTagReplyHeader, MPI_COMM_WORLD, &found, &status);
            return found != 0;
        },
        silent, frame_id);
    return status.MPI_SOURCE;
}

bool FrameDispatcher::gather(const ViewRequest& view, const Assignment& assignment, PackedPixels format,
                             DispatchedFrame& frame, std::vector<TileTime>& normalised) {
    // Tiles of rank `r` as the PBT should see them: at the rank's smoothed speed, or raw.
    const auto add_tiles = [&](int r, const std::vector<TileTime>& tiles, double cpu, double wall) {
        speeds_.observe(r, cpu, wall, settings_.threads);
        const double speed = settings_.normalise_rank_speed ? speeds_.speed(r) : 1.0;
        const std::vector<TileTime> scaled = normalise_tile_times(tiles, speed);
        normalised.insert(normalised.end(), scaled.begin(), scaled.end());
    };
    if (local_) {  // a one-process farm: the admin traces the whole frame itself
        local_->begin_frame(view);
        const GuidePass* guides = nullptr;
        try {
            guides = begin_guides(local_guides_, format, view);
        } catch (const std::runtime_error& e) {
            throw FarmError(e.what());
        }
        TilePassResult pass = render_tile_pass(*local_, assignment.rects[0], settings_.cell_size, settings_.threads,
                                               settings_.exposure, settings_.tone_map, format, guides);
        unpack_reply(assignment.rects[0], pass.packed_pixels, format, frame);
        add_tiles(0, pass.tile_times, pass.cpu_seconds, pass.render_seconds);
        frame.tiles = std::move(pass.tile_times);
        frame.stats.rays = pass.rays;
        frame.stats.rank_render_seconds = {pass.render_seconds};
        return true;
    }
    WireView wire = to_wire(view);
    wire.linear = format == PackedPixels::linear_guided ? 2 : format == PackedPixels::linear ? 1 : 0;
    const double cost = frame_cost_units(view);
    frame_deadline_s_ = deadline_.seconds_for(cost);
    const auto sent = Clock::now();
    const auto deadline =
        frame_deadline_s_ > 0
            ? sent + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(frame_deadline_s_))
            : Clock::time_point::max();
    MPI_Request broadcast;
    MPI_Ibcast(&wire, sizeof wire, MPI_BYTE, 0, MPI_COMM_WORLD, &broadcast);
    poll_until(
        deadline,
        [&] {
            int done = 0;
            MPI_Test(&broadcast, &done, MPI_STATUS_IGNORE);
            return done != 0;
        },
        "(view broadcast)", view.frame_id);
    for (int r = 0; r < mpi_.render_ranks(); ++r) {
        std::vector<int> flat;
        for (const PixelRect& rect : assignment.rects[static_cast<std::size_t>(r)])
            flat.insert(flat.end(), {rect.x0, rect.y0, rect.x1, rect.y1});
        MPI_Send(flat.data(), static_cast<int>(flat.size()), MPI_INT, r + 1, kTagRects, MPI_COMM_WORLD);
    }
    frame.stats.rank_render_seconds.assign(static_cast<std::size_t>(mpi_.render_ranks()), 0.0);
    bool ok = true;
    std::vector<bool> replied(static_cast<std::size_t>(mpi_.render_ranks()), false);
    for (int k = 0; k < mpi_.render_ranks(); ++k) {
        // Replies in arrival order: a slow rank does not hold up compositing the others.
        const int source = probe_reply_until(deadline, replied, view.frame_id);
        replied[static_cast<std::size_t>(source - 1)] = true;
        RankReply reply = receive_reply(source, [&](const std::function<bool()>& done) {
            poll_until(deadline, done, std::to_string(source), view.frame_id);
        });
        if (!reply.header.ok) {
            spdlog::error("{}", std::string(reply.payload.begin(), reply.payload.end()));
            ok = false;
            continue;
        }
        const std::vector<PixelRect>& rects = assignment.rects[static_cast<std::size_t>(source - 1)];
        try {
            unpack_reply(rects, reply.payload, format, frame);
        } catch (const std::exception& e) {
            spdlog::error("rank {}: frame {}: bad reply: {}", source, view.frame_id, e.what());
            ok = false;
            continue;
        }
        std::vector<TileTime> tiles;
        for (std::size_t i = 0; i + 4 < reply.tiles.size(); i += 5)
            tiles.push_back(
                {{int(reply.tiles[i]), int(reply.tiles[i + 1]), int(reply.tiles[i + 2]), int(reply.tiles[i + 3])},
                 reply.tiles[i + 4]});
        add_tiles(source - 1, tiles, reply.header.cpu_seconds, reply.header.render_seconds);
        frame.tiles.insert(frame.tiles.end(), tiles.begin(), tiles.end());
        frame.stats.rays += reply.header.rays;
        frame.stats.rank_render_seconds[static_cast<std::size_t>(source - 1)] = reply.header.render_seconds;
    }
    if (ok) deadline_.observe(cost, std::chrono::duration<double>(Clock::now() - sent).count());
    return ok;
}

}  // namespace mogao
