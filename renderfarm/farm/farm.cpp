#include "renderfarm/farm/farm.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <numeric>
#include <optional>
#include <stdexcept>

#include <time.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "renderfarm/encode/contact_sheet.h"
#include "renderfarm/encode/file_io.h"
#include "renderfarm/encode/jpeg_codec.h"
#include "renderfarm/encode/png_io.h"
#include "renderfarm/farm/camera_path.h"
#include "renderfarm/farm/tile_pass.h"
#include "renderfarm/farm/wire_view.h"
#include "renderfarm/schedule/load_balancer.h"
#include "renderfarm/trace/renderer.h"

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
    std::uint64_t pixel_bytes;   // or error message bytes when ok == 0
    std::uint64_t tiles;
    double render_seconds;
    std::int32_t ok;
};

// ---- render ranks -------------------------------------------------------------------------------

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

void render_rank_loop(Renderer* renderer, const FarmJob& job, float exposure, const std::string& load_error) {
    for (;;) {
        WireView wire{};
        broadcast_view(wire);
        if (wire.stop) return;
        const std::vector<PixelRect> rects = receive_rects();
        ReplyHeader header{wire.frame_id, 0, 0, 0, 0.0, 1};
        try {
            if (!renderer) throw std::runtime_error(load_error);
            renderer->begin_frame(from_wire(wire));
            TilePassResult pass = render_tile_pass(*renderer, rects, job.cell_size, job.threads, exposure);
            std::vector<double> tiles_flat;
            for (const TileTime& t : pass.tile_times)
                tiles_flat.insert(tiles_flat.end(), {double(t.rect.x0), double(t.rect.y0), double(t.rect.x1),
                                                     double(t.rect.y1), t.seconds});
            header.rays = pass.rays;
            header.pixel_bytes = pass.packed_pixels.size();
            header.tiles = pass.tile_times.size();
            header.render_seconds = pass.render_seconds;
            send_reply(header, pass.packed_pixels.data(), pass.packed_pixels.size(), tiles_flat);
        } catch (const std::exception& e) {
            int rank = 0;
            MPI_Comm_rank(MPI_COMM_WORLD, &rank);
            const std::string message = fmt::format("rank {}: frame {}: {}", rank, wire.frame_id, e.what());
            header.ok = 0;
            header.pixel_bytes = message.size();
            send_reply(header, message.data(), message.size(), {});
        }
    }
}

// ---- admin -----------------------------------------------------------------------------------------

struct RankReply {
    ReplyHeader header{};
    std::vector<std::uint8_t> payload;
    std::vector<double> tiles;
};

