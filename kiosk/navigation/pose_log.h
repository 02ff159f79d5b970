// SPDX-License-Identifier: Apache-2.0
// PoseLog: every pose the kiosk submitted to the farm, one JSON line per display tick
// (`mogao-kiosk --pose-log FILE`), for tests and for replaying a visit:
//   {"tick": 1, "t_ns": <CLOCK_MONOTONIC>, "request_id": 1, "eye": [x, y, z], "yaw_deg": 0.0,
//    "pitch_deg": 0.0, "source": "tracking", "tracking": true, "samples": 1, "turn_deg_s": 0.0,
//    "forward_m_s": 0.0}
// "tracking", "samples" (tag samples observed this tick), "turn_deg_s" and "forward_m_s" (the
// Navigator's integrated velocities) only with the tracking source. request_id 0: refused by the
// link (logged). Lines are flushed every second and at close, so a killed kiosk leaves a usable log.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>

#include "appliance/navigation/navigator.h"
#include "common/view_request.h"

namespace mogao {

struct PoseLogEntry {
    std::uint64_t tick = 0;
    std::int64_t time_ns = 0;  // CLOCK_MONOTONIC of the tick (the Navigator's display time)
    std::uint64_t request_id = 0;
    ViewerPose pose;
    bool tracking_source = false;
    bool tracking = false;    // the Navigator had the tag (tracking source only)
    std::size_t samples = 0;  // tag samples observed before this pose
    Velocity velocity;
};

class PoseLog {
public:
    // Creates/truncates `file`. Throws std::runtime_error naming it when it cannot be written.
    explicit PoseLog(const std::filesystem::path& file);

    // Throws std::runtime_error naming the file when a write fails.
    void write(const PoseLogEntry& entry);
    void close();

private:
    std::filesystem::path file_;
    std::ofstream out_;
    std::int64_t last_flush_ns_ = 0;
};

}  // namespace mogao
