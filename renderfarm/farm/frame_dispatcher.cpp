// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/frame_dispatcher.h"

#include <algorithm>
#include <chrono>
#include <deque>
#include <functional>
#include <numeric>

#include <time.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "renderfarm/farm/idle_pause.h"
#include "renderfarm/farm/tile_pass.h"
#include "renderfarm/farm/wire_view.h"

namespace mogao {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Waits without spinning: Open MPI busy-polls inside blocking calls, and when the admin shares cores
// with render ranks (one machine, or a 2-core CI box) a spinning admin steals whole time slices from
// them — seen as 4 ms spikes in tile times that mislead the PBT. 100 µs sleeps cost nothing per
// frame; a wait of unknown length sleeps longer as it goes on (IdleWait).
void sleep_for(std::chrono::microseconds pause) {
    const timespec t{0, static_cast<long>(pause.count()) * 1000};
    nanosleep(&t, nullptr);
}

void sleep_briefly() { sleep_for(std::chrono::microseconds(100)); }

// How long the admin polls a rank's pixel transfer without pausing (FrameDispatcher::poll_until):
// a moving frame's pixels, a few MB, take a few ms over shared memory and tens over a gigabit link.
constexpr double kTransferSpinS = 0.1;

// A wait of unknown length (the next frame's view may be hours away): the pause grows with the
// wait (idle_pause.h).
class IdleWait {
public:
    void pause() {
        sleep_for(idle_pause(std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start_)));
    }

private:
    Clock::time_point start_ = Clock::now();
};

void wait_politely(MPI_Request& request) {
    IdleWait idle;
    for (int done = 0;;) {
        MPI_Test(&request, &done, MPI_STATUS_IGNORE);
        if (done) return;
        idle.pause();
    }
}

MPI_Status probe_politely(int source, int tag) {
    IdleWait idle;
    MPI_Status status;
    for (int found = 0;;) {
        MPI_Iprobe(source, tag, MPI_COMM_WORLD, &found, &status);
        if (found) return status;
        idle.pause();
    }
}

enum Tag : int { kTagRects = 1, kTagReplyHeader, kTagReplyPixels, kTagReplyTiles, kTagProgress, kTagCut, kTagView };

