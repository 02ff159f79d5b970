// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/tag_tracker.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace mogao {
namespace {

double quad_area(const TagDetection& d) {  // shoelace formula
    double a = 0.0;
    for (std::size_t i = 0; i < 4; ++i) {
        const auto& p = d.corners[i];
        const auto& q = d.corners[(i + 1) % 4];
        a += p.x() * q.y() - q.x() * p.y();
    }
    return std::abs(a) / 2.0;
}

template <typename T>
void check_roi(const char* field, T value, T lo, T hi, bool open_low = false) {
    if (!(open_low ? value > lo : value >= lo) || !(value <= hi)) {
        std::ostringstream msg;
        msg << "RoiSettings." << field << " = " << value << " outside " << (open_low ? "(" : "[") << lo << ", " << hi
            << "]";
        throw std::invalid_argument(msg.str());
    }
}

void validate(const RoiSettings& r) {
    check_roi("margin", r.margin, 0.0, 5.0, true);
    check_roi("min_margin_px", r.min_margin_px, 0.0, 1000.0);
    check_roi("full_search_every", r.full_search_every, 0, 100000);
    check_roi("search_decimation", r.search_decimation, 1.0f, 8.0f);
    check_roi("search_blur_sigma", r.search_blur_sigma, -5.0f, 5.0f);
    if (r.window_tag_px != 0.0) check_roi("window_tag_px", r.window_tag_px, 4.0, 1000.0);
    check_roi("window_max_decimation", r.window_max_decimation, 1, 8);
    check_roi("window_blur_sigma", r.window_blur_sigma, -5.0f, 5.0f);
    check_roi("idle_after_s", r.idle_after_s, 0.0, 3600.0);
    check_roi("idle_search_period_s", r.idle_search_period_s, 0.0, 3600.0);
}

// The tracker's detector never runs the up-sampled search (DetectorSettings::upsample_pass_factor):
// it is for tags under ~20 px, i.e. a 10 cm tag more than ~3.5 m from a 700 px camera, not a
// hand-held one, and it costs several times a full-resolution search per frame.
DetectorSettings without_upsampled_pass(DetectorSettings s) {
    s.upsample_pass_factor = 0;
    return s;
}

}  // namespace

TagTracker::TagTracker(const TrackerConfig& config)
    : config_(config), detector_(without_upsampled_pass(config.detector)), disambiguator_(config.disambiguation) {
    validate(config_.roi);
    validate(config_.camera);
    if (!(config_.tag_size_m > 0.0 && config_.tag_size_m <= 10.0)) {
        throw std::invalid_argument("TrackerConfig.tag_size_m " + std::to_string(config_.tag_size_m) +
                                    " outside (0, 10]");
    }
    if (config_.tag_id >= detector_.family().code_count()) {
        throw std::invalid_argument("TrackerConfig.tag_id " + std::to_string(config_.tag_id) + " outside [-1, " +
                                    std::to_string(detector_.family().code_count()) + ") of " +
                                    detector_.family().name());
    }
    if (!(config_.forget_after_s >= 0.0)) throw std::invalid_argument("TrackerConfig.forget_after_s must be >= 0");
}

const TagDetection* TagTracker::pick(const std::vector<TagDetection>& detections) const {
    const TagDetection* best = nullptr;
    for (const auto& d : detections) {
        if (config_.tag_id >= 0 ? d.id == config_.tag_id : (best == nullptr || quad_area(d) > quad_area(*best)))
            best = &d;
    }
    return best;
}

std::vector<TagDetection> TagTracker::detect_in_window(const GrayImage& image, std::int64_t timestamp_ns) {
    // Constant-velocity prediction of the corners (velocity from the last two sightings).
    const double dt = static_cast<double>(timestamp_ns - last_corners_ns_) * 1e-9;
    double x0 = image.width, y0 = image.height, x1 = 0.0, y1 = 0.0, side = 0.0, shortest = 1e300;
    for (std::size_t i = 0; i < 4; ++i) {
        const Eigen::Vector2d& c = last_corners_[i];
        const Eigen::Vector2d p = sightings_ >= 2 ? Eigen::Vector2d(c + velocity_px_s_[i] * dt) : c;
        x0 = std::min({x0, c.x(), p.x()});
        y0 = std::min({y0, c.y(), p.y()});
        x1 = std::max({x1, c.x(), p.x()});
        y1 = std::max({y1, c.y(), p.y()});
        const double edge = (last_corners_[(i + 1) % 4] - c).norm();
        side = std::max(side, edge);
        shortest = std::min(shortest, edge);
    }
    const double grow = std::max(config_.roi.margin * side, config_.roi.min_margin_px);
    const int left = std::clamp(static_cast<int>(std::floor(x0 - grow)), 0, image.width);
    const int top = std::clamp(static_cast<int>(std::floor(y0 - grow)), 0, image.height);
    const int right = std::clamp(static_cast<int>(std::ceil(x1 + grow)), 0, image.width);
    const int bottom = std::clamp(static_cast<int>(std::ceil(y1 + grow)), 0, image.height);
    if (right - left < 8 || bottom - top < 8) return {};  // predicted out of the frame
    window_.width = right - left;
    window_.height = bottom - top;
    window_.pixels.resize(static_cast<std::size_t>(window_.width) * static_cast<std::size_t>(window_.height));
    for (int y = 0; y < window_.height; ++y) {
        std::memcpy(window_.pixels.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(window_.width),
                    image.pixels.data() + static_cast<std::size_t>(y + top) * static_cast<std::size_t>(image.width) +
                        static_cast<std::size_t>(left),
                    static_cast<std::size_t>(window_.width));
    }
    // The quad search's resolution from the tag's size (tag_tracker.h); never finer than the
    // detector's own settings.
    const DetectorSettings& base = config_.detector;
    int decimation = 1;
    if (config_.roi.window_tag_px > 0.0) {
        decimation = std::clamp(static_cast<int>(std::floor(shortest / config_.roi.window_tag_px)), 1,
                                config_.roi.window_max_decimation);
    }
    if (static_cast<float>(decimation) > base.decimation) {
        detector_.set_quad_search(static_cast<float>(decimation), config_.roi.window_blur_sigma);
    } else {
        detector_.set_quad_search(base.decimation, base.blur_sigma);
    }
    last_window_decimation_ = static_cast<int>(detector_.settings().decimation);
    auto found = detector_.detect(window_, TagDetector::Passes::single);
    const Eigen::Vector2d origin(left, top);  // pixel (i, j) of the window is (i + left, j + top)
    for (auto& d : found) {
        for (auto& c : d.corners) c += origin;
        d.centre += origin;
    }
    return found;
}

