// SPDX-License-Identifier: Apache-2.0
// FrameDeadline: how long the admin waits for the render ranks' replies to one frame before it
// takes a rank for lost (dead host, stopped process, cut link) and ends the MPI job so that the
// farm restarts over the hosts that answer (docs/services.md, "Render-node failure").
//
// A fixed deadline must cover the dearest frame the request policy lets through (max_gigarays,
// about 12 s on one 2-core host), so a lost host would keep the wall frozen that long before the
// restart even begins. Instead the deadline follows what frames cost here:
//
//   deadline(frame) = clamp(factor * rate * cost(frame), min_s, max_s)
//   cost(frame)     = render pixels * spp * (max_bounces + 1)      [frame_cost_units]
//   rate            = the largest seconds per cost unit over the last `window` frames
//
// Until a frame has been measured the deadline is max_s. The largest recent rate (not a mean)
// and the factor leave room for a view of a dearer part of the scene or a busy host; a rank that
// is merely slower than predicted within that room is not taken for lost. max_s <= 0: no deadline.
// Units: seconds; cost units are dimensionless.
#pragma once

#include <cstddef>
#include <deque>

#include "common/view_request.h"

namespace mogao {

struct FrameDeadlineSettings {
    double max_s = 30.0;      // upper bound, and the deadline before any frame was measured; <= 0: none
    double min_s = 2.0;       // lower bound (scheduling noise, the first frames of a session)
    double factor = 4.0;      // times the frame's expected time; 0 = always max_s
    std::size_t window = 16;  // frames whose rates are remembered
};

// render pixels * spp * (max_bounces + 1): proportional to the rays of a frame for one scene.
[[nodiscard]] double frame_cost_units(const ViewRequest& view);

class FrameDeadline {
public:
    explicit FrameDeadline(FrameDeadlineSettings settings) : settings_(settings) {}
    // Seconds the ranks get for a frame of `cost` units; 0 = wait forever (max_s <= 0).
    [[nodiscard]] double seconds_for(double cost) const;
    // A frame of `cost` units took `seconds` from sending the view to the last reply.
    void observe(double cost, double seconds);
    [[nodiscard]] const FrameDeadlineSettings& settings() const { return settings_; }

private:
    FrameDeadlineSettings settings_;
    std::deque<double> rates_;  // seconds per cost unit, newest last
};

}  // namespace mogao
