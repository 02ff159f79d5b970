// SPDX-License-Identifier: Apache-2.0
// RequestPace: the pace an appliance asks for frames at, and the frame-time target that follows it
// (renderfarm/farm/live_frames.h, LiveOptions::follow_request_pace).
//
// A 10 Hz kiosk against a 15 frames/s target leaves the farm idle a third of the time: the pixels it
// could have rendered are wasted. The session's request period P is measured from its requests' own
// stamps (ViewRequest::request_time_ns over the request ids between two requests, so requests
// superseded on the way count), and the farm's wait W before each of its frames; both are weighted
// exponentially (weight 0.3 for the newest, a few requests' memory). While the farm waits for the
// appliance, the frame may take share * P (the rest of the period for the hand-off and the frames'
// jitter), between the target T and max_factor * T:
//     target = clamp(share * P, T, max_factor * T)
// The session counts as setting the pace once W reaches half of the period's rest, (1 - share) P / 2,
// and stops below a sixth of it (hysteresis: following, the wait is about the rest less the hand-off).
// An appliance that asks for its next view only once a frame is back waits for the farm instead: its
// W is the hand-off alone, and its frames keep T.
//
// Units: seconds. Pure: no clock of its own.
#pragma once

namespace mogao {

class RequestPace {
public:
    // A request `period_s` after the previous one (per request id), the farm having waited `wait_s` for it;
    // share in (0, 1). Non-positive or non-finite periods are ignored; a negative wait counts as 0.
    void note(double period_s, double wait_s, double share);
    // The target for the next frame: clamp(share * period, target_s, max_factor * target_s) while the session
    // sets the pace, else target_s.
    [[nodiscard]] double target(double target_s, double share, double max_factor) const;

    [[nodiscard]] double period_s() const { return period_s_; }
    [[nodiscard]] double wait_s() const { return wait_s_; }
    [[nodiscard]] bool paced() const { return paced_; }

private:
    double period_s_ = 0.0;
    double wait_s_ = 0.0;
    bool paced_ = false;
};

}  // namespace mogao
