// SPDX-License-Identifier: Apache-2.0
#include "kiosk/stats/kiosk_stats.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "common/file_io.h"
#include "kiosk/navigation/tracking_thread.h"
#include "kiosk/stats/kiosk_metrics.h"
#include "renderfarm/link/link_client.h"

namespace mogao {
namespace {

double ms(std::int64_t ns) { return static_cast<double>(ns) / 1e6; }

double percentile(std::vector<double> values, double p) {
    if (values.empty()) return 0;
    std::sort(values.begin(), values.end());
    const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(values.size())));
    return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

double round3(double x) { return std::round(x * 1000.0) / 1000.0; }

nlohmann::json summary_json(const StatsSummary& s) {
    return {{"frames", s.frames},
            {"fps", round3(s.fps)},
            {"motion_to_photon_ms",
             {{"mean", round3(s.latency_mean_ms)},
              {"p50", round3(s.latency_p50_ms)},
              {"p95", round3(s.latency_p95_ms)},
              {"max", round3(s.latency_max_ms)}}},
            {"link_mean_ms", round3(s.link_mean_ms)},
            {"kiosk_mean_ms", round3(s.kiosk_mean_ms)},
            {"decode_mean_ms", round3(s.decode_mean_ms)},
            {"bytes_per_frame", round3(s.bytes_per_frame)},
            {"bandwidth_bytes_per_s", round3(s.bandwidth_bytes_per_s)}};
}

// One frame's entry of the per-frame list and the frame log (docs/kiosk.md).
nlohmann::json frame_record(const PresentedFrame& f) {
    nlohmann::json j = {{"request_id", f.request_id},
                        {"link_frame_id", f.link_frame_id},
                        {"jpeg_bytes", f.jpeg_bytes},
                        {"request_ns", f.request_ns},
                        {"receive_ns", f.receive_ns},
                        {"presented_ns", f.presented_ns},
                        {"motion_to_photon_ms", round3(ms(f.presented_ns - f.request_ns))},
                        {"decode_ms", round3(f.decode_ms)},
                        {"display_round", f.display_round},
                        {"served", {f.served.width, f.served.height}}};
    if (f.served_spp > 0) j["served_spp"] = f.served_spp, j["served_bounces"] = f.served_bounces;
    return j;
}

}  // namespace

KioskStats::KioskStats(std::size_t window, std::size_t frames_kept)
    : window_size_(std::max<std::size_t>(window, 2)),
      frames_kept_(frames_kept),
      latency_ms_(0.005, 0.01, 3.6e6),  // 10 us to 1 h
      served_height_(0.005, 1, 65536),
      motion_to_photon_(motion_to_photon_buckets()) {
    history_.reserve(frames_kept_);  // once: the list never reallocates while the wall plays
}

void KioskStats::open_frame_log(const std::filesystem::path& path) { frame_log_ = std::make_unique<FrameLog>(path); }

void KioskStats::add_to_totals(const PresentedFrame& f) {
    Totals& t = totals_;
    const double latency = ms(f.presented_ns - f.request_ns);
    if (frames_ == 1) t.first_presented_ns = f.presented_ns, t.first_bytes = f.jpeg_bytes;
    t.last_presented_ns = f.presented_ns;
    t.latency_sum_ms += latency;
    t.latency_max_ms = frames_ == 1 ? latency : std::max(t.latency_max_ms, latency);
    t.link_sum_ms += ms(f.receive_ns - f.request_ns);
    t.kiosk_sum_ms += ms(f.presented_ns - f.receive_ns);
    t.decode_sum_ms += f.decode_ms;
    t.served_height_sum += f.served.height;
    t.served_height_min = frames_ == 1 ? f.served.height : std::min(t.served_height_min, f.served.height);
    latency_ms_.add(latency);
    served_height_.add(f.served.height);
    if (f.served_spp == 0) return;
    const bool first = t.quality_frames++ == 0;
    t.spp_min = first ? f.served_spp : std::min(t.spp_min, f.served_spp);
    t.bounce_min = first ? f.served_bounces : std::min(t.bounce_min, f.served_bounces);
    t.spp_sum += f.served_spp, t.bounce_sum += f.served_bounces;
}

void KioskStats::presented(const PresentedFrame& frame) {
    if (frame.request_id <= last_request_id_) ++out_of_order_;
    last_request_id_ = frame.request_id;
    ++frames_;
    bytes_ += frame.jpeg_bytes;
    add_to_totals(frame);
    motion_to_photon_.observe(double(frame.presented_ns - frame.request_ns) * 1e-9);
    window_.push_back(frame);
    while (window_.size() > window_size_) window_.pop_front();
    if (history_.size() < frames_kept_) history_.push_back(frame);
    if (frame_log_) frame_log_->append(frame_record(frame).dump());
}

