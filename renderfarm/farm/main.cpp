// SPDX-License-Identifier: Apache-2.0
// mogao-farm: the render farm's command line. This file is the one place where the farm's stages
// are wired: scene (load) -> schedule (PBT) -> trace (Embree) -> encode (TurboJPEG), under MPI, and
// for live tours -> link (gRPC + mutual TLS over IPv6).
//
//   mpirun -n 3 mogao-farm render --scene scenes/grotto.json --frames 60 --out out/tour
//   mpirun -n 3 mogao-farm serve --scene scenes/grotto.json --listen [::]:7443 --tls-dir /etc/mogao/pki --name farm
//   mogao-farm pki init-ca --dir /etc/mogao/pki        (no MPI; see docs/link.md)
//   mogao-farm health                                  (no MPI; the launcher's per-host check)
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "common/program_cli.h"
#include "common/quality_preset.h"
#include "common/request_limits.h"
#include "renderfarm/farm/farm.h"
#include "renderfarm/farm/mpi_session.h"
#include "renderfarm/farm/path_tour.h"
#include "renderfarm/farm/serve.h"
#include "renderfarm/farm/view_policy_file.h"
#include "renderfarm/link/pki.h"
#include "renderfarm/link/tls_material.h"

namespace {

namespace L = mogao::request_limits;

struct CameraFlags {
    std::string kind = "cylinder";
    double fov_deg = 60.0;
    double radius = 3.0, arc = 150.0, bottom = 0.2, top = 2.8, eye_height = 1.6;
};

// Flags every farm command shares: the scene and how frames are split over the ranks.
void add_farm_flags(CLI::App& command, mogao::FarmSetup& setup, std::string& scans) {
    command.add_option("--scene", setup.scene_file, "Scene file (JSON, docs/scene-format.md)")
        ->required()
        ->check(CLI::ExistingFile);
    command.add_option("--scans", scans,
                       "Folder of the real scans (default: $MOGAO_SCANS_DIR or ../shared/data/scans)");
    command.add_option("--balance", setup.dispatch.balancer, "pbt | equal | roundrobin")
        ->check(CLI::IsMember({"pbt", "equal", "roundrobin"}));
    command.add_option("--snap-px", setup.dispatch.snap, "PBT/equal split snap in pixels")
        ->check(CLI::IsMember({4, 8, 16, 32}));
    command.add_option("--rr-tile-px", setup.dispatch.roundrobin_tile, "Round-robin tile size in pixels")
        ->check(CLI::Range(8, 1024));
    command
        .add_option("--threads", setup.dispatch.threads,
                    "Render threads per render rank (0 = this host's CPUs shared among its render ranks, the same "
                    "on every rank: render_threads.h)")
        ->check(CLI::Range(0, 256));
    command
        .add_option(
            "--rank-deadline-s", setup.dispatch.rank_deadline_s,
            "Most seconds a render rank that owes a frame may stay silent (rendering ranks report their "
            "progress every 0.1 s, however long the frame takes); a silent rank is taken as lost and the MPI "
            "job is aborted (exit 3) so that systemd restarts the farm over the hosts that answer; 4 times this when "
            "every rank that owes a frame is silent at once, the stall of a shared machine (0 = wait forever)")
        ->check(CLI::Range(0.0, 86400.0));
    command.add_option("--lost-ranks-file", setup.lost_ranks_file,
                       "Where the admin writes the ranks it took for lost (one per line) before it aborts the job; "
                       "mogao-farm-launch passes it and reads it at the restart (docs/services.md)");
    command.add_flag("--rank-speed,!--no-rank-speed", setup.dispatch.normalise_rank_speed,
                     "Normalise each rank's tile times by its measured speed before the PBT (default; --no-rank-speed: "
                     "raw wall time)");
}

// Live frame scheduling of serve mode (docs/services.md, live_frames.h).
void add_live_flags(CLI::App& serve, mogao::ServeOptions& options, double& frame_time_ms) {
    auto& live = options.live;
    serve
        .add_option("--frame-time-ms", frame_time_ms,
                    "Frame-time target per session in ms: resolution scale and spp of moving views are chosen to "
                    "meet it (0 = render each request as asked)")
        ->check(CLI::Range(0.0, 10000.0));
    serve
        .add_option("--min-scale", live.controller.min_scale,
                    "Floor of the resolution scale the frame-time target may pick; below it, it lowers the bounces")
        ->check(CLI::Range(0.01, 1.0));
    serve.add_option("--min-bounces", live.controller.min_bounces, "Fewest bounces the frame-time target may pick")
        ->check(CLI::Range(L::kMaxBounces.min, L::kMaxBounces.max));
    serve.add_option("--max-spp", live.controller.max_spp, "Largest spp the frame-time target may pick")
        ->check(CLI::Range(L::kSpp.min, L::kSpp.max));
    serve.add_flag("--progressive,!--no-progressive", live.progressive,
                   "Refine still views over successive requests (frames then differ from a lone render of the request; "
                   "default off: every request alone)");
    serve.add_option("--converged-spp", live.converged_spp, "Samples at which a still view stops refining")
        ->check(CLI::Range(1, 1 << 20));
    serve.add_flag(
        "--denoise,!--no-denoise", live.denoise,
        "Filter frames of few samples (moving views, a still view's first passes) with the a-trous "
        "denoiser; the ranks trace its guides (default off; the interactive and balanced presets turn it on)");
    serve
        .add_option(
            "--denoise-max-spp", live.denoise_max_spp,
            "Largest samples per pixel of a frame still filtered (256; a still view by the noise its passes measure)")
        ->check(CLI::Range(1, 1 << 20));
    serve.add_flag("--radiance-cache,!--no-radiance-cache", live.radiance_cache,
                   "Trace moving frames with the render ranks' radiance cache: the lights per pixel, the rest from "
                   "a world-space cache that every frame trains (biased, cheaper; still views refine without it; "
                   "default off; the interactive and balanced presets turn it on)");
    serve.add_flag("--temporal,!--no-temporal", live.temporal,
                   "Blend each filtered moving frame with the session's earlier frames, reprojected by depth, before "
                   "the denoiser (default: on whenever the denoiser is)");
    serve
        .add_option("--shading-one-in", live.shading_one_in,
                    "With the radiance cache and temporal accumulation: a moving frame shades a sparse one-in-N "
                    "pattern that moves every frame and takes the rest from the reprojected history (default 4; "
                    "1 shades everything)")
        ->check(CLI::Range(1, 16));
    serve.add_flag(
        "--share-frame-time,!--no-share-frame-time", live.share_frame_time,
        "Share the frame-time target among the sessions served in the last 2 s: with N appliances each "
        "frame aims at the target / N and a dearer request is degraded to that share, so each keeps "
        "its frame rate and latency with fewer pixels (default; --no-share-frame-time: each frame aims at the "
        "whole target, sessions in turn)");
    serve.add_flag("--follow-request-pace,!--no-follow-request-pace", live.follow_request_pace,
                   "A session whose requests come less often than the frame-time target has its moving frames take "
                   "0.85 of its request period (at most twice the target) while the farm waits for its requests, "
                   "instead of leaving the farm idle (default off; the interactive and balanced presets turn it on)");
    serve.add_flag("--per-session-cost-maps,!--shared-cost-map", live.per_session_maps,
                   "One PBT cost map per session (default; --shared-cost-map: one for all)");
    serve.add_flag("--pipeline,!--no-pipeline", options.pipeline,
                   "Encode off the main thread (default; --no-pipeline: encode before taking the next request)");
}

void add_render_flags(CLI::App& render, mogao::PathTour& job, CameraFlags& camera) {
    auto& q = job.view_template.quality;
    render.add_option("--frames", job.frames, "Number of frames of the camera path")->check(CLI::Range(1, 1000000));
    render.add_option("--path", job.path, mogao::cli::kPathHelp);
    render
        .add_option("--out", job.out_dir,
                    "Output folder for frame-NNNN.jpg, stats.json, tile-costs.json, contact-sheet.png")
        ->required();
    render.add_option("--width", job.view_template.size.width, "Image width in pixels")
        ->check(CLI::Range(16, L::kImageSide.max));
    render.add_option("--height", job.view_template.size.height, "Image height in pixels")
        ->check(CLI::Range(16, L::kImageSide.max));
    render.add_option("--projection", camera.kind, "cylinder (the projection screen's content) | pinhole")
        ->check(CLI::IsMember({"cylinder", "pinhole"}));
    render.add_option("--fov-deg", camera.fov_deg, "Pinhole vertical field of view, degrees")
        ->check(CLI::Range(1.0, 179.0));
    render.add_option("--screen-radius-m", camera.radius, "Cylinder screen radius, metres")
        ->check(CLI::Range(0.1, 1000.0));
    render.add_option("--screen-arc-deg", camera.arc, "Cylinder screen arc, degrees")->check(CLI::Range(1.0, 360.0));
    render.add_option("--screen-bottom-m", camera.bottom, "Cylinder screen bottom edge, metres above the floor");
    render.add_option("--screen-top-m", camera.top, "Cylinder screen top edge, metres above the floor");
    render.add_option("--spp", q.spp, "Samples per pixel")->check(CLI::Range(L::kSpp.min, L::kSpp.max));
    render.add_option("--bounces", q.max_bounces, "Path-tracing bounces (0 = direct light only)")
        ->check(CLI::Range(L::kMaxBounces.min, L::kMaxBounces.max));
    render.add_option("--ao", q.ao_samples, "Ambient-occlusion rays for the environment light (0 = unoccluded)")
        ->check(CLI::Range(L::kAoSamples.min, L::kAoSamples.max));
    render.add_option("--area-samples", q.area_light_samples, "Shadow rays per area light per sample")
        ->check(CLI::Range(L::kAreaLightSamples.min, L::kAreaLightSamples.max));
    render.add_option("--resolution-scale", q.resolution_scale, "Resolution scale of the frames, (0, 1]")
        ->check(CLI::Range(0.01, 1.0));
    render.add_option("--jpeg-quality", q.jpeg_quality, "TurboJPEG quality 1..100")
        ->check(CLI::Range(L::kJpegQuality.min, L::kJpegQuality.max));
    render.add_option("--seed", job.view_template.seed, "Sampling seed (same seed, same image)");
    render.add_option(
        "--first-frame-id", job.first_frame_id,
        "frame_id of the first frame (sampling depends on seed and frame_id; a live frame's is its request id)");
    render.add_flag("--save-raw", job.save_raw, "Also write lossless frame-NNNN.ppm");
    render.add_option("--contact-sheet", job.contact_sheet_frames, "Frames on the contact sheet (0 = none)")
        ->check(CLI::Range(0, 64));
}

// Which views appliances may have (view_policy.h).
void add_view_policy_flags(CLI::App& serve, mogao::ViewPolicy& policy, std::vector<double>& screen,
                           std::filesystem::path& policy_file) {
    serve.add_flag("--visitable-area,!--no-visitable-area", policy.visitable_area,
                   "Move each requested eye into the scene's viewer.visitable area (default, when the scene has one)");
    serve
        .add_option("--view-screen", screen,
                    "The appliances' screen RADIUS_M,ARC_DEG,BOTTOM_M,TOP_M[,EYE_HEIGHT_M]: cylinder requests "
                    "get its shape and at most its arc plus the guard band, pinhole requests its camera")
        ->delimiter(',')
        ->expected(4, 5);
    serve
        .add_option("--view-max-guard-deg", policy.max_guard_deg,
                    "Arc allowed beyond the screen's on each side (the kiosk's late-warp guard band)")
        ->check(CLI::Range(0.0, 179.999));
    serve.add_option("--view-policy", policy_file,
                     "JSON file of per-appliance view policies (screen, max_size, ...; docs/services.md); listed "
                     "certificates get their entry, the others the --view-* flags (read on the admin host only)");
    serve
        .add_option("--view-min-fov-deg", policy.min_fov_deg,
                    "Without --view-screen: narrower pinhole requests are widened to this (0 = off)")
        ->check(CLI::Range(0.0, 179.0));
}

// Who may connect and how much one request may cost (docs/link.md, request_policy.h).
void add_link_flags(CLI::App& serve, mogao::ServeOptions& serve_options, std::filesystem::path& tls_dir,
                    std::string& farm_name) {
    serve.add_option("--listen", serve_options.link.listen, "IPv6 endpoint [addr]:port");
    serve
        .add_option("--tls-dir", tls_dir,
                    "TLS folder: ca.pem, farm-NAME.pem, farm-NAME.key, optional crl.pem; never ca.key (mogao-farm pki "
                    "export-farm); read on the admin host only, render hosts need none")
        ->required();
    serve.add_option("--name", farm_name, "Farm certificate name in --tls-dir");
    serve.add_option("--allow", serve_options.link.allowed_appliances,
                     "Only these appliance certificate names (default: any the CA issued)");
    serve.add_option(
        "--crl", serve_options.link.crl_path,
        "Revocation list (PEM CRL of the farm CA, re-read when it changes; default: --tls-dir/crl.pem if present)");
    serve.add_option("--max-sessions", serve_options.link.max_sessions, "Concurrent appliance sessions")
        ->check(CLI::Range(1, 256));
    serve
        .add_option("--max-sessions-per-appliance", serve_options.link.max_sessions_per_appliance,
                    "Concurrent sessions of one appliance certificate")
        ->check(CLI::Range(1, 256));
    mogao::ConnectionLimits& caps = serve_options.link.connections;
    serve
        .add_option("--max-connections", caps.max_connections,
                    "Open TCP connections in all (docs/link.md, \"Connection caps\")")
        ->check(CLI::Range(1, 65536));
    serve
        .add_option("--max-unauthenticated-connections", caps.max_unauthenticated,
                    "Open connections without an admitted session (TLS handshakes in progress included)")
        ->check(CLI::Range(1, 65536));
    serve
        .add_option("--max-unauthenticated-per-address", caps.max_unauthenticated_per_address,
                    "Of those, from one source address")
        ->check(CLI::Range(1, 65536));
    serve
        .add_option("--unauthenticated-max-age-s", caps.unauthenticated_max_age_s,
                    "A connection that opened no session is closed after this many seconds")
        ->check(CLI::Range(1.0, 3600.0));
    serve
        .add_option("--max-request-megapixels", serve_options.policy.max_megapixels,
                    "Megapixels rendered per request; a larger request is rendered at a lower resolution scale")
        ->check(CLI::Range(0.001, 268.5));
    serve
        .add_option("--max-request-gigarays", serve_options.policy.max_gigarays,
                    "Estimated rays per request, billions; a dearer request is degraded (spp, then light samples, "
                    "bounces, resolution scale)")
        ->check(CLI::Range(1e-6, 1e6));
    serve.add_option("--metrics-file", serve_options.metrics_file,
                     "Prometheus textfile to rewrite every second (node_exporter's textfile collector, e.g. "
                     "/var/lib/prometheus/node-exporter/mogao-farm.prom; docs/services.md)");
}

// --quality NAME: the preset's values for every knob not given explicitly on the command line.
void add_quality_flag(CLI::App& command, std::string& preset) {
    command
        .add_option(
            "--quality", preset,
            "Preset (" + mogao::quality_preset_names() + ", docs/quality.md); explicit flags override its values")
        ->check([](const std::string& name) {
            return mogao::quality_preset(name) != nullptr
                       ? std::string()
                       : "unknown preset '" + name + "' (known: " + mogao::quality_preset_names() + ")";
        });
}

void apply_render_preset(const CLI::App& render, const mogao::QualityPreset& p, mogao::Quality& q) {
    const auto unset = [&](const char* flag) { return render.count(flag) == 0; };
    if (unset("--spp")) q.spp = p.request.spp;
    if (unset("--bounces")) q.max_bounces = p.request.max_bounces;
    if (unset("--ao")) q.ao_samples = p.request.ao_samples;
    if (unset("--area-samples")) q.area_light_samples = p.request.area_light_samples;
    if (unset("--resolution-scale")) q.resolution_scale = p.request.resolution_scale;
    if (unset("--jpeg-quality")) q.jpeg_quality = p.request.jpeg_quality;
}

// Serve schedules what appliances ask for: the preset sets the scheduling, not the requests.
void apply_serve_preset(const CLI::App& serve, const mogao::QualityPreset& p, mogao::LiveOptions& live,
                        double& frame_time_ms) {
    const auto unset = [&](const char* flag) { return serve.count(flag) == 0; };
    if (unset("--frame-time-ms")) frame_time_ms = p.frame_time_ms;
    if (unset("--progressive") && unset("--no-progressive")) live.progressive = p.progressive;
    if (unset("--converged-spp")) live.converged_spp = p.converged_spp;
    if (unset("--denoise") && unset("--no-denoise")) live.denoise = p.denoise;
    if (unset("--radiance-cache") && unset("--no-radiance-cache")) live.radiance_cache = p.radiance_cache;
    if (unset("--follow-request-pace") && unset("--no-follow-request-pace"))
        live.follow_request_pace = p.follow_request_pace;
}

// `mogao-farm health`: what mogao-farm-launch runs on each render host (over the same rsh agent
// mpirun uses) before it starts the job. Reaching this line proves the host answers, the binary and
// every library it links (Embree, Open MPI, gRPC, OpenSSL) load there; MPI itself is not started.
int run_health() {
    char host[256] = {};
    if (gethostname(host, sizeof host - 1) != 0) std::snprintf(host, sizeof host, "?");
    std::printf("mogao-farm health: ok on %s, %u hardware threads\n", host, std::thread::hardware_concurrency());
    return 0;
}

// The admin's part of `serve` that reads files: the view policies and the link's TLS material.
// Returns what is wrong (naming the flag or file), or "" when all is well.
std::string prepare_admin_link(mogao::ServeOptions& serve_options, const std::filesystem::path& tls_dir,
                               const std::string& farm_name, const std::filesystem::path& view_policy_file) {
    try {
        serve_options.view_policy.validate();
    } catch (const std::invalid_argument& e) {
        return fmt::format("--view-screen / --view-*: {}", e.what());
    }
    if (!view_policy_file.empty()) {
        try {
            serve_options.appliance_view_policies =
                mogao::read_view_policies(view_policy_file, serve_options.view_policy).appliances;
        } catch (const std::exception& e) {
            return fmt::format("--view-policy: {}", e.what());
        }
    }
    try {
        serve_options.link.tls = mogao::load_farm_tls(tls_dir, farm_name);
        // Re-read while serving: the farm certificate is rotated by replacing the files.
        serve_options.link.tls_files = {mogao::ca_cert_path(tls_dir), mogao::farm_cert_path(tls_dir, farm_name),
                                        mogao::farm_key_path(tls_dir, farm_name)};
        if (serve_options.link.crl_path.empty() && std::filesystem::exists(mogao::crl_path(tls_dir))) {
            serve_options.link.crl_path = mogao::crl_path(tls_dir).string();
        }
    } catch (const std::exception& e) {
        return fmt::format("--tls-dir {}: {}", tls_dir.string(), e.what());
    }
    return "";
}

bool asks_for_help_or_version(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
        const std::string_view a = argv[i];
        if (a == "-h" || a == "--help" || a == "--version") return true;
    }
    return false;
}

