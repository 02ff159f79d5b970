// SPDX-License-Identifier: Apache-2.0
// Frame-time target of a live session: how much to render next so a frame takes `target_seconds`.
//
// The knob is the frame's work w = resolution_scale^2 * spp (pixels traced times samples, relative
// to the full-size frame at 1 spp); render time is close to proportional to it. After each frame the
// controller moves w toward the work that would have met the target, as Equalizer's dynamic frame
// resize does (S. Eilemann et al., "Equalizer: A Scalable Parallel Rendering Framework", IEEE TVCG
// 15(3), 2009, sec. 5.3; Equalizer's DFR equaliser scales each axis by sqrt(target / measured)):
//     w' = w_used * clamp(target / measured, 1/max_step, max_step) ^ gain
// gain in (0, 1] damps the step (1 = jump to the prediction at once; the default 0.5 halves the
// log-error each frame, so a frame that took twice the target shrinks each axis by 2^(1/4)).
// measured = 0 (a frame too fast to time) counts as the largest step up. w is then clamped so that
// the scale stays in [min_scale, the request's own scale] with each side at least
// request_limits::kLinkImageSide.min pixels, and spp in [1, max_spp] (request_limits::kSpp).
// Samples go first, resolution last: shrinking w, spp (= round(w / scale^2)) falls to 1 at the
// request's full scale before the scale moves; then the scale falls, but never below `min_scale`
// (the floor, 0.5 by default: a visitor walking through the grotto sees blocks below it).
//
// Below the floor the frame is made cheaper by its path depth instead: the request's bounces b_r
// step down towards `min_bounces`, at the floor's scale and 1 spp. Its default, 1, keeps the first
// bounce: in the closed grotto 0 bounces is the largest error of all (docs/quality.md), and the
// serve benchmark (mogao_bench_serve --configs denoise,denoise-floor-0.2) measured a moving frame
// at 0 bounces about 7 dB below one at 1. A frame of b bounces is modelled as costing
// (1 + bounce_cost * b) times a direct-light-only one (docs/quality.md's bounce sweep of the grotto
// at 1 spp: 16, 57, 90, 121 ms for 0 to 3 bounces, about 2.5 times the direct-only cost per
// bounce), so the ladder's works are W_b = floor^2 * (1 + c b) / (1 + c b_r). Bounces are discrete
// and change the picture's brightness, so they are not chased by the damped step (which would flip
// between two depths every few frames when the target lies between them): once a frame's damped
// step would take w below W_{b_r}, the controller predicts each level's time from the measured one
// (seconds * W_b / w_used) and takes the deepest level whose prediction meets the
// aim, climbing back only when the prediction is within `climb_margin` of the aim (hysteresis,
// so that a model error of up to 1 / climb_margin never oscillates). The ladder's aim is
// target * (1 - headroom), without the jitter allowance G / A (which belongs to the damped loop
// and is inflated for a while by the descent from full scale), and the time of the frames at one
// level is smoothed (weight kLadderWeight per frame, restarted at each change of level) so that
// one slow frame does not drop a bounce. When even min_bounces misses the aim, the frame takes
// longer than the target: the floor holds, the rate falls.
//
// The rate served is frames over the SUM of their times, so it is the arithmetic mean frame time
// that must meet the target. The step above drives the mean of log(measured) to log(aim), i.e. the
// geometric mean; with frame-to-frame jitter the arithmetic mean is larger (the AM-GM inequality;
// for log-normal times E[t] = exp(E[log t] + Var(log t) / 2)), and the rate falls short of
// 1 / target (mogao_bench_serve showed it on the grotto). So the controller aims at
//     aim = target * (1 - headroom) * G / A
// where G and A are the geometric and arithmetic means of the recent measured times, exponentially
// weighted alike (weight `jitter_weight` per frame): with the geometric mean at target * G / A, the
// arithmetic one is at the target. G / A is measured, not modelled, so it holds for any
// distribution of the jitter and includes what the damped step adds to it and any correlation
// between frames. Frames whose step was clamped by max_step (a new view, a stall) are not jitter
// and are left out; the aim never drops below `min_aim` * target. jitter_weight = 0 leaves G / A
// out (the geometric mean at the aim, as before). `headroom` is a margin: even with G / A measured
// exactly, the mean is only at the aim on average, and a rate measured over a few seconds (a hundred
// frames or so) scatters by about 2 % around it; with a 2 % margin the rate a visitor gets stays
// at or above 1 / target.
//
// A frame's share of the period is also the caller's hand-off after it (encoding on the pipeline,
// queueing the next request), which the farm's own clock does not see. observe() takes the gap
// between the session's previous frame and this one: a gap shorter than `max_handoff` * target
// (the caller turned round at once, frames back to back) is charged to this frame; a longer one is
// the appliance's own pace (a 10 Hz kiosk leaves the farm idle between requests) and is not.
// max_handoff = 0 charges nothing.
//
// Units: seconds. Errors: the constructor throws std::invalid_argument naming a bad field.
#pragma once

