// SPDX-License-Identifier: Apache-2.0
// KioskNavigation: where each display tick's view comes from ([navigation] source, docs/kiosk.md):
// the scripted visitor (kiosk/navigation/view_script.h), or tracking -- the tracking thread's tag samples
// (kiosk/navigation/tracking_thread.h, through a TagSampleQueue) fed in order to a Navigator that is advanced to
// the tick's CLOCK_MONOTONIC time.
//
// Threading: next() and the Navigator on the loop's thread only; the tracking thread only pushes
// into the queue. Errors: the tracking constructor throws what Navigator / TrackingThread throw
// (std::invalid_argument, std::runtime_error naming [navigation].camera).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "appliance/navigation/navigator.h"
#include "common/view_request.h"
#include "kiosk/config/kiosk_config.h"
#include "kiosk/navigation/pose_log.h"
#include "kiosk/navigation/tag_sample_queue.h"
#include "kiosk/navigation/tracking_thread.h"
#include "kiosk/navigation/view_script.h"

namespace mogao {

class KioskNavigation {
public:
    // The scripted visitor.
    explicit KioskNavigation(ViewScript script);
    // Tracking ([navigation] source = "tracking"): a Navigator at the viewer start and the tracking
    // thread on the configured camera, started here; each view filled into `request_template`
    // (make_view_template).
    KioskNavigation(const NavigationConfig& navigation, ViewRequest request_template);
    ~KioskNavigation();
    KioskNavigation(const KioskNavigation&) = delete;
    KioskNavigation& operator=(const KioskNavigation&) = delete;

    struct Step {
        ViewRequest request;        // to submit; frame_id and request_time_ns are the link's
        PoseLogEntry entry;         // time_ns and the tracking fields; tick, request_id, pose are the caller's
        bool replay_ended = false;  // the replay's last samples were observed and replay_end = "stop"
    };
    // The next tick's view: after observing every queued tag sample, in order (tracking).
    [[nodiscard]] Step next();

    // Stops and joins the tracking thread (no-op for the scripted visitor). Idempotent.
    void stop();

    [[nodiscard]] bool tracking() const { return navigator_.has_value(); }
    // The statistics JSON's "navigation" (docs/kiosk.md); with tracking also logs its summary line.
    [[nodiscard]] nlohmann::json report(std::uint64_t ticks) const;

private:
    std::optional<ViewScript> script_;
    ViewRequest template_;
    std::optional<Navigator> navigator_;
    ReplayEnd replay_end_ = ReplayEnd::stop;
    std::unique_ptr<TagSampleQueue> samples_;
    std::unique_ptr<TrackingThread> tracker_;  // last: stopped before the queue and navigator go
};

}  // namespace mogao
