// SPDX-License-Identifier: Apache-2.0
// SessionBudgets: admitted work bounded by time as well as by estimated rays. The request policy
// (request_policy.h) bounds a request by its estimated rays, a figure fixed before anything was
// rendered; what those rays cost here in seconds depends on the scene, the view, the hosts and
// their load, and an admitted request can take many seconds a frame. The frame budget bounds it
// twice:
//  - within a frame: the dispatcher cuts a frame still rendering after `frame_s` (its remaining
//    tiles rendered coarse, frame_dispatcher.h), so one frame holds the farm for about the budget;
//  - across frames, here: each appliance's frames teach the farm its rate, estimated rays (the
//    request policy's formula) per second of the uncut frame (FrameStats::full_seconds). A request
//    whose estimate at that rate exceeds `frame_s` is degraded with the request policy's own steps
//    (spp, light samples, bounces, resolution scale) to `aim` x `frame_s`:
//        max_rays = rate * aim * frame_s
//    so its next frames fit the budget without being cut, and a still view stays the same view
//    (same_view) frame after frame. The rate is kept while new measurements stay within a factor
//    `band` of it (a degraded view's frames then do not move it back and forth), and replaced
//    otherwise.
//  - a request that does not fit even fully degraded (its estimate at the policy's floor still
//    over `frame_s`) is refused: apply() throws RequestRefused, which ends the session with that
//    message (link_server.h), instead of letting it take the farm's time frame after frame.
// Per appliance (certificate name), so a reconnecting appliance keeps what was measured; the least
// recently used is forgotten beyond `max_appliances`.
//
// Units: seconds, rays (counts). Errors: the constructor throws std::invalid_argument naming a bad
// field; apply() throws RequestRefused (above).
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "common/view_request.h"
#include "renderfarm/farm/request_policy.h"

namespace mogao {

struct TimeBudget {
    double frame_s = 1.0;             // a frame's time budget; 0 = off (requests pass unchanged)
    double aim = 0.5;                 // (0, 1]: degraded requests aim at aim * frame_s
    double band = 2.0;                // >= 1: a rate is replaced when a frame measures outside [rate/band, rate*band]
    std::size_t max_appliances = 64;  // rates remembered
    // A request degraded to its share of the farm (share_s < frame_s) keeps at least this resolution
    // scale: the share is the frame-time target's (live_frames.h), whose controller trades bounces, not
    // pixels, below its floor (its min_scale, which serve passes here). Degraded to frame_s itself, a
    // request may go lower. In [0, 1].
    double share_min_scale = 0.5;
};

struct BudgetDecision {
    ViewRequest view;  // the request as it will be rendered
    bool degraded = false;
    std::string changes;     // the request policy's list of changed knobs (empty when not degraded)
    double predicted_s = 0;  // the rendered view's estimated seconds at the measured rate (0: no rate yet)
    double limit_s = 0;      // the seconds it was held to: frame_s, or a smaller share
};

class SessionBudgets {
public:
    SessionBudgets(TimeBudget budget, LightCounts lights);
    // `request` of appliance `who`, degraded to its measured rate; throws RequestRefused (see above).
    // `share_s` > 0: other appliances are waiting and this frame's share of the farm is share_s
    // seconds (live_frames.h, share_frame_time): the request is degraded to fit the smaller of it
    // and frame_s, but refused only when it cannot fit frame_s.
    [[nodiscard]] BudgetDecision apply(const ViewRequest& request, const std::string& who, double share_s = 0.0);
    // A frame of `who` rendering `rendered` would have taken `full_seconds` uncut (> 0).
    void observe(const std::string& who, const ViewRequest& rendered, double full_seconds);
    // Estimated rays per second measured for `who`; 0 = none yet.
    [[nodiscard]] double rate(const std::string& who) const;
    [[nodiscard]] const TimeBudget& budget() const { return budget_; }

private:
    struct Appliance {
        double rays_per_s = 0.0;
        std::uint64_t last_used = 0;
    };
    TimeBudget budget_;
    LightCounts lights_;
    std::map<std::string, Appliance> appliances_;
    std::uint64_t uses_ = 0;
};

}  // namespace mogao