// `render`: a camera path into numbered frames.
struct RenderCommand {
    CLI::App* app = nullptr;
    mogao::PathTour job;
    CameraFlags camera;
    std::string preset;
};

// `serve`: live tours for authenticated appliances.
struct ServeCommand {
    CLI::App* app = nullptr;
    mogao::ServeOptions options;
    std::filesystem::path tls_dir;
    std::string farm_name = "farm";
    std::string preset;
    double frame_time_ms = 0.0;
    double frame_budget_s = 1.0;
    std::vector<double> view_screen;
    std::filesystem::path view_policy_file;
};

void add_render_command(CLI::App& app, mogao::FarmSetup& setup, std::string& scans, RenderCommand& r) {
    r.app = app.add_subcommand("render", "Render a camera path headless into numbered JPEG frames");
    add_farm_flags(*r.app, setup, scans);
    add_render_flags(*r.app, r.job, r.camera);
    add_quality_flag(*r.app, r.preset);
}

void add_serve_command(CLI::App& app, mogao::FarmSetup& setup, std::string& scans, ServeCommand& s) {
    s.app = app.add_subcommand("serve", "Serve live tours to authenticated appliances over IPv6 (gRPC, mutual TLS)");
    add_farm_flags(*s.app, setup, scans);
    add_link_flags(*s.app, s.options, s.tls_dir, s.farm_name);
    // Off unless asked: a refined frame is not the lone render of its request that the kiosk's
    // end-to-end tests compare against.
    s.options.live.progressive = false;
    add_live_flags(*s.app, s.options, s.frame_time_ms);
    add_quality_flag(*s.app, s.preset);
    add_view_policy_flags(*s.app, s.options.view_policy, s.view_screen, s.view_policy_file);
    s.app
        ->add_option("--frame-budget-s", s.frame_budget_s,
                     "Seconds a frame may take: the rest of a frame still rendering then is rendered coarse, and a "
                     "session's next requests are degraded from what its frames cost (0 = no budget)")
        ->check(CLI::Range(0.0, 3600.0));
    mogao::cli::add_duration_flag(*s.app, s.options.duration_s);
}