void KioskStats::event(std::int64_t realtime_ns, std::string what, std::uint64_t last_request_id) {
    if (events_.size() >= kMaxEvents) {
        ++events_dropped_;
        return;
    }
    events_.push_back({{"time_ns", realtime_ns},
                       {"event", std::move(what)},
                       {"display_round", rounds_},
                       {"frames", frames_},
                       {"last_request_id", last_request_id}});
}

StatsSummary KioskStats::summarise(const std::vector<const PresentedFrame*>& frames) {
    StatsSummary s;
    s.frames = frames.size();
    if (frames.empty()) return s;
    std::vector<double> latency;
    double link = 0, kiosk = 0, decode = 0, bytes = 0;
    for (const PresentedFrame* f : frames) {
        latency.push_back(ms(f->presented_ns - f->request_ns));
        link += ms(f->receive_ns - f->request_ns);
        kiosk += ms(f->presented_ns - f->receive_ns);
        decode += f->decode_ms;
        bytes += static_cast<double>(f->jpeg_bytes);
    }
    const auto n = static_cast<double>(frames.size());
    double sum = 0;
    for (const double l : latency) sum += l;
    s.latency_mean_ms = sum / n;
    s.latency_max_ms = *std::max_element(latency.begin(), latency.end());
    s.latency_p50_ms = percentile(latency, 0.50);
    s.latency_p95_ms = percentile(latency, 0.95);
    s.link_mean_ms = link / n;
    s.kiosk_mean_ms = kiosk / n;
    s.decode_mean_ms = decode / n;
    s.bytes_per_frame = bytes / n;
    const double span_s = static_cast<double>(frames.back()->presented_ns - frames.front()->presented_ns) / 1e9;
    if (frames.size() >= 2 && span_s > 0) {
        s.fps = (n - 1) / span_s;
        s.bandwidth_bytes_per_s = (bytes - static_cast<double>(frames.front()->jpeg_bytes)) / span_s;
    }
    return s;
}

StatsSummary KioskStats::window_summary() const {
    std::vector<const PresentedFrame*> frames;
    for (const auto& f : window_) frames.push_back(&f);
    return summarise(frames);
}

StatsSummary KioskStats::total_summary() const {
    if (every_frame_kept()) {
        std::vector<const PresentedFrame*> frames;
        for (const auto& f : history_) frames.push_back(&f);
        return summarise(frames);
    }
    const Totals& t = totals_;
    const auto n = static_cast<double>(frames_);
    StatsSummary s;
    s.frames = frames_;
    s.latency_mean_ms = t.latency_sum_ms / n;
    s.latency_max_ms = t.latency_max_ms;
    s.latency_p50_ms = latency_ms_.quantile(0.50);
    s.latency_p95_ms = latency_ms_.quantile(0.95);
    s.link_mean_ms = t.link_sum_ms / n;
    s.kiosk_mean_ms = t.kiosk_sum_ms / n;
    s.decode_mean_ms = t.decode_sum_ms / n;
    s.bytes_per_frame = static_cast<double>(bytes_) / n;
    const double span_s = static_cast<double>(t.last_presented_ns - t.first_presented_ns) / 1e9;
    if (span_s > 0) {
        s.fps = (n - 1) / span_s;
        s.bandwidth_bytes_per_s = static_cast<double>(bytes_ - t.first_bytes) / span_s;
    }
    return s;
}

std::string KioskStats::log_line() const {
    const StatsSummary w = window_summary();
    return fmt::format(
        "frames={} fps={:.1f} motion_to_photon_ms(mean={:.1f} p95={:.1f} max={:.1f}) link_ms={:.1f} kiosk_ms={:.1f} "
        "bytes_per_frame={:.0f} bandwidth_MBps={:.3f} rejected={} superseded={} rounds={}",
        frames_, w.fps, w.latency_mean_ms, w.latency_p95_ms, w.latency_max_ms, w.link_mean_ms, w.kiosk_mean_ms,
        w.bytes_per_frame, w.bandwidth_bytes_per_s / 1e6, rejected_, superseded_, rounds_);
}

namespace {

// The content's height from run_stats_json's "content": [width, height]; 0 when absent.
double content_height(const nlohmann::json& extra) {
    const auto content = extra.find("content");
    if (content == extra.end() || !content->is_array() || content->size() != 2 || !(*content)[1].is_number()) return 0;
    return std::max(0.0, (*content)[1].get<double>());
}

}  // namespace

