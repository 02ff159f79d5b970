// SPDX-License-Identifier: Apache-2.0
#include "kiosk/navigation/kiosk_navigation.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "kiosk/stats/kiosk_stats.h"

namespace mogao {

namespace {

const char* replay_end_name(ReplayEnd end) {
    return end == ReplayEnd::stop ? "stop" : end == ReplayEnd::loop ? "loop" : "idle";
}

}  // namespace

KioskNavigation::KioskNavigation(ViewScript script) : script_(std::move(script)) {}

KioskNavigation::KioskNavigation(const NavigationConfig& navigation, ViewRequest request_template)
    : template_(std::move(request_template)),
      navigator_(std::in_place, navigation.tracking.params, start_pose(navigation)),
      replay_end_(navigation.tracking.replay_end),
      samples_(std::make_unique<TagSampleQueue>()) {
    const TrackingConfig& t = navigation.tracking;
    tracker_ = std::make_unique<TrackingThread>(t, *samples_);
    spdlog::info("tracking: {} -> tag {} of {} mm ({}), intrinsics {}; replay end: {}", tracker_->description(),
                 t.tag_id < 0 ? std::string("largest") : std::to_string(t.tag_id), t.tag_size_m * 1000.0,
                 t.detector.family, t.intrinsics_file.string(), replay_end_name(t.replay_end));
}

KioskNavigation::~KioskNavigation() { stop(); }

KioskNavigation::Step KioskNavigation::next() {
    Step step;
    if (!navigator_) {
        step.entry.time_ns = monotonic_ns();
        step.request = script_->next();
        return step;
    }
    const TagSampleQueue::Batch batch = samples_->take_all();
    for (const TagSample& sample : batch.samples) navigator_->observe(sample);
    step.entry.tracking_source = true;
    step.entry.samples = batch.samples.size();
    step.replay_ended = batch.closed && replay_end_ == ReplayEnd::stop;
    step.entry.time_ns = monotonic_ns();
    step.request = template_;
    step.request.pose = navigator_->advance(step.entry.time_ns);
    step.entry.tracking = navigator_->tracking();
    step.entry.velocity = navigator_->velocity();
    return step;
}

void KioskNavigation::stop() {
    if (tracker_) tracker_->stop();
}

nlohmann::json KioskNavigation::report(std::uint64_t ticks) const {
    nlohmann::json navigation = {{"source", navigator_ ? "tracking" : "path"}, {"ticks", ticks}};
    if (!tracker_) return navigation;
    const TrackingCounters c = tracker_->counters();
    navigation.update(tracking_stats_json(tracker_->description(), c, samples_->pushed(), samples_->dropped(),
                                          navigator_->rejected_samples(), navigator_->pose()));
    spdlog::info(
        "tracking: {} frames ({} skipped behind newer ones), tag visible in {}, {} rejected by the "
        "flip gate, {} samples dropped",
        c.frames, c.skipped, c.visible, navigator_->rejected_samples(), samples_->dropped());
    return navigation;
}

}  // namespace mogao