// After the parse: the presets and what the flags imply.
void apply_flags(RenderCommand& r, ServeCommand& s) {
    if (!s.preset.empty())
        apply_serve_preset(*s.app, *mogao::quality_preset(s.preset), s.options.live, s.frame_time_ms);
    if (!r.preset.empty()) apply_render_preset(*r.app, *mogao::quality_preset(r.preset), r.job.view_template.quality);
    if (s.app->count("--temporal") == 0 && s.app->count("--no-temporal") == 0)
        s.options.live.temporal = s.options.live.denoise;
    s.options.live.frame_time_s = s.frame_time_ms / 1e3;
    const std::vector<double>& v = s.view_screen;
    if (!v.empty()) {
        s.options.view_policy.screen =
            mogao::CylinderScreen{v[0], v[1], v[2], v[3], {0.0, v.size() > 4 ? v[4] : 1.6, 0.0}};
    }
}

int run_serve_command(mogao::MpiSession& mpi, mogao::FarmSetup& setup, ServeCommand& s) {
    setup.dispatch.frame_budget_s = s.frame_budget_s;
    s.options.budget.frame_s = s.frame_budget_s;
    s.options.budget.share_min_scale = s.options.live.controller.min_scale;
    // Only the admin talks to appliances, so only the admin host holds the link's key, its
    // revocation list and the view policies (render hosts have no /etc/mogao/pki). Every rank
    // then agrees: one that returned alone would wait in MPI_Finalize while the others wait
    // for it in their first collective (the two-host farm hung so).
    std::string error =
        mpi.is_admin() ? prepare_admin_link(s.options, s.tls_dir, s.farm_name, s.view_policy_file) : std::string();
    // Listening before the scene loads: appliances reconnect while it loads (serve.h, ServeLink).
    std::optional<mogao::ServeLink> link;
    if (error.empty() && mpi.is_admin()) {
        try {
            link.emplace(s.options);
        } catch (const std::exception& e) {
            error = fmt::format("--listen {}: {}", s.options.link.listen, e.what());
        }
    }
    if (!error.empty()) spdlog::error("{}", error);
    if (!mpi.all(error.empty())) return 2;
    return mogao::run_farm(mpi, setup,
                           [&](mogao::FrameDispatcher& farm, const mogao::Scene& scene, mogao::RunInfo& run) {
                               return mogao::run_serve(s.options, *link, farm, scene, run);
                           });
}