// The samples per pixel and bounces of the frames the farm reported them for: mean and least of
// each; null when no frame carried them (a farm from before the fields).
nlohmann::json KioskStats::served_quality_json() const {
    const Totals& t = totals_;
    if (t.quality_frames == 0) return nullptr;
    const auto n = static_cast<double>(t.quality_frames);
    return {{"frames", t.quality_frames},
            {"spp", {{"mean", round3(t.spp_sum / n)}, {"min", t.spp_min}}},
            {"bounces", {{"mean", round3(t.bounce_sum / n)}, {"min", t.bounce_min}}}};
}

// The served scale's mean, least and 5th percentile over the run; null without frames or content.
nlohmann::json KioskStats::served_scale_json(const nlohmann::json& extra) const {
    const double height = content_height(extra);
    if (frames_ == 0 || height <= 0) return nullptr;
    double p05 = served_height_.quantile(0.05);
    if (every_frame_kept()) {
        std::vector<double> heights;
        for (const auto& f : history_) heights.push_back(f.served.height);
        p05 = percentile(std::move(heights), 0.05);
    }
    return {{"mean", round3(totals_.served_height_sum / static_cast<double>(frames_) / height)},
            {"min", round3(totals_.served_height_min / height)},
            {"p05", round3(p05 / height)}};
}

nlohmann::json KioskStats::to_json(const nlohmann::json& extra) const {
    const double height = content_height(extra);
    nlohmann::json frames = nlohmann::json::array();
    for (const auto& f : history_) {
        frames.push_back(frame_record(f));
        if (height > 0) frames.back()["served_scale"] = round3(f.served.height / height);
    }
    nlohmann::json total = summary_json(total_summary());
    total["percentiles"] = every_frame_kept() ? "exact" : "sketch (within 0.5 %)";
    total["served_scale"] = served_scale_json(extra);
    total["served_quality"] = served_quality_json();
    nlohmann::json out = {{"frames_presented", frames_},
                          {"jpeg_bytes_presented", bytes_},
                          {"frames_rejected", rejected_},
                          {"frames_superseded", superseded_},
                          {"frames_out_of_order", out_of_order_},
                          {"display_rounds", rounds_},
                          {"total", std::move(total)},
                          {"window", summary_json(window_summary())},
                          {"events", events_},
                          {"events_dropped", events_dropped_},
                          {"frames_kept", frames_kept_},
                          {"frames", std::move(frames)}};
    if (frame_log_) {
        out["frame_log"] = {{"path", frame_log_->path().string()}, {"lines", frame_log_->lines()}};
        if (!frame_log_->error().empty()) out["frame_log"]["error"] = frame_log_->error();
    }
    for (const auto& [key, value] : extra.items()) out[key] = value;
    return out;
}

void KioskStats::write_json(const std::filesystem::path& path, const nlohmann::json& extra) const {
    const std::string text = to_json(extra).dump(1) + "\n";
    write_file_atomically(path, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
}

nlohmann::json link_stats_json(const LinkClientStats& link) {
    return {{"sessions_opened", link.sessions_opened},       {"attempts_failed", link.attempts_failed},
            {"requests_submitted", link.requests_submitted}, {"requests_sent", link.requests_sent},
            {"requests_coalesced", link.requests_coalesced}, {"frames_received", link.frames_received},
            {"frames_discarded", link.frames_discarded},     {"bytes_received", link.bytes_received}};
}

nlohmann::json tracking_stats_json(const std::string& camera, const TrackingCounters& c, std::uint64_t samples_queued,
                                   std::uint64_t samples_dropped, std::uint64_t samples_rejected_by_gate,
                                   const ViewerPose& final_pose) {
    return {{"camera", camera},
            {"frames_tracked", c.frames},
            {"frames_skipped", c.skipped},
            {"tag_visible", c.visible},
            {"ambiguous", c.ambiguous},
            {"frame_errors", c.frame_errors},
            {"camera_timeouts", c.timeouts},
            {"camera_reopens", c.reopens},
            {"replay_ended", c.ended},
            {"samples_queued", samples_queued},
            {"samples_dropped", samples_dropped},
            {"samples_rejected_by_gate", samples_rejected_by_gate},
            {"final_pose",
             {{"eye", {final_pose.eye.x(), final_pose.eye.y(), final_pose.eye.z()}}, {"yaw_deg", final_pose.yaw_deg}}}};
}

nlohmann::json run_stats_json(const RunRecord& run) {
    return {{"endpoint", run.endpoint},
            {"content", {run.content.width, run.content.height}},
            {"jpeg_quality", run.jpeg_quality},
            {"navigation", run.navigation},
            {"link", run.link},
            {"exit_code", run.exit_code}};
}

}  // namespace mogao