RankReply receive_reply(int source) {
    RankReply reply;
    MPI_Recv(&reply.header, sizeof reply.header, MPI_BYTE, source, kTagReplyHeader, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    reply.payload.resize(reply.header.pixel_bytes);
    MPI_Recv(reply.payload.data(), static_cast<int>(reply.payload.size()), MPI_BYTE, source, kTagReplyPixels,
             MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    MPI_Status status;
    MPI_Probe(source, kTagReplyTiles, MPI_COMM_WORLD, &status);
    int count = 0;
    MPI_Get_count(&status, MPI_DOUBLE, &count);
    reply.tiles.resize(static_cast<std::size_t>(count));
    MPI_Recv(reply.tiles.data(), count, MPI_DOUBLE, source, kTagReplyTiles, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return reply;
}

void stop_render_ranks(const MpiSession& mpi) {
    if (mpi.size() < 2) return;
    WireView stop{};
    stop.stop = 1;
    broadcast_view(stop);
}

class Admin {
public:
    Admin(const MpiSession& mpi, const FarmJob& job, const Scene& scene, Renderer* local, RunInfo run)
        : mpi_(mpi), job_(job), scene_(scene), local_(local), run_(std::move(run)),
          balancer_(make_load_balancer(job.balancer, job.balancer == "roundrobin" ? job.roundrobin_tile : job.snap)) {}

    int run() {
        const std::vector<ViewerPose> poses = make_camera_path(job_.path, scene_.viewer, job_.frames);
        const ImageSize size = render_size(job_.view_template);
        std::optional<CostMap> predicted;
        std::vector<FrameStats> stats;
        std::vector<std::vector<TileTime>> tile_log;
        std::vector<Rgb8Image> thumbnails;
        const int ranks = std::max(1, mpi_.render_ranks());
        const int sheet_every = job_.contact_sheet_frames > 0
                                    ? std::max(1, static_cast<int>(poses.size()) / job_.contact_sheet_frames) : 0;
        JpegEncoder encoder;
        std::filesystem::create_directories(job_.out_dir);

        for (std::size_t f = 0; f < poses.size(); ++f) {
            const auto frame_start = Clock::now();
            ViewRequest view = job_.view_template;
            view.frame_id = f;
            view.pose = poses[f];
            view.request_time_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                       std::chrono::system_clock::now().time_since_epoch()).count();
            if (!predicted) predicted = CostMap::uniform(size, job_.cell_size);
            const Assignment assignment = balancer_->assign(*predicted, ranks);

            FrameStats frame;
            frame.frame = f;
            frame.rank_predicted_seconds = assignment.predicted_cost;
            Rgb8Image image(size);
            std::vector<TileTime> tiles;
            const auto render_start = Clock::now();
            if (!render_frame(view, assignment, image, tiles, frame)) {
                return 1;
            }
            frame.render_phase_seconds = seconds_since(render_start);
            frame.rays_per_second = frame.render_phase_seconds > 0 ? double(frame.rays) / frame.render_phase_seconds : 0;
            const double max_rank = *std::max_element(frame.rank_render_seconds.begin(), frame.rank_render_seconds.end());
            const double mean_rank = std::accumulate(frame.rank_render_seconds.begin(), frame.rank_render_seconds.end(), 0.0) /
                                     double(frame.rank_render_seconds.size());
            frame.balance_efficiency = max_rank > 0 ? mean_rank / max_rank : 1.0;

            const auto encode_start = Clock::now();
            const std::vector<std::uint8_t> jpeg = encoder.encode(image, view.quality.jpeg_quality);
            frame.encode_seconds = seconds_since(encode_start);
            frame.jpeg_bytes = jpeg.size();
            write_file_atomically(job_.out_dir / fmt::format("frame-{:04d}.jpg", f), jpeg);
            if (job_.save_raw) write_ppm(job_.out_dir / fmt::format("frame-{:04d}.ppm", f), image);
            if (sheet_every > 0 && f % static_cast<std::size_t>(sheet_every) == 0 &&
                static_cast<int>(thumbnails.size()) < job_.contact_sheet_frames)
                thumbnails.push_back(downscale_box(image, {480, std::max(1, 480 * size.height / size.width)}));

            // Re-balance: this frame's measured tile times predict the next frame's cost.
            predicted = CostMap::from_tile_times(size, job_.cell_size, tiles);
            frame.frame_seconds = seconds_since(frame_start);
            spdlog::info("frame {:4d}: {:6.3f} s, efficiency {:.3f}, {:6.2f} Mrays/s, encode {:5.1f} ms, {:7d} bytes",
                         f, frame.frame_seconds, frame.balance_efficiency, frame.rays_per_second / 1e6,
                         frame.encode_seconds * 1e3, frame.jpeg_bytes);
            stats.push_back(std::move(frame));
            tile_log.push_back(std::move(tiles));
        }
        stop_render_ranks(mpi_);
        write_stats_json(job_.out_dir / "stats.json", run_, stats);
        write_tile_costs_json(job_.out_dir / "tile-costs.json", size, job_.cell_size, tile_log);
        if (!thumbnails.empty()) {
            write_png(job_.out_dir / "contact-sheet.png", make_contact_sheet(thumbnails, 4, 480));
        }
        return 0;
    }

private:
    // Fills `image` and `tiles`; false after reporting a rank's failure (the job then stops).
    bool render_frame(const ViewRequest& view, const Assignment& assignment, Rgb8Image& image,
                      std::vector<TileTime>& tiles, FrameStats& frame) {
        if (local_) {  // a one-process farm: the admin traces the whole frame itself
            local_->begin_frame(view);
            TilePassResult pass = render_tile_pass(*local_, assignment.rects[0], job_.cell_size, job_.threads, scene_.exposure);
            unpack_rects(assignment.rects[0], pass.packed_pixels, image);
            tiles = std::move(pass.tile_times);
            frame.rays = pass.rays;
            frame.rank_render_seconds = {pass.render_seconds};
            return true;
        }
        WireView wire = to_wire(view);
        broadcast_view(wire);
        for (int r = 0; r < mpi_.render_ranks(); ++r) {
            std::vector<int> flat;
            for (const PixelRect& rect : assignment.rects[static_cast<std::size_t>(r)])
                flat.insert(flat.end(), {rect.x0, rect.y0, rect.x1, rect.y1});
            MPI_Send(flat.data(), static_cast<int>(flat.size()), MPI_INT, r + 1, kTagRects, MPI_COMM_WORLD);
        }
        frame.rank_render_seconds.assign(static_cast<std::size_t>(mpi_.render_ranks()), 0.0);
        bool ok = true;
        for (int k = 0; k < mpi_.render_ranks(); ++k) {
            // Take replies in arrival order so a slow rank does not hold up compositing the others.
            const int source = probe_politely(MPI_ANY_SOURCE, kTagReplyHeader).MPI_SOURCE;
            RankReply reply = receive_reply(source);
            if (!reply.header.ok) {
                spdlog::error("{}", std::string(reply.payload.begin(), reply.payload.end()));
                ok = false;
                continue;
            }
            try {
                unpack_rects(assignment.rects[static_cast<std::size_t>(source - 1)], reply.payload, image);
            } catch (const std::exception& e) {
                spdlog::error("rank {}: frame {}: bad reply: {}", source, view.frame_id, e.what());
                ok = false;
                continue;
            }
            for (std::size_t i = 0; i + 4 < reply.tiles.size(); i += 5)
                tiles.push_back({{int(reply.tiles[i]), int(reply.tiles[i + 1]), int(reply.tiles[i + 2]), int(reply.tiles[i + 3])},
                                 reply.tiles[i + 4]});
            frame.rays += reply.header.rays;
            frame.rank_render_seconds[static_cast<std::size_t>(source - 1)] = reply.header.render_seconds;
        }
        if (!ok) stop_render_ranks(mpi_);
        return ok;
    }

    const MpiSession& mpi_;
    const FarmJob& job_;
    const Scene& scene_;
    Renderer* local_;
    RunInfo run_;
    std::unique_ptr<LoadBalancer> balancer_;
};

}  // namespace

int run_farm_job(const MpiSession& mpi, const FarmJob& job) {
    // 1. Every rank loads the scene itself; a collective check makes a failure on any rank stop all.
    const auto load_start = Clock::now();
    std::optional<Scene> scene;
    SceneLoadReport report;
    std::string error;
    try {
        scene = load_scene(job.scene_file, job.scene_options, &report);
    } catch (const std::exception& e) {
        error = e.what();
    }
    const double load_seconds = seconds_since(load_start);
    int loaded = scene ? 1 : 0, all_loaded = 0;
    MPI_Allreduce(&loaded, &all_loaded, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (!all_loaded) {
        if (!scene) spdlog::error("rank {}: {}", mpi.rank(), error);
        return 1;
    }

    // 2. Render ranks (or a lone admin) build the BVH; the admin only schedules and encodes.
    std::optional<Renderer> renderer;
    double bvh_seconds = 0.0;
    const bool renders = !mpi.is_admin() || mpi.size() == 1;
    if (renders) {
        const auto bvh_start = Clock::now();
        try {
            RendererOptions options;
            options.embree_config = fmt::format("threads={}", job.threads);
            renderer.emplace(*scene, options);
        } catch (const std::exception& e) {
            error = e.what();
        }
        bvh_seconds = seconds_since(bvh_start);
    }
    int built = (!renders || renderer) ? 1 : 0, all_built = 0;
    MPI_Allreduce(&built, &all_built, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    double max_bvh = 0.0;
    MPI_Reduce(&bvh_seconds, &max_bvh, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    if (!all_built) {
        if (!error.empty()) spdlog::error("rank {}: cannot build the BVH: {}", mpi.rank(), error);
        return 1;
    }

    if (!mpi.is_admin()) {
        render_rank_loop(renderer ? &*renderer : nullptr, job, scene->exposure, error);
        return 0;
    }

    RunInfo run;
    run.scene = job.scene_file.string();
    run.balancer = job.balancer;
    run.ranks = mpi.size();
    run.render_ranks = std::max(1, mpi.render_ranks());
    run.threads_per_rank = job.threads;
    run.size = render_size(job.view_template);
    run.camera = std::holds_alternative<CylinderScreen>(job.view_template.camera) ? "cylinder" : "pinhole";
    run.path = job.path;
    run.spp = job.view_template.quality.spp;
    run.max_bounces = job.view_template.quality.max_bounces;
    run.ao_samples = job.view_template.quality.ao_samples;
    run.jpeg_quality = job.view_template.quality.jpeg_quality;
    run.resolution_scale = job.view_template.quality.resolution_scale;
    run.seed = job.view_template.seed;
    run.scene_load = report;
    run.scene_load_seconds = load_seconds;
    run.bvh_build_seconds = max_bvh;
    spdlog::info("scene {}: {} triangles instanced from {} meshes, loaded in {:.2f} s; BVH {:.2f} s",
                 run.scene, report.instanced_triangles, report.meshes.size(), load_seconds, max_bvh);
    for (const MeshLoadFigures& m : report.meshes)
        spdlog::info("  mesh {:<12} {:>9} triangles {:>8} vertices {:6.3f} s  {}", m.name, m.triangles, m.vertices,
                     m.seconds, m.source);
    try {
        return Admin(mpi, job, *scene, renderer ? &*renderer : nullptr, run).run();
    } catch (const std::exception& e) {
        // One boundary for the admin's frame loop: report, release the render ranks, fail the job.
        spdlog::error("admin: {}", e.what());
        stop_render_ranks(mpi);
        return 1;
    }
}

}  // namespace mogao