#include "common/view_request.h"

namespace mogao {

struct FrameTimeTarget {
    double target_seconds = 1.0 / 15.0;  // > 0
    double gain = 0.5;                   // (0, 1]
    double max_step = 4.0;               // >= 1: largest change of w in one frame (factor)
    double min_scale = 0.5;              // (0, 1]: the floor of the resolution scale
    int max_spp = 16;                    // in request_limits::kSpp
    int min_bounces = 1;                 // in request_limits::kMaxBounces: fewest bounces below the floor
    double bounce_cost = 2.5;            // > 0: each bounce's cost relative to a direct-light-only frame
    double climb_margin = 0.8;           // (0, 1]: a deeper level is taken back when predicted <= margin * aim
    double jitter_weight = 0.1;          // [0, 1): weight of a frame in the means G and A (0 = off)
    double headroom = 0.02;              // [0, 1 - min_aim]: margin below the target (see above)
    double min_aim = 0.8;                // (0, 1]: the aim never drops below min_aim * target_seconds
    double max_handoff = 0.25;           // [0, 1): longest gap charged, as a fraction of target_seconds
};

struct FrameChoice {
    double resolution_scale = 1.0;
    int spp = 1;
    int bounces = -1;          // path depth to trace; -1 = the request's own
    double bounce_work = 1.0;  // (1 + c * bounces) / (1 + c * the request's bounces): 1 at its own depth
    // The ladder below the floor (set by choose()): its scale and the request's and fewest bounces.
    double floor_scale = 0.0;
    int request_bounces = 0, fewest_bounces = 0;
    [[nodiscard]] double work() const { return resolution_scale * resolution_scale * spp * bounce_work; }
};

class FrameTimeController {
public:
    explicit FrameTimeController(FrameTimeTarget target);

    // Scale and spp for the next frame of `request` (its size and resolution_scale bound the scale).
    // The first call, before any observe(), returns the request's own scale and spp (clamped).
    [[nodiscard]] FrameChoice choose(const ViewRequest& request) const;
    // The frame rendered with `used` took `seconds` (>= 0; NaN and negatives count as 0), and came
    // `gap_seconds` after the session's previous frame was handed back (see above; NaN, negatives and
    // gaps of max_handoff * target or more are not charged).
    void observe(const FrameChoice& used, double seconds, double gap_seconds = 0.0);
    // The gap observe() charges to a frame: `gap_seconds` when it is a hand-off, else 0.
    [[nodiscard]] double charged_gap(double gap_seconds) const;

    [[nodiscard]] double work() const { return work_; }  // < 0 before the first observe()
    // Seconds the next frame aims at: target_seconds less the headroom and the jitter's allowance.
    [[nodiscard]] double aim_seconds() const;
    // G / A of the recent unclamped frames (see above): 1 without jitter, and before the first one.
    [[nodiscard]] double jitter_allowance() const;
    [[nodiscard]] const FrameTimeTarget& target() const { return target_; }
    // Changes the target (the farm's share of it, live_frames.h); the measured means are kept.
    // Throws std::invalid_argument unless `seconds` is finite and > 0.
    void set_target_seconds(double seconds);

    // Work of the ladder's level of `bounces` for a frame shaped like `like` (see above).
    [[nodiscard]] double level_work(const FrameChoice& like, int bounces) const;

private:
    void note_time(double seconds);
    [[nodiscard]] double ladder_work(const FrameChoice& used, double seconds) const;

    static constexpr double kLadderWeight = 0.3;

    FrameTimeTarget target_;
    double work_ = -1.0;
    double ladder_used_work_ = -1.0;  // work of the last frame below the floor; -1 above it
    double ladder_seconds_ = 0.0;     // smoothed time of the frames at that level
    bool timed_ = false;              // the means hold a first sample
    double log_mean_ = 0.0;           // EWMA of log(measured): log G
    double arithmetic_ = 0.0;         // EWMA of measured: A
};

}  // namespace mogao
