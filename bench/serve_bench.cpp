// SPDX-License-Identifier: Apache-2.0
// Serve mode's live frame scheduling on the farm alone (no link, no kiosk): frames/s served for a
// moving view and the still-view convergence curve, with every new part on, with each part off,
// and with all of them off (the serial loop of before), all in ONE run so only ratios are read.
//
//   mpirun -n 3 mogao_bench_serve --scene scenes/grotto.json [--width 960] [--height 540]
//          [--warmup-seconds 3] [--move-seconds 4] [--still-seconds 5] [--frame-time-ms 66.7] [--reference-spp 64]
//          [--configs today,all,denoise,...] [--quality PRESET] [--denoise-max-spp 256]
//          [--denoise-iterations 3] [--json FILE] [--side-by-side FILE.png]
//
// Configurations: today (the serial loop of before: every request alone, full size, sRGB8 from the
// ranks), all (every new scheduling part), denoise (all + the à-trous denoiser on frames of at most
// --denoise-max-spp samples, its guides traced by the ranks: live_frames.h), and all minus one part
// (no-rate-aim: the frame-time controller aims at the target itself, without the jitter allowance,
// the hand-off charge and the headroom of schedule/frame_time_controller.h), and denoise-floor-0.2
// (the denoise configuration with the frame-time target's scale floor at 0.2 and the bounces never
// lowered: the controller before its floor of 0.5), and cache (the denoise configuration with moving
// frames from the ranks' radiance cache: renderfarm/trace/cached_packet.h; the cache starts empty
// at the configuration's first frame only if it is the first configuration of the run: the ranks
// keep their caches between configurations, as a farm keeps them between sessions), and temporal
// (the cache configuration with every filtered moving frame first blended with the session's
// earlier frames by reprojection: renderfarm/denoise/temporal_accumulation.h), sparse (the temporal
// configuration shading one pixel in --shading-one-in of each moving frame that has a history) and
// sparse-all-levels (sparse with its blended frames filtered by --denoise-iterations levels, as every
// other filtered frame, instead of LiveOptions::blended_denoise_iterations) and sparse-spatial-variance
// (sparse with the filter's luminance variance estimated spatially at every pixel, not from the
// history's moments: LiveOptions::temporal_variance off).
// With both all and denoise in the run, the denoiser's ratios are printed: frames/s on / off and the
// moving frame's PSNR on - off. --quality takes a preset's request quality (spp, bounces, AO, area
// samples, JPEG; common/quality_preset.h) for every request and the reference; without it the
// request's defaults (1 spp, 0 bounces).
//
// A session looks at the screen (the kiosk's cylinder: radius 3 m, 150 degrees, 0.2-2.8 m) from the
// scene's viewer. Moving: the yaw turns a little every request, so nothing accumulates; after a
// warm-up of at least 10 frames (the frame-time target settles, the PBT learns), frames/s over at
// least 5 frames = frames served (rendered, composited, encoded to JPEG) / wall time. Still: the
// last moving pose is requested again and again; after every frame the served image (upsampled to
// full size when the frame-time target had shrunk it) is compared with the reference (the same view
// at --reference-spp, one render) by PSNR of the sRGB8 frames; comparison time is not counted.
// For the moving frames counted, the table gives the scale the farm served (mean and least), the
// spp and the bounces (means). A moving frame's error: the first frame at the reference's pose after
// another pose, rendered as the configuration renders any moving frame, upsampled to full size,
// against the reference by PSNR, SSIM (bench/quality/image_metrics.h) and GMSD (bench/quality/gmsd.h,
// which counts blur and blocks: lower is better), the mean of 4 such frames. The baseline line
// before the table: today's renderer at full resolution and 1 spp at the same pose (no scheduling,
// no denoiser), the same metrics over 4 frames, and its time per frame.
// The reference is the mean, in linear light, of two independent halves (reference-spp / 2 each,
// distinct RNG keys): the PSNR between the halves is printed as its noise floor. The reference's own
// error is about 6 dB below that floor's (each half has twice the reference's variance, their
// difference four times), so a served frame's PSNR above floor + 6 dB cannot be measured with it.
// --side-by-side writes one PNG of two rows: a moving frame as rendered (at its own size) and as
// upsampled to full size; the still view after --still-seconds and the reference; from the "all new
// parts" configuration (the denoise one when it runs).
// Exits 77 when the scene's scans are absent.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "bench/quality/gmsd.h"
#include "bench/quality/image_metrics.h"
#include "common/image_compare.h"
#include "common/jpeg_codec.h"
#include "common/png_io.h"
#include "common/quality_preset.h"
#include "common/request_limits.h"
#include "renderfarm/farm/farm.h"
#include "renderfarm/farm/live_frames.h"
#include "renderfarm/trace/film.h"

