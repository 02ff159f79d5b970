// SPDX-License-Identifier: Apache-2.0
// Live frame scheduling of serve mode: what the farm renders for each appliance session's request.
//
// Per session (ViewRequest::session, set by the link server):
//  - Progressive refinement: while the session asks for the same view (same_view(): pose, camera,
//    size and quality unchanged), each request renders one more pass at the request's full scale
//    with new random numbers (pass_frame_id) and the frame sent is the mean of all passes so far, in
//    linear float (progressive_accumulator.h). Any change starts over. The second pass takes
//    LiveOptions::still_second_pass_spp samples per pixel, later ones still_pass_spp (each pass's
//    samples at fresh sub-pixel positions, RendererOptions::jitter_one_spp, so the mean converges
//    to the pixel's area average). Once `converged_spp` samples are in, the mean is sent without
//    rendering.
//  - A frame-time target (schedule/frame_time_controller.h): while the view moves, the resolution
//    scale and spp of each frame are chosen to take `frame_time_s` (spp first, the scale down to
//    its floor, then the bounces); the appliance upsamples the smaller frame (its warp takes
//    content of any size). A still view is accumulated at the request's own scale and bounces. The controller also sees
//    the gap since the session's previous frame was handed back, and charges it when it is a hand-off (frames back to
//    back: the caller's encode and the next request), so that frames plus hand-offs meet the target
//    (frame_time_controller.h).
//  - Its own predicted cost map (FrameDispatcher stream = session), so sessions looking at
//    different places do not mislead each other's PBT.
//  - With `denoise`: every frame served with at most `denoise_max_spp` samples per pixel (moving
//    frames, a still view while it refines) is filtered by the edge-avoiding à-trous denoiser
//    (renderfarm/denoise/atrous_filter.h) in linear light before the display transform. A frame
//    of one pass is filtered by the noise the filter estimates spatially; a still view's
//    accumulation of two passes or more by the noise its passes measure
//    (ProgressiveAccumulator::variance_of_mean), so the filter does less as samples come in and
//    the view keeps improving. The first pass of each view asks the ranks for the guides too
//    (PackedPixels::linear_guided: albedo, normal, depth of each pixel centre's first hit, traced on
//    the ranks' own BVHs beside the tiles); later passes of the same view reuse them. The admin
//    filters the composited frame, so the served frame is the same for any split of the frame over
//    any number of ranks; the accumulation keeps the raw samples (never filtered ones). The
//    filter's time is part of LiveFrame::seconds, which the frame-time target observes, so the
//    target still holds with it (it shrinks the frame to pay for the filter). With `temporal`, a
//    filtered moving frame is first blended with the session's earlier frames, reprojected by
//    depth (temporal_accumulation.h; exact for a static scene, with disocclusion rejection): the
//    temporal half of SVGF before its spatial half. A still view's frames are never blended: its
//    first pass is already at full scale and unbiased, and the moving frames' history (smaller,
//    from the radiance cache) would outweigh it.
// A pass cut at the farm's frame budget (FrameStats::tiles_cut, frame_dispatcher.h) is sent alone
// and never accumulated: its coarse tiles would stay in the mean.
// Sessions are forgotten least-recently-used beyond `max_sessions`.
//
// Threads: main thread only (it drives the FrameDispatcher, MPI_THREAD_FUNNELED).
// Errors: what FrameDispatcher::render throws (std::invalid_argument for a bad view, FarmError);
// the session's state is left as it was (the failed frame is not accumulated).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>

#include "renderfarm/denoise/atrous_filter.h"
#include "renderfarm/denoise/temporal_accumulation.h"
#include "renderfarm/farm/frame_dispatcher.h"
#include "renderfarm/farm/progressive_accumulator.h"
#include "renderfarm/schedule/frame_time_controller.h"
#include "renderfarm/schedule/request_pace.h"