int run_render_command(mogao::MpiSession& mpi, mogao::FarmSetup& setup, RenderCommand& r) {
    const CameraFlags& camera = r.camera;
    if (camera.kind == "pinhole") {
        r.job.view_template.camera = mogao::PinholeCamera{camera.fov_deg};
    } else {
        if (!(camera.top > camera.bottom)) {
            if (mpi.is_admin())
                spdlog::error("--screen-top-m ({}) must be above --screen-bottom-m ({})", camera.top, camera.bottom);
            return 2;
        }
        r.job.view_template.camera =
            mogao::CylinderScreen{camera.radius, camera.arc, camera.bottom, camera.top, {0.0, camera.eye_height, 0.0}};
    }
    return mogao::run_farm(mpi, setup,
                           [&](mogao::FrameDispatcher& farm, const mogao::Scene& scene, mogao::RunInfo& run) {
                               return mogao::run_path_tour(r.job, farm, scene, run);
                           });
}

}  // namespace

int main(int argc, char** argv) {
    // The PKI needs no farm: handle it before MPI starts.
    if (argc >= 2 && std::string_view(argv[1]) == "pki") return mogao::run_pki_command(argc - 1, argv + 1);
    if (argc == 2 && std::string_view(argv[1]) == "health") return run_health();
    CLI::App app{"mogao-farm: the mogao render farm (Embree ray tracing, sort-first PBT over MPI ranks, JPEG frames)"};
    mogao::cli::prepare(app, "mogao-farm");
    app.require_subcommand(1);
    mogao::FarmSetup setup;
    std::string scans;
    RenderCommand render;
    add_render_command(app, setup, scans, render);
    ServeCommand serve;
    add_serve_command(app, setup, scans, serve);
    // Listed in --help; handled at the top of main, before MPI starts.
    app.add_subcommand(
           "pki", "The link's PKI: CA, farm and appliance certificates, revocation (no MPI; mogao-farm pki --help)")
        ->prefix_command();
    app.add_subcommand("health",
                       "Print ok and this host's hardware threads (no MPI; what mogao-farm-launch runs per host)");
    // --help and --version need no farm: answered before MPI starts (a singleton MPI_Init outside
    // mpirun takes seconds).
    if (asks_for_help_or_version(argc, argv)) return mogao::cli::parse(app, argc, argv).value_or(0);
    mogao::MpiSession mpi(&argc, &argv);
    auto logger = spdlog::stderr_color_mt("mogao-farm");
    spdlog::set_default_logger(logger);
    // journald-friendly: no timestamps of our own (the journal adds them), rank and level first.
    spdlog::set_pattern(fmt::format("mogao-farm[{}] %l: %v", mpi.rank()));
    if (!mpi.is_admin()) spdlog::set_level(spdlog::level::warn);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return mogao::cli::exit_status(app, e, /*quiet=*/!mpi.is_admin());  // 2 on every rank
    }
    setup.scene_options.scans_dir = scans;
    apply_flags(render, serve);
    if (serve.app->parsed()) return run_serve_command(mpi, setup, serve);
    return run_render_command(mpi, setup, render);
}