namespace {

using namespace mogao;
using Clock = std::chrono::steady_clock;

struct Config {
    std::string key;  // --configs names it
    std::string name;
    LiveOptions live;
    bool pipeline = true;
    bool rank_speed = true;
};

struct BenchArgs {
    int width = 960, height = 540;
    double warmup_seconds = 3.0, move_seconds = 4.0, still_seconds = 5.0, frame_time_ms = 1000.0 / 15.0;
    int reference_spp = 64;
    std::vector<std::string> configs;  // keys; empty = all
    std::string json, side_by_side;
    std::string quality;  // preset name; empty = Quality{}
    int denoise_max_spp = LiveOptions{}.denoise_max_spp, denoise_iterations = AtrousParams{}.iterations;
    int shading_one_in = LiveOptions{}.shading_one_in;  // the sparse configuration's
};

// The images of the side-by-side PNG: a moving frame as rendered and upsampled, the still view.
struct Snapshots {
    Rgb8Image moving_rendered, moving, still;
};

// Error of a served frame (upsampled to full size) against the reference: PSNR and SSIM of the
// sRGB8 frames, and GMSD (bench/quality/gmsd.h), which counts blur and blocks.
struct FrameQuality {
    double psnr_db = 0, ssim = 0, gmsd = 0;
    FrameQuality& operator+=(const FrameQuality& o) {
        psnr_db += o.psnr_db;
        ssim += o.ssim;
        gmsd += o.gmsd;
        return *this;
    }
    [[nodiscard]] FrameQuality over(int n) const { return {psnr_db / n, ssim / n, gmsd / n}; }
    [[nodiscard]] nlohmann::json json() const { return {{"psnr_db", psnr_db}, {"ssim", ssim}, {"gmsd", gmsd}}; }
};

FrameQuality frame_quality(const Rgb8Image& served, const Rgb8Image& reference) {
    return {psnr(served, reference), quality::ssim_luminance(served, reference), quality::gmsd(served, reference)};
}

// What the farm served for each counted moving frame: its scale, spp and bounces, and where its
// time went on the admin (seconds: the whole frame, the render phase, the slowest rank's tracing,
// the filter; the rest of `frame_seconds` is compositing, accumulation and the hand-off), and the
// render ranks' balance (mean over max of their tracing times: 1 when none waits for another); with
// temporal, the share of its surface pixels that earlier frames supplied by reprojection.
struct ServedLog {
    nlohmann::json frames = nlohmann::json::array();
    double scale_sum = 0, scale_min = 1, spp_sum = 0, bounces_sum = 0;
    double frame_s = 0, render_phase_s = 0, slowest_rank_s = 0, denoise_s = 0, temporal_s = 0, balance_sum = 0;
    double reprojected_sum = 0, shaded_sum = 0;
    int blended = 0;
    void add(const LiveFrame& f) {
        const Quality& q = f.rendered.quality;
        const auto& ranks = f.stats.rank_render_seconds;
        const double slowest = ranks.empty() ? 0.0 : *std::max_element(ranks.begin(), ranks.end());
        frames.push_back({{"scale", q.resolution_scale},
                          {"spp", q.spp},
                          {"bounces", q.max_bounces},
                          {"frame_seconds", f.seconds},
                          {"render_phase_seconds", f.stats.render_phase_seconds},
                          {"slowest_rank_seconds", slowest},
                          {"balance_efficiency", f.stats.balance_efficiency},
                          {"denoise_seconds", f.denoise_seconds},
                          {"temporal_seconds", f.temporal_seconds}});
        if (f.temporal.surface_pixels > 0) {
            const double share = double(f.temporal.reprojected) / double(f.temporal.surface_pixels);
            frames.back()["reprojected_share"] = share;
            const double shaded = 1.0 - double(f.temporal.unshaded) / double(f.temporal.surface_pixels);
            frames.back()["shaded_share"] = shaded;
            frames.back()["filled_share"] = double(f.temporal.filled) / double(f.temporal.surface_pixels);
            reprojected_sum += share;
            shaded_sum += shaded;
            ++blended;
        }
        scale_sum += q.resolution_scale;
        scale_min = std::min(scale_min, q.resolution_scale);
        spp_sum += q.spp;
        bounces_sum += q.max_bounces;
        frame_s += f.seconds;
        render_phase_s += f.stats.render_phase_seconds;
        slowest_rank_s += slowest;
        balance_sum += f.stats.balance_efficiency;
        denoise_s += f.denoise_seconds;
        temporal_s += f.temporal_seconds;
    }
    [[nodiscard]] nlohmann::json summary() const {
        const double n = std::max<double>(1, double(frames.size()));
        nlohmann::json out = {{"scale_mean", scale_sum / n},
                              {"scale_min", scale_min},
                              {"spp_mean", spp_sum / n},
                              {"bounces_mean", bounces_sum / n},
                              {"frame_seconds_mean", frame_s / n},
                              {"render_phase_seconds_mean", render_phase_s / n},
                              {"slowest_rank_seconds_mean", slowest_rank_s / n},
                              {"balance_efficiency_mean", balance_sum / n},
                              {"denoise_seconds_mean", denoise_s / n},
                              {"temporal_seconds_mean", temporal_s / n}};
        if (blended > 0) {
            out["reprojected_share_mean"] = reprojected_sum / blended;
            out["shaded_share_mean"] = shaded_sum / blended;
        }
        return out;
    }
};

// Moving frames measured against the reference (each the first frame at the reference's pose
// after another pose, so the frame-time target picks it as it picks any moving frame).
constexpr int kMovingSamples = 4;

std::vector<Config> all_configs(const BenchArgs& a) {
    Config all{"all", "all new parts", {}, true, true};
    all.live.frame_time_s = a.frame_time_ms / 1e3;
    Config today{"today", "none (serial, as before)", {}, false, false};
    today.live.progressive = false;
    today.live.per_session_maps = false;
    Config denoise = all;
    denoise.key = "denoise";
    denoise.name = "all new parts + denoiser";
    denoise.live.denoise = true;
    denoise.live.denoise_max_spp = a.denoise_max_spp;
    denoise.live.denoise_params.iterations = a.denoise_iterations;
    // The frame-time target as it was: the scale falls to 0.2 and the bounces never drop.
    Config floor = denoise;
    floor.key = "denoise-floor-0.2";
    floor.name = "all + denoiser, scale floor 0.2";
    floor.live.controller.min_scale = 0.2;
    floor.live.controller.min_bounces = request_limits::kMaxBounces.max;
    // The denoise configuration with moving frames from the ranks' radiance cache.
    Config cache = denoise;
    cache.key = "cache";
    cache.name = "all + denoiser + radiance cache";
    cache.live.radiance_cache = true;
    // The cache configuration with each moving frame blended with earlier ones by reprojection.
    Config temporal = cache;
    temporal.key = "temporal";
    temporal.name = "all + denoiser + cache + temporal, every pixel shaded";
    temporal.live.temporal = true;
    temporal.live.shading_one_in = 1;  // every pixel shaded
    // The cache configuration with a still view's second pass of 1 spp (2 by default, as later ones).
    Config second1 = cache;
    second1.key = "cache-second-pass-1spp";
    second1.name = "all + denoiser + cache, second still pass of 1 spp";
    second1.live.still_second_pass_spp = 1;
    // The cache configuration with a still view's first pass of 1 spp (2 by default), as before.
    Config first1 = cache;
    first1.key = "cache-first-pass-1spp";
    first1.name = "all + denoiser + cache, first still pass of 1 spp";
    first1.live.still_first_pass_spp = 1;
    // The temporal configuration with moving frames shading one pixel in --shading-one-in.
    Config sparse = temporal;
    sparse.key = "sparse";
    sparse.name = "all + denoiser + cache + temporal, 1 pixel in " + std::to_string(a.shading_one_in) + " shaded";
    sparse.live.shading_one_in = a.shading_one_in;
    // The sparse configuration with its blended frames filtered by as many levels as any other frame.
    Config sparse_levels = sparse;
    sparse_levels.key = "sparse-all-levels";
    sparse_levels.name = sparse.name + ", " + std::to_string(a.denoise_iterations) + " filter levels";
    sparse_levels.live.blended_denoise_iterations = a.denoise_iterations;
    // The sparse configuration with the filter's luminance variance estimated spatially at every pixel.
    Config sparse_spatial = sparse;
    sparse_spatial.key = "sparse-spatial-variance";
    sparse_spatial.name = sparse.name + ", spatial variance";
    sparse_spatial.live.temporal_variance = false;
    std::vector<Config> out{today,  all,           denoise,        floor,   cache, temporal,
                            sparse, sparse_levels, sparse_spatial, second1, first1};
    const auto without = [&](const char* key, const char* name, auto change) {
        Config c = all;
        c.key = key;
        c.name = name;
        change(c);
        out.push_back(c);
    };
    without("no-progressive", "all but progressive", [](Config& c) { c.live.progressive = false; });
    without("no-target", "all but frame-time target", [](Config& c) { c.live.frame_time_s = 0; });
    without("no-pipeline", "all but pipelining", [](Config& c) { c.pipeline = false; });
    without("no-rank-speed", "all but rank-speed normalisation", [](Config& c) { c.rank_speed = false; });
    without("no-rate-aim", "all but aiming at the served rate", [](Config& c) {
        c.live.controller.jitter_weight = 0;  // aim at the target itself, as before
        c.live.controller.max_handoff = 0;
        c.live.controller.headroom = 0;
    });
    return out;
}

// The configurations --configs names, in the order of all_configs() (today first: the baseline).
std::vector<Config> configs(const BenchArgs& a) {
    std::vector<Config> out;
    for (const Config& c : all_configs(a))
        if (a.configs.empty() || std::find(a.configs.begin(), a.configs.end(), c.key) != a.configs.end())
            out.push_back(c);
    return out;
}

// Bilinear resampling of an sRGB8 frame to `size` (what the kiosk's warp does to a smaller frame).
Rgb8Image upsample(const Rgb8Image& in, ImageSize size) {
    if (in.size == size) return in;
    Rgb8Image out(size);
    const double sx = double(in.size.width) / size.width, sy = double(in.size.height) / size.height;
    for (int y = 0; y < size.height; ++y) {
        const double fy = std::clamp((y + 0.5) * sy - 0.5, 0.0, in.size.height - 1.0);
        const int y0 = int(fy), y1 = std::min(y0 + 1, in.size.height - 1);
        for (int x = 0; x < size.width; ++x) {
            const double fx = std::clamp((x + 0.5) * sx - 0.5, 0.0, in.size.width - 1.0);
            const int x0 = int(fx), x1 = std::min(x0 + 1, in.size.width - 1);
            const double wx = fx - x0, wy = fy - y0;
            for (int c = 0; c < 3; ++c) {
                const double top = in.at(x0, y0)[c] * (1 - wx) + in.at(x1, y0)[c] * wx;
                const double bottom = in.at(x0, y1)[c] * (1 - wx) + in.at(x1, y1)[c] * wx;
                out.at(x, y)[c] = static_cast<std::uint8_t>(std::lround(top * (1 - wy) + bottom * wy));
            }
        }
    }
    return out;
}

// Encodes one frame, inline or on a worker while the next frame renders (one encode in flight).
class Encoder {
public:
    explicit Encoder(bool pipeline) : pipeline_(pipeline) {}
    ~Encoder() { finish(); }
    void submit(Rgb8Image image) {
        finish();
        if (!pipeline_) {
            bytes_ += encoder_.encode(image, 85).size();
            return;
        }
        pending_ =
            std::async(std::launch::async, [this, im = std::move(image)] { return encoder_.encode(im, 85).size(); });
    }
    void finish() {
        if (pending_.valid()) bytes_ += pending_.get();
    }

private:
    bool pipeline_;
    JpegEncoder encoder_;
    std::future<std::size_t> pending_;
    std::size_t bytes_ = 0;
};

ViewRequest session_view(const Scene& scene, const BenchArgs& a) {
    ViewRequest v;
    v.size = {a.width, a.height};
    v.camera = CylinderScreen{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 0.0}};
    v.pose.eye = scene.viewer.start + Eigen::Vector3d(0.0, scene.viewer.eye_height_m, 0.0);
    v.pose.yaw_deg = scene.viewer.start_yaw_deg;
    v.session = 1;
    if (!a.quality.empty()) {
        v.quality = quality_preset(a.quality)->request;
        v.quality.resolution_scale = 1.0;
    }
    return v;
}

