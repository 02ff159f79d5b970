// SPDX-License-Identifier: Apache-2.0
#include "kiosk/navigation/pose_log.h"

#include <stdexcept>

#include <nlohmann/json.hpp>

namespace mogao {

PoseLog::PoseLog(const std::filesystem::path& file) : file_(file), out_(file, std::ios::trunc) {
    if (!out_) throw std::runtime_error("pose log " + file.string() + ": cannot be written");
}

void PoseLog::write(const PoseLogEntry& e) {
    nlohmann::json line = {{"tick", e.tick},
                           {"t_ns", e.time_ns},
                           {"request_id", e.request_id},
                           {"eye", {e.pose.eye.x(), e.pose.eye.y(), e.pose.eye.z()}},
                           {"yaw_deg", e.pose.yaw_deg},
                           {"pitch_deg", e.pose.pitch_deg},
                           {"source", e.tracking_source ? "tracking" : "path"}};
    if (e.tracking_source) {
        line["tracking"] = e.tracking;
        line["samples"] = e.samples;
        line["turn_deg_s"] = e.velocity.turn_deg_s;
        line["forward_m_s"] = e.velocity.forward_m_s;
    }
    out_ << line.dump() << '\n';
    if (e.time_ns - last_flush_ns_ >= 1'000'000'000) {
        out_.flush();
        last_flush_ns_ = e.time_ns;
    }
    if (!out_) throw std::runtime_error("pose log " + file_.string() + ": write failed");
}

void PoseLog::close() {
    if (!out_.is_open()) return;
    out_.flush();
    const bool ok = static_cast<bool>(out_);
    out_.close();
    if (!ok) throw std::runtime_error("pose log " + file_.string() + ": write failed");
}

}  // namespace mogao