namespace mogao {

struct LiveOptions {
    bool progressive = true;   // accumulate still views
    int converged_spp = 1024;  // stop rendering a still view once it has this many samples
    // A still view's passes: the first takes still_first_pass_spp samples per pixel, the second
    // still_second_pass_spp, later ones still_pass_spp (fewer passes: less filtering, guides, display
    // and hand-off per sample, while a pass stays short enough for a visitor who moves on); never
    // fewer than the frame-time controller's choice. Each >= 1. On the grotto a first pass of two
    // samples, filtered, is past 38 dB where one sample is not, and sooner than one sample and a
    // second pass (the serve bench's cache-first-pass-1spp against cache, in one run); a second pass
    // of one sample was measured no sooner past 38 dB, with fewer samples later
    // (cache-second-pass-1spp).
    int still_first_pass_spp = 2;
    int still_second_pass_spp = 2;
    int still_pass_spp = 2;
    double frame_time_s = 0.0;  // per-session frame-time target, seconds; 0 = render requests as asked
    // Share the frame-time target among the sessions served in the last kActiveWindow: each
    // session's frames aim at frame_time_s / (active sessions), so that one round of every active
    // session's frame takes about frame_time_s. Each appliance then keeps its frame rate and
    // motion-to-photon latency as more appliances join, with fewer pixels (resolution first, then
    // bounces, as the controller degrades); off, each frame aims at frame_time_s and the round,
    // so every appliance's latency, grows with the number of appliances. The controller keeps its
    // floors (min_scale, min_bounces): past them the rate falls for everyone alike. The farm's
    // session budget also holds each frame to an equal turn (frame_share_seconds(),
    // session_budget.h): no longer than the target or the other active sessions' median recent
    // frame, whichever is longer, so a dear request is degraded instead of holding the others'
    // frames back, and an ordinary one is not shrunk below the floors when the farm is slow.
    bool share_frame_time = true;  // on by default: measured against round-robin (docs/reliability.md)
    // Follow the appliance's pace (renderfarm/schedule/request_pace.h): a session whose requests come less often
    // than one per frame-time target (a 10 Hz kiosk against a 15 frames/s target) leaves the farm idle between
    // frames. While the farm waits for its requests, its moving frames aim at pace_share of its request period
    // instead, never below the target and never above max_pace_factor times it: the frame takes the time the
    // appliance gives it, and the latency it adds stays bounded. Only a session served alone (no other in the
    // last kActiveWindow) follows its pace: with several, the farm is busy with the others between one's frames.
    bool follow_request_pace = false;  // the interactive and balanced presets turn it on
    double pace_share = 0.85;          // (0, 1)
    double max_pace_factor = 2.0;      // >= 1
    FrameTimeTarget controller;        // its other settings (target_seconds is taken from frame_time_s)
    bool per_session_maps = true;      // one PBT cost map per session; false = all share one (stream 0)
    std::size_t max_sessions = 64;
    bool denoise = false;       // filter frames of at most denoise_max_spp samples (see above)
    int denoise_max_spp = 256;  // >= 1; past it a still view is sent raw (its noise is below the filter's bias)
    AtrousParams denoise_params = default_denoise_params();  // threads 0 = every core of the admin
    // Moving frames read and train the render ranks' radiance caches (ViewRequest::radiance_cache,
    // renderfarm/trace/radiance_cache.h): much cheaper, biased; such a frame is shown alone, never
    // accumulated, so a still view still converges to the unbiased image.
    bool radiance_cache = false;
    // Frames the denoiser filters that are not a still view's accumulation (moving frames, a view's
    // first pass) are first blended with the session's earlier frames by reprojection
    // (renderfarm/denoise/temporal_accumulation.h): a moving view keeps most of its samples.
    bool temporal = false;
    TemporalParams temporal_params;
    // The à-trous levels ([0, 10], AtrousParams::iterations) for a frame blended with its history
    // (temporal): the blend already averages a few frames, so the filter needs fewer levels than
    // denoise_params.iterations, which every other filtered frame keeps. 1: moving frames closer to
    // the converged reference than with 3 (PSNR, SSIM and GMSD; the wider levels blur detail the
    // history keeps), at a larger scale; 0 measured closer still but leaves grain and isolated
    // bright pixels on the walls (the serve bench's sparse and sparse-all-levels configurations).
    int blended_denoise_iterations = 1;
    // A frame blended with its history gives the filter the history's temporal luminance variance
    // (TemporalHistory::luminance_variance, SVGF §4.2) where it holds enough frames; the 5x5 spatial
    // estimate runs only around the rest. false: the spatial estimate everywhere.
    bool temporal_variance = true;
    // With radiance_cache, denoise and temporal: a moving frame that has a history shades one pixel
    // in `shading_one_in` ([1, 16]; 1 shades all), on a pattern that moves every frame
    // (ViewRequest::shading_one_in; each pixel is shaded once in as many frames), and takes the
    // others from the reprojected history (temporal_accumulation.h): the ranks trace each frame's
    // camera rays and a fraction of its light. 4: as close to the reference as shading every pixel,
    // with more moving frames a second; 8 was no faster, 2 slower (docs/renderer.md, the serve
    // bench's temporal and sparse configurations).
    int shading_one_in = 4;
    // The scene's lights at a scene time (renderfarm/scene/scene.h, lighting_state; empty: static
    // lights). Every request is stamped with the scene time (ViewRequest::scene_time_s, from
    // scene_clock, or seconds since this LiveFrames was made); a session whose lights changed since
    // its previous frame starts its temporal history and its still view's accumulation anew (the
    // render ranks empty their radiance caches themselves: renderer.h).
    std::function<std::vector<float>(double)> lighting;
    std::function<double()> scene_clock;  // seconds, non-decreasing; tests set it