// A moving frame's error against the reference: kMovingSamples times, a frame 1.5 degrees off and then the first
// frame back at the reference's pose, upsampled to the reference's size (shots keep the last).
FrameQuality moving_frame_quality(LiveFrames& live, ViewRequest& request, double base_yaw, const Rgb8Image& reference,
                                  std::uint64_t& next_id, Snapshots& shots) {
    LiveFrame last;
    FrameQuality moving;
    for (int k = 0; k < kMovingSamples; ++k) {
        request.pose.yaw_deg = base_yaw + 1.5;
        request.frame_id = next_id++;
        (void)live.render(request);
        // The still view starts where the visitor stopped: the reference's pose.
        request.pose.yaw_deg = base_yaw;
        request.frame_id = next_id++;
        last = live.render(request);  // the first frame at the new pose: a moving frame's error
        shots.moving_rendered = last.image;
        shots.moving = upsample(last.image, reference.size);
        moving += frame_quality(shots.moving, reference);
    }
    return moving.over(kMovingSamples);
}

nlohmann::json run_config(const Config& c, FrameDispatcher& farm, const Scene& scene, const BenchArgs& a,
                          const Rgb8Image& reference, std::uint64_t& next_id, Snapshots& shots) {
    farm.set_normalise_rank_speed(c.rank_speed);
    LiveFrames live(farm, c.live);
    Encoder encoder(c.pipeline);
    ViewRequest request = session_view(scene, a);
    const double base_yaw = request.pose.yaw_deg;
    int moved = 0;
    const auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
    LiveFrame last;
    // Warm-up (not counted): the frame-time target settles, the PBT learns the view.
    // At least 10 frames: from full scale the target needs about 5 to reach the smallest scale.
    for (const auto warm = Clock::now(); moved < 10 || since(warm) < a.warmup_seconds;) {
        request.frame_id = next_id++;
        request.pose.yaw_deg = base_yaw + 0.5 * (moved % 2 == 0 ? 1 : -1) * (1 + moved % 7);
        last = live.render(request);
        encoder.submit(last.image);
        ++moved;
    }
    encoder.finish();
    moved = 0;
    ServedLog served_log;
    const auto start = Clock::now();
    while (moved < 5 || since(start) < a.move_seconds) {  // 5 frames at least, however slow
        request.frame_id = next_id++;
        request.pose.yaw_deg = base_yaw + 0.5 * (moved % 2 == 0 ? 1 : -1) * (1 + moved % 7);
        last = live.render(request);
        encoder.submit(last.image);
        served_log.add(last);
        ++moved;
    }
    encoder.finish();
    const double move_fps = moved / since(start);
    const FrameQuality moving = moving_frame_quality(live, request, base_yaw, reference, next_id, shots);
    const double moving_psnr = moving.psnr_db;
    const nlohmann::json served_summary = served_log.summary();
    nlohmann::json curve = nlohmann::json::array();
    double served = 0.0, to38 = -1.0;
    int still_frames = 0;
    while (served < a.still_seconds) {
        const auto t0 = Clock::now();
        request.frame_id = next_id++;
        last = live.render(request);
        encoder.submit(last.image);
        served += since(t0);
        ++still_frames;
        const double p = psnr(upsample(last.image, reference.size), reference);
        if (to38 < 0 && p >= 38.0) to38 = served;
        curve.push_back({{"seconds", served},
                         {"psnr_db", p},
                         {"samples", last.samples},
                         {"frame_seconds", last.seconds},
                         {"render_phase_seconds", last.stats.render_phase_seconds},
                         {"rank_render_seconds", last.stats.rank_render_seconds},
                         {"denoise_seconds", last.denoise_seconds}});
    }
    encoder.finish();
    shots.still = upsample(last.image, reference.size);
    std::printf("| %-34s | %7.2f | %4.2f (%4.2f) | %4.1f | %4.2f | %6.2f | %5.3f | %5.3f | %6.2f | %s | %4d |\n",
                c.name.c_str(), move_fps, served_summary["scale_mean"].get<double>(),
                served_summary["scale_min"].get<double>(), served_summary["spp_mean"].get<double>(),
                served_summary["bounces_mean"].get<double>(), moving_psnr, moving.ssim, moving.gmsd,
                curve.back()["psnr_db"].get<double>(), to38 < 0 ? "  never" : fmt::format("{:7.2f}", to38).c_str(),
                last.samples);
    std::fflush(stdout);
    return {{"config", c.name},
            {"key", c.key},
            {"move_frames_per_second", move_fps},
            {"moving_frame_psnr_db", moving_psnr},
            {"moving_frame", moving.json()},
            {"moving_served", served_summary},
            {"moving_frames", served_log.frames},
            {"still_curve", curve},
            {"still_seconds_to_38db", to38},
            {"still_frames", still_frames}};
}