bool TagTracker::idle_throttled(std::int64_t timestamp_ns) const {
    const RoiSettings& r = config_.roi;
    if (!r.enabled || r.idle_search_period_s <= 0.0 || sightings_ > 0 || full_searches_ == 0) return false;
    if (timestamp_ns < last_search_ns_) return false;
    const std::int64_t unseen_since = seen_ ? std::max(last_seen_ns_, first_search_ns_) : first_search_ns_;
    if (static_cast<double>(timestamp_ns - unseen_since) * 1e-9 < r.idle_after_s) return false;
    // Due once the period has passed, give or take 1 ms of timestamp rounding (3 frames stamped
    // 33'333'333 ns apart are a period of 0.1 s).
    return static_cast<double>(timestamp_ns - last_search_ns_) * 1e-9 + 1e-3 < r.idle_search_period_s;
}

TrackedTag TagTracker::track(const CameraFrame& frame) {
    if (frame.image.width != config_.camera.width || frame.image.height != config_.camera.height) {
        throw std::invalid_argument("TagTracker: frame " + std::to_string(frame.image.width) + "x" +
                                    std::to_string(frame.image.height) + " but the calibration is for " +
                                    std::to_string(config_.camera.width) + "x" + std::to_string(config_.camera.height));
    }
    TrackedTag out;
    out.timestamp_ns = frame.timestamp_ns;
    last_window_decimation_ = 0;
    if (idle_throttled(frame.timestamp_ns)) return out;  // idle: not this frame (RoiSettings)
    std::vector<TagDetection> detections;
    std::optional<TagDetection> chosen;
    if (config_.roi.enabled && sightings_ > 0) {
        detections = detect_in_window(frame.image, frame.timestamp_ns);
        // In the window: the followed tag (its id), so a neighbour does not steal the track.
        for (const auto& d : detections) {
            if (d.id == followed_id_) chosen = d;
        }
        out.from_window = chosen.has_value();
    }
    ++frames_since_search_;
    const bool cadence = config_.roi.full_search_every > 0 && frames_since_search_ >= config_.roi.full_search_every;
    if (!config_.roi.enabled || !chosen || cadence) {
        if (config_.roi.enabled) {
            detector_.set_quad_search(config_.roi.search_decimation, config_.roi.search_blur_sigma);
        } else {
            detector_.set_quad_search(config_.detector.decimation, config_.detector.blur_sigma);
        }
        detections = detector_.detect(frame.image);
        if (full_searches_ == 0) first_search_ns_ = frame.timestamp_ns;
        last_search_ns_ = frame.timestamp_ns;
        ++full_searches_;
        frames_since_search_ = 0;
        const TagDetection* p = pick(detections);
        // A whole-frame result replaces the window's only for another (larger) tag: the window's
        // corners come from full resolution.
        if (p != nullptr && (!chosen || (p->id != chosen->id && quad_area(*p) > quad_area(*chosen)))) {
            chosen = *p;
            out.from_window = false;
        }
    }
    if (!chosen) {
        sightings_ = 0;
        return out;
    }
    if (seen_ && static_cast<double>(frame.timestamp_ns - last_seen_ns_) > config_.forget_after_s * 1e9)
        disambiguator_.reset();
    const auto candidates = solve_tag_pose(chosen->corners, config_.camera, config_.tag_size_m);
    if (candidates.empty()) {
        sightings_ = 0;
        return out;
    }
    // The prediction's state: velocity only between two consecutive sightings of the same tag.
    const double dt = static_cast<double>(frame.timestamp_ns - last_corners_ns_) * 1e-9;
    const bool continues = sightings_ > 0 && chosen->id == followed_id_ && dt > 0.0;
    for (std::size_t i = 0; i < 4; ++i)
        velocity_px_s_[i] =
            continues ? Eigen::Vector2d((chosen->corners[i] - last_corners_[i]) / dt) : Eigen::Vector2d::Zero();
    sightings_ = continues ? sightings_ + 1 : 1;
    followed_id_ = chosen->id;
    last_corners_ = chosen->corners;
    last_corners_ns_ = frame.timestamp_ns;

    out.visible = true;
    out.id = chosen->id;
    out.detection = *chosen;
    out.pose = disambiguator_.choose(candidates);
    out.ambiguous = disambiguator_.last_was_ambiguous();
    seen_ = true;
    last_seen_ns_ = frame.timestamp_ns;
    return out;
}

}  // namespace mogao