    // The filter's settings for served frames: AtrousParams' defaults (chosen at 1 spp) on every
    // core of the admin, which waits for the ranks meanwhile.
    [[nodiscard]] static AtrousParams default_denoise_params() {
        AtrousParams p;
        p.threads = 0;
        return p;
    }
};

struct LiveFrame {
    Rgb8Image image;                // what to encode and send: render_size(rendered)
    ViewRequest rendered;           // the view as traced: scale, spp and frame_id of the pass
    int samples = 0;                // samples per pixel in `image` (all accumulated passes)
    int passes = 1;                 // passes in `image`
    bool still = false;             // the request repeated the session's previous view (a still view)
    bool rendered_now = true;       // false: a converged still view, sent from the accumulation
    bool denoised = false;          // `image` is the filtered frame
    double seconds = 0.0;           // render + composite (+ accumulate, + denoise) on the admin, wall
    double denoise_seconds = 0.0;   // the filter's part of `seconds`
    double temporal_seconds = 0.0;  // ... of which the temporal accumulation's (temporal)
    double gap_seconds = 0.0;       // since the session's previous frame was handed back (0: its first)
    // With `temporal`, a moving frame's surface pixels and how many of them the previous frames
    // supplied by reprojection (temporal_accumulation.h); both 0 when the frame was not blended.
    TemporalStats temporal;
    FrameStats stats;
};

// Renders one frame: FrameDispatcher::render, or a stand-in in tests.
using FrameSource = std::function<DispatchedFrame(const ViewRequest&, std::uint64_t stream, PackedPixels)>;

class LiveFrames {
public:
    // Frames from `farm`, displayed with its exposure and tone map.
    LiveFrames(FrameDispatcher& farm, LiveOptions options);
    // Frames from `source`; accumulated radiance is displayed with `exposure` and `tone_map` (film.h).
    // Throws std::invalid_argument for bad options (naming the field; a bad denoise_params names
    // it as atrous_filter.h's validation does).
    LiveFrames(FrameSource source, LiveOptions options, float exposure, ToneMap tone_map);

    // Renders the frame answering `request` (validated by the renderer). Main thread only. Throws
    // std::runtime_error when the denoiser refuses the frame's guides (its message).
    LiveFrame render(const ViewRequest& request);

    [[nodiscard]] const LiveOptions& options() const { return options_; }
    // The seconds of the farm a frame of session `current` may take now (share_frame_time, with
    // other sessions served in the last kActiveWindow): the larger of frame_time_s and the median
    // of the other active sessions' recent frame times (an equal turn); 0 when not shared or alone.
    [[nodiscard]] double frame_share_seconds(std::uint64_t current) const;

private:
    struct Session {
        std::optional<ViewRequest> last_request;
        ProgressiveAccumulator accumulation;
        std::optional<FrameTimeController> controller;
        GuideBuffers guides;       // of the accumulated view (denoise), or of the last frame
        TemporalHistory temporal;  // earlier moving frames (LiveOptions::temporal)
        std::uint64_t last_used = 0;
        std::optional<std::chrono::steady_clock::time_point> handed_back;  // the previous render() returned
        double recent_seconds = 0.0;                 // rendered frames' seconds, exponentially weighted (0: none yet)
        RequestPace pace;                            // its requests' pace (follow_request_pace)
        std::optional<std::vector<float>> lighting;  // the lights' state of its previous frame
        std::uint64_t sparse_frames = 0;             // sparse frames asked for: the pattern's phase
    };
    Session& session(std::uint64_t id);
    // Sessions handed a frame within kActiveWindow before `now`, `current` counted even if new.
    [[nodiscard]] std::size_t active_sessions(std::uint64_t current, std::chrono::steady_clock::time_point now) const;
    // The frame-time target of session `s`'s next frame (share_frame_time, follow_request_pace), after noting
    // `request`'s pace and the farm's wait `gap_seconds` before it.
    [[nodiscard]] double paced_target(Session& s, const ViewRequest& request, double gap_seconds,
                                      std::chrono::steady_clock::time_point now) const;
    static constexpr std::chrono::seconds kActiveWindow{2};
    [[nodiscard]] bool is_still(const Session& s, const ViewRequest& request) const;
    [[nodiscard]] double scene_time_s() const;
    void follow_lighting(Session& s, double scene_time_s);
    [[nodiscard]] ViewRequest plan(Session& s, const ViewRequest& request, FrameChoice& choice) const;
    void plan_sparse(Session& s, ViewRequest& view) const;
    [[nodiscard]] Rgb8Image to_display(const RgbFloatImage& radiance) const;
    [[nodiscard]] bool accumulates(const LiveFrame& frame) const;
    void dispatch(Session& s, const ViewRequest& request, int spp, LiveFrame& frame, RgbFloatImage& radiance);
    void display(Session& s, const RgbFloatImage& radiance, LiveFrame& frame);

    FrameSource source_;
    LiveOptions options_;
    float exposure_;
    ToneMap tone_map_;
    std::map<std::uint64_t, Session> sessions_;
    std::uint64_t frames_ = 0;
    std::chrono::steady_clock::time_point created_ = std::chrono::steady_clock::now();  // scene time 0
    AtrousDenoiser denoiser_;  // scratch planes reused frame to frame
};

}  // namespace mogao