struct Reference {
    Rgb8Image image;
    double floor_psnr_db = 0.0;  // PSNR between the two independent halves
};

// The mean of two independent halves in linear light, tone-mapped as the farm does.
Reference render_reference(FrameDispatcher& farm, const Scene& scene, const BenchArgs& a, std::uint64_t id) {
    ViewRequest v = session_view(scene, a);
    RgbFloatImage half[2];
    Rgb8Image half8[2];
    // Each half in passes of at most 16 spp (distinct RNG keys: rng.h keys on seed and frame_id), so
    // that no frame outlasts the farm's rank deadline; the spp-weighted mean is one estimate.
    const int half_spp = std::max(1, a.reference_spp / 2);
    for (int h = 0; h < 2; ++h) {
        std::uint64_t frame_id = id + std::uint64_t(h) * 1000003u;
        for (int done = 0; done < half_spp;) {
            v.quality.spp = std::min(16, half_spp - done);
            v.frame_id = frame_id++;
            const RgbFloatImage pass = farm.render(v, 999, PackedPixels::linear).radiance;
            if (done == 0) half[h] = RgbFloatImage(pass.size, 0.0f);
            const float w = float(v.quality.spp) / float(half_spp);
            for (std::size_t i = 0; i < pass.pixels.size(); ++i) half[h].pixels[i] += w * pass.pixels[i];
            done += v.quality.spp;
        }
        half8[h] = Rgb8Image(half[h].size);
        to_srgb8(half[h], PixelRect::whole(half[h].size), farm.settings().exposure, half8[h], farm.settings().tone_map);
    }
    RgbFloatImage mean = half[0];
    for (std::size_t i = 0; i < mean.pixels.size(); ++i)
        mean.pixels[i] = 0.5f * (half[0].pixels[i] + half[1].pixels[i]);
    Reference r;
    r.image = Rgb8Image(mean.size);
    to_srgb8(mean, PixelRect::whole(mean.size), farm.settings().exposure, r.image, farm.settings().tone_map);
    r.floor_psnr_db = psnr(half8[0], half8[1]);
    return r;
}

