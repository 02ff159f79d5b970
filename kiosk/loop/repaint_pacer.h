// SPDX-License-Identifier: Apache-2.0
// RepaintPacer: how much of the rasteriser's time the late warp's repaints may take.
//
// Between two farm frames the kiosk repaints the current frame at each tick when the late warp
// moved it (the yaw turned since the frame's request; docs/kiosk.md, "Late warp"). On a GPU a round
// of every output takes a millisecond or two and this costs nothing. On a software rasteriser
// (llvmpipe, the appliance without a GPU and this project's test machine) a round of three
// 1024x768 outputs takes tens of milliseconds: repaints at every tick keep the rasteriser busy all
// the time, so a new farm frame first waits for the round in progress, and the rasteriser's threads
// take the cores the farm renders on when both share a machine.
//
// The pacer allows a repaint only when the rasteriser has rested, since the end of its last round,
// (1 / max_duty - 1) times that round's duration: with max_duty = 0.5 it rests as long as it drew,
// with max_duty = 1 there is no limit. Rounds that show a new farm frame are never held back; they
// are counted (drew) like any other.
//
// Units: steady-clock time points; max_duty in (0, 1] (std::invalid_argument otherwise).
#pragma once

#include <chrono>

namespace mogao {

class RepaintPacer {
public:
    using Clock = std::chrono::steady_clock;
    explicit RepaintPacer(double max_duty);

    // A round was drawn from `start` to `end` (a new frame or a repaint).
    void drew(Clock::time_point start, Clock::time_point end);
    // Whether a repaint at `now` keeps the rasteriser's busy share within max_duty.
    [[nodiscard]] bool may_repaint(Clock::time_point now) const;

private:
    double rest_per_busy_;  // 1 / max_duty - 1
    Clock::time_point last_end_{};
    Clock::duration last_round_{};
};

}  // namespace mogao