// The view goes from the admin to each render rank point to point, not through a collective: in a
// broadcast tree a stopped rank would keep the view from the ranks below it, and they would fall
// silent with it (the admin could no longer tell which rank was lost).
WireView receive_view() {
    (void)probe_politely(0, kTagView);
    WireView wire{};
    MPI_Recv(&wire, sizeof wire, MPI_BYTE, 0, kTagView, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return wire;
}

struct ReplyHeader {
    std::uint64_t frame_id;
    std::uint64_t rays;
    std::uint64_t payload_bytes;  // pixels, or the error message when ok == 0
    std::uint64_t tiles;
    double render_seconds;
    double cpu_seconds;
    std::int32_t ok;
    std::uint64_t tiles_cut;  // tiles rendered coarse after the admin's cut
    double full_seconds;      // the pass uncut (full_pass_seconds)
};

// A render rank's beat while it renders (kTagProgress); a cut is the frame's sequence (kTagCut).
struct Progress {
    std::uint64_t sequence;
    std::uint64_t done;
    std::uint64_t total;
};

// ---- render ranks --------------------------------------------------------------------------------

// A render rank's main thread while its workers render one frame: each poll sends a progress
// report (non-blocking) and takes the admin's cut of this frame, if any (cuts of earlier frames,
// sent as the rank replied, are dropped).
class RankBeat {
public:
    explicit RankBeat(std::uint64_t sequence) : sequence_(sequence) {}
    RankBeat(const RankBeat&) = delete;
    RankBeat& operator=(const RankBeat&) = delete;

    bool poll(std::size_t done, std::size_t total) {
        while (!sent_.empty()) {  // reports the admin took
            int complete = 0;
            MPI_Test(&sent_.front().request, &complete, MPI_STATUS_IGNORE);
            if (!complete) break;
            sent_.pop_front();
        }
        Pending& p = sent_.emplace_back(Pending{{sequence_, done, total}, MPI_REQUEST_NULL});
        MPI_Isend(&p.progress, sizeof p.progress, MPI_BYTE, 0, kTagProgress, MPI_COMM_WORLD, &p.request);
        for (int found = 1;;) {
            MPI_Iprobe(0, kTagCut, MPI_COMM_WORLD, &found, MPI_STATUS_IGNORE);
            if (!found) break;
            std::uint64_t cut = 0;
            MPI_Recv(&cut, 1, MPI_UINT64_T, 0, kTagCut, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            cut_ = cut_ || cut == sequence_;
        }
        return cut_;
    }
    // Completes every report before the reply (their buffers live here).
    void finish() {
        for (Pending& p : sent_) wait_politely(p.request);
        sent_.clear();
    }

private:
    struct Pending {
        Progress progress;
        MPI_Request request;
    };
    std::uint64_t sequence_;
    std::deque<Pending> sent_;  // stable addresses
    bool cut_ = false;
};

std::vector<PixelRect> receive_rects() {
    MPI_Status status = probe_politely(0, kTagRects);
    int count = 0;
    MPI_Get_count(&status, MPI_INT, &count);
    std::vector<int> flat(static_cast<std::size_t>(count));
    MPI_Recv(flat.data(), count, MPI_INT, 0, kTagRects, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    std::vector<PixelRect> rects;
    for (std::size_t i = 0; i + 3 < flat.size(); i += 4)
        rects.push_back({flat[i], flat[i + 1], flat[i + 2], flat[i + 3]});
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
// `on_header` sees the header before the payload is received.
RankReply receive_reply(int source, const std::function<void(const std::function<bool()>&)>& wait,
                        const std::function<void(const ReplyHeader&)>& on_header) {
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
    on_header(reply.header);
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

// Begins the guide pass's frame when `format` needs guides and a guide pass is given, unless the
// renderer's frame samples the pixel centres: without a guide pass the renderer's own first hits are
// the guides (tile_pass.h), and at pixel centres they are the guide pass's. Throws when it cannot.
const GuidePass* begin_guides(const Renderer& renderer, GuidePass* guides, PackedPixels format,
                              const ViewRequest& view) {
    if (format != PackedPixels::linear_guided || guides == nullptr || renderer.samples_pixel_centres()) return nullptr;
    if (Status s = guides->begin_frame(view); !s.ok()) throw std::invalid_argument(s.error().message);
    return guides;
}

}  // namespace

void serve_render_rank(Renderer* renderer, const DispatchSettings& settings, const std::string& load_error,
                       GuidePass* guides) {
    // A render rank serves for months but, unlike the admin, never trims its heap
    // (common/memory_release.h): loading the scene leaves the heap at a high-water mark (94 MiB for
    // the grotto) that its frames' buffers mostly fit in, so its resident memory settles (in a soak
    // one rank stayed at the mark, the other settled 13 MiB above it within the hour). Trimmed once
    // a minute, it swung between 60 and 100 MiB with the trim's phase instead. What a rank keeps
    // past its frames (the radiance cache's queue) gives its storage back itself.
    for (;;) {
        const WireView wire = receive_view();
        if (wire.stop) return;
        const std::vector<PixelRect> rects = receive_rects();
        ReplyHeader header{wire.frame_id, 0, 0, 0, 0.0, 0.0, 1, 0, 0.0};
        RankBeat beat(wire.sequence);
        const TilePassControl control{[&beat](std::size_t done, std::size_t total) { return beat.poll(done, total); },
                                      settings.rank_beat_s, settings.cut_block};
        try {
            beat.poll(0, 0);  // heard before begin_frame, however long it takes
            if (!renderer) throw std::runtime_error(load_error);
            const ViewRequest view = from_wire(wire);
            renderer->begin_frame(view);
            const PackedPixels format = wire_format(wire.linear);
            const TilePassResult pass =
                render_tile_pass(*renderer, rects, settings.cell_size, settings.threads, settings.exposure,
                                 settings.tone_map, format, begin_guides(*renderer, guides, format, view), &control);
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
            header.tiles_cut = pass.tiles_cut;
            header.full_seconds = full_pass_seconds(pass.render_seconds, pass.cut_at_seconds, pass.tiles_done_at_cut,
                                                    pass.tile_times.size());
            beat.finish();
            send_reply(header, pass.packed_pixels.data(), pass.packed_pixels.size(), tiles_flat);
            // While the admin composites, filters and encodes: off the next frame's critical path.
            renderer->commit_radiance_cache();
        } catch (const std::exception& e) {
            int rank = 0;
            MPI_Comm_rank(MPI_COMM_WORLD, &rank);
            const std::string message = fmt::format("rank {}: frame {}: {}", rank, wire.frame_id, e.what());
            header.ok = 0;
            header.payload_bytes = message.size();
            beat.finish();
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
                                   settings_.balancer == "roundrobin" ? settings_.roundrobin_tile : settings_.snap)) {
    if (mpi.size() == 1 && !local) throw std::invalid_argument("a one-process farm needs a local renderer");
    if (!(settings_.rank_beat_s > 0)) throw std::invalid_argument("DispatchSettings.rank_beat_s must be > 0");
    if (settings_.cut_block < 1) throw std::invalid_argument("DispatchSettings.cut_block must be >= 1");
    if (settings_.threads < 1)
        throw std::invalid_argument("DispatchSettings.threads must be >= 1 (run_farm resolves 0: render_threads.h)");
}

FrameDispatcher::~FrameDispatcher() { stop(); }

int FrameDispatcher::render_ranks() const { return std::max(1, mpi_.render_ranks()); }

void FrameDispatcher::stop() {
    if (stopped_) return;
    stopped_ = true;
    if (mpi_.size() < 2 || broken_) return;  // broken: a rank would never take the broadcast
    WireView stop_view{};
    stop_view.stop = 1;
    for (int r = 1; r < mpi_.size(); ++r) MPI_Send(&stop_view, sizeof stop_view, MPI_BYTE, r, kTagView, MPI_COMM_WORLD);
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
    if (local_) {
        gather_local(view, assignment, format, frame, normalised);
    } else if (!gather(view, assignment, format, frame, normalised)) {
        throw FarmError(fmt::format("frame {} failed on a render rank", view.frame_id));
    }
    frame.stats.render_phase_seconds = seconds_since(start);
    if (frame.stats.tiles_cut == 0) frame.stats.full_seconds = frame.stats.render_phase_seconds;
    finish_stats(frame.stats);
    // Re-balance: this frame's measured tile times predict the stream's next frame.
    predicted = CostMap::from_tile_times(size, settings_.cell_size, normalised);
    return frame;
}

void FrameDispatcher::add_tiles(int rank_index, const std::vector<TileTime>& tiles, double cpu, double wall,
                                std::vector<TileTime>& normalised) {
    // Tiles of the rank as the PBT should see them: at the rank's smoothed speed, or raw.
    speeds_.observe(rank_index, cpu, wall, settings_.threads);
    const double speed = settings_.normalise_rank_speed ? speeds_.speed(rank_index) : 1.0;
    const std::vector<TileTime> scaled = normalise_tile_times(tiles, speed);
    normalised.insert(normalised.end(), scaled.begin(), scaled.end());
}

// A one-process farm: the admin traces the whole frame itself, cut at the budget like the ranks.
void FrameDispatcher::gather_local(const ViewRequest& view, const Assignment& assignment, PackedPixels format,
                                   DispatchedFrame& frame, std::vector<TileTime>& normalised) {
    local_->begin_frame(view);
    const GuidePass* guides = nullptr;
    try {
        guides = begin_guides(*local_, local_guides_, format, view);
    } catch (const std::runtime_error& e) {
        throw FarmError(e.what());
    }
    const auto start = Clock::now();
    auto next_beat = start + std::chrono::seconds(1);
    const TilePassControl control{[&](std::size_t, std::size_t) {
                                      if (heartbeat_ && Clock::now() >= next_beat) {
                                          heartbeat_();
                                          next_beat = Clock::now() + std::chrono::seconds(1);
                                      }
                                      return settings_.frame_budget_s > 0 &&
                                             seconds_since(start) > settings_.frame_budget_s;
                                  },
                                  settings_.rank_beat_s, settings_.cut_block};
    TilePassResult pass = render_tile_pass(*local_, assignment.rects[0], settings_.cell_size, settings_.threads,
                                           settings_.exposure, settings_.tone_map, format, guides, &control);
    unpack_reply(assignment.rects[0], pass.packed_pixels, format, frame);
    add_tiles(0, pass.tile_times, pass.cpu_seconds, pass.render_seconds, normalised);
    frame.stats.tiles_cut = pass.tiles_cut;
    frame.stats.full_seconds =
        full_pass_seconds(pass.render_seconds, pass.cut_at_seconds, pass.tiles_done_at_cut, pass.tile_times.size());
    frame.tiles = std::move(pass.tile_times);
    frame.stats.rays = pass.rays;
    frame.stats.rank_render_seconds = {pass.render_seconds};
}

// One frame's watch on the ranks: who was heard when, and the frame's time budget.
struct FrameDispatcher::Watch {
    Clock::time_point sent;
    std::uint64_t sequence;
    std::uint64_t frame_id;
    RankLiveness liveness;
    bool cut_sent = false;
    [[nodiscard]] double now() const { return seconds_since(sent); }
};

// Polls `done()` until it is true; meanwhile takes the ranks' progress reports, cuts the frame at
// its budget, and throws RankTimeout (the farm broken) when a rank that owes a reply falls silent
// (heartbeat about once a second).
template <typename Done>
void FrameDispatcher::poll_until(Watch& watch, const Done& done, const char* phase, int transfer_from) {
    auto next_beat = Clock::now() + std::chrono::seconds(1);
    const double started = watch.now();
    double last_poll = started;
    while (!done()) {
        // The admin itself stalled (descheduled on a loaded host, a sanitizer, a long unpack):
        // the ranks could not be heard meanwhile, so the stall is not their silence.
        if (const double gap = watch.now() - last_poll; gap > kAdminStallS) {
            for (int r = 1; r <= mpi_.render_ranks(); ++r)
                if (watch.liveness.owes(r)) watch.liveness.allow(r, gap);
        }
        last_poll = watch.now();
        drain_progress(watch);
        // While one rank's pixels transfer, a rank that has finished cannot be heard: it waits in its own send
        // until the admin takes its reply. Were they judged, a rank stopped between its reply header and its
        // pixels would have the others named in its place. So only the transferring rank is judged; the others'
        // silence counts again from the transfer's end.
        if (transfer_from > 0) {
            for (int r = 1; r <= mpi_.render_ranks(); ++r)
                if (r != transfer_from && watch.liveness.owes(r)) watch.liveness.heard(r, watch.now());
        }
        if (settings_.frame_budget_s > 0 && !watch.cut_sent && watch.now() > settings_.frame_budget_s) send_cuts(watch);
        if (const std::vector<int> silent = watch.liveness.silent(watch.now()); !silent.empty())
            lost(watch, silent, phase);
        if (heartbeat_ && Clock::now() >= next_beat) {
            heartbeat_();
            next_beat = Clock::now() + std::chrono::seconds(1);
        }
        // A rank's pixels arrive in fragments (Open MPI's shared-memory and TCP transports move a
        // large message a fragment per progress call on the receiving side), so a pause between
        // polls paces the transfer: 100 µs per fragment made a moving frame's pixels, a few MB,
        // take about 12 ms where the copy takes 2. While pixels flow, poll without pausing, for at
        // most kTransferSpinS (a stalled transfer is then waited for like any other reply).
        if (transfer_from == 0 || watch.now() - started > kTransferSpinS) sleep_briefly();
    }
}

void FrameDispatcher::lost(const Watch& watch, const std::vector<int>& ranks, const char* phase) {
    broken_ = true;
    lost_ranks_ = ranks;
    std::string who;
    for (int r : ranks) who += (who.empty() ? "" : ", ") + std::to_string(r);
    if (phase) who = phase;  // the broadcast is not any one rank's
    const double limit = watch.liveness.limit_s(ranks);
    double longest_silence = 0.0;
    for (int r : ranks) longest_silence = std::max(longest_silence, watch.liveness.silent_for(r, watch.now()));
    const std::string every = limit > watch.liveness.silence_s() ? ", every rank that owed a reply silent at once" : "";
    throw RankTimeout(fmt::format(
        "render rank(s) {} did not reply to frame {} and sent no progress report for {:.1f} s (liveness limit "
        "{} s{}, reports every {} s while rendering): host down, process stopped or link cut",
        who, watch.frame_id, longest_silence, limit, every, settings_.rank_beat_s));
}

// Takes every progress report waiting: a report of this frame counts its rank as heard.
void FrameDispatcher::drain_progress(Watch& watch) {
    for (;;) {
        int found = 0;
        MPI_Status status;
        MPI_Iprobe(MPI_ANY_SOURCE, kTagProgress, MPI_COMM_WORLD, &found, &status);
        if (!found) return;
        Progress progress{};
        MPI_Recv(&progress, sizeof progress, MPI_BYTE, status.MPI_SOURCE, kTagProgress, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
        if (progress.sequence == watch.sequence) watch.liveness.heard(status.MPI_SOURCE, watch.now());
    }
}

// The frame's budget ran out: the ranks that still owe a reply render the rest coarse.
void FrameDispatcher::send_cuts(Watch& watch) {
    watch.cut_sent = true;
    for (int r = 1; r <= mpi_.render_ranks(); ++r)
        if (watch.liveness.owes(r)) MPI_Send(&watch.sequence, 1, MPI_UINT64_T, r, kTagCut, MPI_COMM_WORLD);
}

// The next rank whose reply header has arrived.
int FrameDispatcher::probe_reply(Watch& watch) {
    MPI_Status status;
    int found = 0;
    poll_until(
        watch,
        [&] {
            MPI_Iprobe(MPI_ANY_SOURCE, kTagReplyHeader, MPI_COMM_WORLD, &found, &status);
            return found != 0;
        },
        nullptr);
    watch.liveness.heard(status.MPI_SOURCE, watch.now());
    return status.MPI_SOURCE;
}

bool FrameDispatcher::gather(const ViewRequest& view, const Assignment& assignment, PackedPixels format,
                             DispatchedFrame& frame, std::vector<TileTime>& normalised) {
    WireView wire = to_wire(view);
    wire.linear = format == PackedPixels::linear_guided ? 2 : format == PackedPixels::linear ? 1 : 0;
    wire.sequence = ++sequence_;
    Watch watch{Clock::now(), wire.sequence, view.frame_id,
                RankLiveness(mpi_.render_ranks(), settings_.rank_deadline_s, 0.0)};
    std::vector<MPI_Request> sends(static_cast<std::size_t>(mpi_.render_ranks()));
    for (int r = 1; r <= mpi_.render_ranks(); ++r)
        MPI_Isend(&wire, sizeof wire, MPI_BYTE, r, kTagView, MPI_COMM_WORLD, &sends[static_cast<std::size_t>(r - 1)]);
    poll_until(
        watch,
        [&] {
            int done = 0;
            MPI_Testall(static_cast<int>(sends.size()), sends.data(), &done, MPI_STATUSES_IGNORE);
            return done != 0;
        },
        "(view sent to the ranks)");
    for (int r = 0; r < mpi_.render_ranks(); ++r) {
        std::vector<int> flat;
        for (const PixelRect& rect : assignment.rects[static_cast<std::size_t>(r)])
            flat.insert(flat.end(), {rect.x0, rect.y0, rect.x1, rect.y1});
        MPI_Send(flat.data(), static_cast<int>(flat.size()), MPI_INT, r + 1, kTagRects, MPI_COMM_WORLD);
    }
    // A rank reports progress only once it has its rects: its silence counts from here.
    for (int r = 1; r <= mpi_.render_ranks(); ++r) watch.liveness.heard(r, watch.now());
    frame.stats.rank_render_seconds.assign(static_cast<std::size_t>(mpi_.render_ranks()), 0.0);
    bool ok = true;
    for (int k = 0; k < mpi_.render_ranks(); ++k) {
        // Replies in arrival order: a slow rank does not hold up compositing the others.
        const int source = probe_reply(watch);
        // While its pixels transfer the rank sends nothing else: their time at the slowest link is allowed.
        RankReply reply = receive_reply(
            source, [&](const std::function<bool()>& done) { poll_until(watch, done, nullptr, source); },
            [&](const ReplyHeader& h) {
                // The ranks that finished meanwhile wait in their own sends, silent, until the admin
                // is done with this one: the transfer's time is allowed to every rank that owes.
                const double transfer_s = double(h.payload_bytes) / kSlowestLinkBytesPerSecond;
                for (int r = 1; r <= mpi_.render_ranks(); ++r)
                    if (watch.liveness.owes(r)) watch.liveness.allow(r, transfer_s);
            });
        watch.liveness.replied(source);
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
        add_tiles(source - 1, tiles, reply.header.cpu_seconds, reply.header.render_seconds, normalised);
        frame.tiles.insert(frame.tiles.end(), tiles.begin(), tiles.end());
        frame.stats.rays += reply.header.rays;
        frame.stats.rank_render_seconds[static_cast<std::size_t>(source - 1)] = reply.header.render_seconds;
        frame.stats.tiles_cut += reply.header.tiles_cut;
        frame.stats.full_seconds = std::max(frame.stats.full_seconds, reply.header.full_seconds);
    }
    return ok;
}

}  // namespace mogao