// Two rows: a moving frame as rendered (at its own size, top left, on black) | the same upsampled
// to full size as the kiosk shows it; the still view after --still-seconds | the reference.
void write_side_by_side(const std::string& path, const Snapshots& shots, const Rgb8Image& reference) {
    const ImageSize one = reference.size;
    Rgb8Image out({2 * one.width, 2 * one.height}, 0);
    const Rgb8Image* panels[4] = {&shots.moving_rendered, &shots.moving, &shots.still, &reference};
    for (int p = 0; p < 4; ++p) {
        const Rgb8Image& im = *panels[p];
        const int w = std::min(im.size.width, one.width), h = std::min(im.size.height, one.height);
        for (int y = 0; y < h; ++y)
            std::copy_n(im.at(0, y), 3 * w, out.at((p % 2) * one.width, (p / 2) * one.height + y));
    }
    write_png(path, out);
}

// Today's renderer at full resolution and 1 spp (no scheduling, no denoiser) at the reference's
// pose: the moving frames' quality baseline, measured in the same run, and its time per frame.
nlohmann::json full_resolution_baseline(FrameDispatcher& farm, const Scene& scene, const BenchArgs& a,
                                        const Rgb8Image& reference, std::uint64_t& next_id) {
    ViewRequest v = session_view(scene, a);
    v.quality.spp = 1;
    v.quality.resolution_scale = 1.0;
    FrameQuality sum;
    const auto t0 = Clock::now();
    double seconds = 0;
    for (int k = 0; k < kMovingSamples; ++k) {
        v.frame_id = next_id++;
        const auto f0 = Clock::now();
        const Rgb8Image image = farm.render(v, 998, PackedPixels::srgb8).image;
        seconds += std::chrono::duration<double>(Clock::now() - f0).count();
        sum += frame_quality(image, reference);
    }
    const FrameQuality q = sum.over(kMovingSamples);
    std::printf(
        "baseline: full resolution, 1 spp, %d bounces, no denoiser: %.1f ms/frame, PSNR %.2f dB, SSIM %.3f, "
        "GMSD %.3f (mean of %d frames, %.1f s)\n",
        v.quality.max_bounces, 1e3 * seconds / kMovingSamples, q.psnr_db, q.ssim, q.gmsd, kMovingSamples,
        std::chrono::duration<double>(Clock::now() - t0).count());
    nlohmann::json j = q.json();
    j["seconds_per_frame"] = seconds / kMovingSamples;
    j["bounces"] = v.quality.max_bounces;
    return j;
}

// Ratios of configurations measured in this run.
void print_ratios(const std::map<std::string, std::pair<double, double>>& figures) {
    const auto today = figures.find("today"), all = figures.find("all"), denoise = figures.find("denoise");
    if (today != figures.end() && all != figures.end() && today->second.first > 0 && all->second.first > 0)
        std::printf("\nratio frames/s all new parts / none = %.2f\n", all->second.first / today->second.first);
    if (all != figures.end() && denoise != figures.end() && all->second.first > 0) {
        std::printf("ratio frames/s denoiser on / off = %.2f; moving frame PSNR denoiser on - off = %+.2f dB\n",
                    denoise->second.first / all->second.first, denoise->second.second - all->second.second);
    }
    const auto cache = figures.find("cache");
    if (denoise != figures.end() && cache != figures.end() && denoise->second.first > 0) {
        std::printf(
            "ratio frames/s radiance cache on / off (both denoised) = %.2f; moving frame PSNR on - off = %+.2f dB\n",
            cache->second.first / denoise->second.first, cache->second.second - denoise->second.second);
    }
    const auto temporal = figures.find("temporal");
    if (cache != figures.end() && temporal != figures.end() && cache->second.first > 0) {
        std::printf("ratio frames/s temporal on / off (both cached) = %.2f; moving frame PSNR on - off = %+.2f dB\n",
                    temporal->second.first / cache->second.first, temporal->second.second - cache->second.second);
    }
    if (today != figures.end() && denoise != figures.end() && today->second.first > 0) {
        std::printf("ratio frames/s all + denoiser / none = %.2f; moving frame PSNR all + denoiser - none = %+.2f dB\n",
                    denoise->second.first / today->second.first, denoise->second.second - today->second.second);
    }
}

int admin(FrameDispatcher& farm, const Scene& scene, const BenchArgs& a) {
    std::uint64_t next_id = 1;
    const auto t0 = Clock::now();
    const Reference ref = render_reference(farm, scene, a, 1u << 30);
    const Rgb8Image& reference = ref.image;
    std::printf(
        "reference: %dx%d at %d spp in %.1f s (two halves %.2f dB apart: PSNR above ~%.0f dB is not "
        "measurable); %d render ranks; frame-time target %.1f ms\n\n",
        a.width, a.height, a.reference_spp, std::chrono::duration<double>(Clock::now() - t0).count(), ref.floor_psnr_db,
        ref.floor_psnr_db + 6.0, farm.render_ranks(), a.frame_time_ms);
    const nlohmann::json baseline = full_resolution_baseline(farm, scene, a, reference, next_id);
    std::printf("\n| %-34s | %7s | %11s | %4s | %4s | %6s | %5s | %5s | %6s | %7s | %4s |\n", "parts on", "move/s",
                "scale (min)", "spp", "bnc", "dB mov", "SSIM", "GMSD", "dB 5s", "s to 38", "spp");
    std::printf("|%s|%s|%s|%s|%s|%s|%s|%s|%s|%s|%s|\n", std::string(36, '-').c_str(), std::string(9, '-').c_str(),
                std::string(13, '-').c_str(), std::string(6, '-').c_str(), std::string(6, '-').c_str(),
                std::string(8, '-').c_str(), std::string(7, '-').c_str(), std::string(7, '-').c_str(),
                std::string(8, '-').c_str(), std::string(9, '-').c_str(), std::string(6, '-').c_str());
    nlohmann::json results = nlohmann::json::array();
    std::map<std::string, std::pair<double, double>> figures;  // key -> (moving frames/s, moving PSNR)
    const std::vector<Config> chosen = configs(a);
    const auto has = [&](const char* key) {
        return std::any_of(chosen.begin(), chosen.end(), [&](const Config& c) { return c.key == key; });
    };
    const std::string pictured = has("sparse")                    ? "sparse"
                                 : has("sparse-spatial-variance") ? "sparse-spatial-variance"
                                 : has("cache")                   ? "cache"
                                 : has("temporal")                ? "temporal"
                                 : has("denoise")                 ? "denoise"
                                                                  : "all";
    for (const Config& c : chosen) {
        Snapshots shots;
        results.push_back(run_config(c, farm, scene, a, reference, next_id, shots));
        figures[c.key] = {results.back()["move_frames_per_second"].get<double>(),
                          results.back()["moving_frame_psnr_db"].get<double>()};
        if (c.key == pictured && !a.side_by_side.empty()) write_side_by_side(a.side_by_side, shots, reference);
    }
    print_ratios(figures);
    if (!a.json.empty()) {
        std::ofstream(a.json) << nlohmann::json{
            {"width", a.width},
            {"height", a.height},
            {"render_ranks", farm.render_ranks()},
            {"frame_time_ms", a.frame_time_ms},
            {"reference_spp", a.reference_spp},
            {"reference_floor_psnr_db", ref.floor_psnr_db},
            {"still_seconds", a.still_seconds},
            {"quality", a.quality.empty() ? "request defaults" : a.quality},
            {"denoise_max_spp", a.denoise_max_spp},
            {"denoise_iterations", a.denoise_iterations},
            {"shading_one_in", a.shading_one_in},
            {"baseline_full_resolution_1spp", baseline},
            {"configs", results}}.dump(2);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    MpiSession mpi(&argc, &argv);
    spdlog::set_level(spdlog::level::warn);
    CLI::App app{"mogao_bench_serve: serve mode's live scheduling, each part on and off, in one run"};
    FarmSetup setup;
    setup.scene_file = "scenes/grotto.json";
    BenchArgs a;
    std::string scans;
    app.add_option("--scene", setup.scene_file, "Scene file");
    app.add_option("--scans", scans, "Folder of the real scans");
    app.add_option("--width", a.width)->check(CLI::Range(16, 16384));
    app.add_option("--height", a.height)->check(CLI::Range(16, 16384));
    app.add_option("--warmup-seconds", a.warmup_seconds, "Moving frames before the count starts")
        ->check(CLI::Range(0.0, 600.0));
    app.add_option("--move-seconds", a.move_seconds)->check(CLI::Range(0.1, 600.0));
    app.add_option("--still-seconds", a.still_seconds)->check(CLI::Range(0.1, 600.0));
    app.add_option("--frame-time-ms", a.frame_time_ms)->check(CLI::Range(1.0, 10000.0));
    app.add_option("--reference-spp", a.reference_spp, "Reference samples per pixel (two halves)")
        ->check(CLI::Range(2, 8192));
    app.add_option("--configs", a.configs,
                   "today, all, denoise, denoise-floor-0.2, cache, temporal, sparse, sparse-all-levels, "
                   "sparse-spatial-variance, cache-second-pass-1spp, cache-first-pass-1spp, no-progressive, no-target, "
                   "no-pipeline, "
                   "no-rank-speed, no-rate-aim")
        ->delimiter(',')
        ->check(CLI::IsMember({"today", "all", "denoise", "denoise-floor-0.2", "cache", "temporal", "sparse",
                               "sparse-all-levels", "sparse-spatial-variance", "cache-second-pass-1spp",
                               "cache-first-pass-1spp", "no-progressive", "no-target", "no-pipeline", "no-rank-speed",
                               "no-rate-aim"}));
    app.add_option("--quality", a.quality,
                   "Preset whose request quality every request uses (" + quality_preset_names() +
                       "); default: the request's defaults")
        ->check([](const std::string& name) {
            return quality_preset(name) ? std::string()
                                        : "unknown preset '" + name + "' (known: " + quality_preset_names() + ")";
        });
    app.add_option("--denoise-max-spp", a.denoise_max_spp, "denoise configuration: filter frames up to this spp")
        ->check(CLI::Range(1, 1 << 20));
    app.add_option("--denoise-iterations", a.denoise_iterations, "denoise configuration: a-trous levels")
        ->check(CLI::Range(0, AtrousParams::kMaxIterations));
    app.add_option("--shading-one-in", a.shading_one_in, "sparse configuration: moving frames shade 1 pixel in N")
        ->check(CLI::Range(1, 16));
    app.add_flag("--jitter-cached-one-spp", setup.jitter_cached_one_spp,
                 "Moving frames from the radiance cache jittered, their guides from a guide pass (as before)");
    app.add_option("--json", a.json, "Write every figure (and the curves) as JSON");
    app.add_option("--side-by-side", a.side_by_side,
                   "PNG: moving frame | still view after --still-seconds | reference");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return mpi.is_admin() ? app.exit(e) : 2;
    }
    setup.scene_options.scans_dir = scans;
    // A throughput benchmark on a shared machine: a rank stalled by the load must not abort the run;
    // the farm's own liveness limit (2 s of silence) is for hung ranks (farm_rank_lost_test covers it).
    setup.dispatch.rank_deadline_s = 300.0;
    const std::filesystem::path scans_dir = resolve_scans_dir(setup.scene_file, setup.scene_options);
    std::ifstream scene_text(setup.scene_file);
    const std::string text((std::istreambuf_iterator<char>(scene_text)), std::istreambuf_iterator<char>());
    if (text.find("{scans}") != std::string::npos && !std::filesystem::exists(scans_dir)) {
        if (mpi.is_admin()) std::printf("SKIP: real scans not found at %s\n", scans_dir.c_str());
        return 77;
    }
    return run_farm(mpi, setup,
                    [&](FrameDispatcher& farm, const Scene& scene, RunInfo&) { return admin(farm, scene, a); });
}
