// SPDX-License-Identifier: Apache-2.0
// Tracker-to-view latency: the time from a camera frame handed to the tracker to the ViewerPose the
// kiosk submits for it — AprilTag detection, IPPE pose + ambiguity resolution, then the navigator's
// observe (One Euro filtering, flip gate) and advance — measured frame by frame on the synthetic
// hand-held sequence (known poses, 800x600). The filter adds its own lag on top of this processing
// time (One Euro vs low-pass: mogao_navigation_bench). Times are wall clock of this thread; the
// detector alone on the same frames (the tracker's whole-frame settings) is the baseline measured in
// the same run, and the tracker runs both with region-of-interest tracking off and on.
//   mogao_tracker_to_view_bench [--frames N]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include <CLI/CLI.hpp>

#include "appliance/navigation/navigator.h"
#include "appliance/navigation/tag_sample_of.h"
#include "appliance/tracker/lab/hand_sequence.h"
#include "appliance/tracker/lab/synthetic_view.h"
#include "appliance/tracker/tag_bitmap.h"
#include "appliance/tracker/tag_family.h"
#include "appliance/tracker/tag_tracker.h"

namespace mogao {
namespace {

using Clock = std::chrono::steady_clock;

double percentile(std::vector<double> v, double p) {
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

// One way from a camera frame to a ViewerPose: tracker (pose, disambiguation), then the
// navigator's observe (One Euro, flip gate) and advance; wall-clock time per frame.
struct Stage {
    const char* name;
    TagTracker tracker;
    Navigator navigator;
    std::vector<double> ms;
    int tracked = 0;

    void step(const CameraFrame& frame) {
        const auto t0 = Clock::now();
        const TrackedTag tag = tracker.track(frame);
        navigator.observe(tag_sample_of(tag));
        (void)navigator.advance(frame.timestamp_ns);
        ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        tracked += tag.visible ? 1 : 0;
    }
};

}  // namespace
}  // namespace mogao

int main(int argc, char** argv) {
    using namespace mogao;
    CLI::App app{"tracker-to-view latency on the synthetic hand-held sequence"};
    int frames = 120;
    app.add_option("--frames", frames, "frames of the sequence to process")->check(CLI::Range(2, 3600));
    CLI11_PARSE(app, argc, argv);

    HandSequenceSpec spec;
    const std::vector<HandFrame> truth = hand_trajectory(spec);
    const PlanarTarget target = tag_target(make_tag_bitmap(TagFamily(spec.family), spec.tag_id), spec.tag_size_m);
    std::vector<CameraFrame> camera_frames;
    for (int i = 0; i < frames && i < static_cast<int>(truth.size()); ++i) {
        if (!truth[static_cast<std::size_t>(i)].visible) continue;
        CameraFrame f;
        f.image = render_target(target, truth[static_cast<std::size_t>(i)].pose, spec.camera);
        f.timestamp_ns = truth[static_cast<std::size_t>(i)].time_ns;
        f.sequence = static_cast<std::uint64_t>(i);
        camera_frames.push_back(std::move(f));
    }

    TrackerConfig config;
    config.camera = spec.camera;
    config.tag_size_m = spec.tag_size_m;
    config.tag_id = spec.tag_id;
    // The baseline is the whole-frame search the tracker itself runs (it never runs the detector's
    // up-sampled pass: tag_tracker.h).
    DetectorSettings whole_frame = config.detector;
    whole_frame.upsample_pass_factor = 0;
    TagDetector detector(whole_frame);
    TrackerConfig no_roi = config;
    no_roi.roi.enabled = false;
    Stage full{"frame -> ViewerPose, whole-frame search every frame (ROI off)",
               TagTracker(no_roi),
               Navigator(NavigationParams{}, ViewerPose{}),
               {},
               0};
    Stage roi{"frame -> ViewerPose, region-of-interest tracking (the kiosk's default)",
              TagTracker(config),
              Navigator(NavigationParams{}, ViewerPose{}),
              {},
              0};
    std::vector<double> detect_ms;
    for (const CameraFrame& frame : camera_frames) {  // interleaved: the machine's load biases none
        const auto t0 = Clock::now();
        (void)detector.detect(frame.image);
        detect_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        full.step(frame);
        roi.step(frame);
    }
    const double base = percentile(detect_ms, 0.5);
    std::printf("| stage (%zu frames 800x600) | frames tracked | median ms | p95 ms | median / detection |\n",
                camera_frames.size());
    std::printf("|---|--:|--:|--:|--:|\n");
    std::printf("| AprilTag detection alone, whole frame (baseline) | | %.2f | %.2f | 1.00 |\n", base,
                percentile(detect_ms, 0.95));
    for (const Stage* s : {&full, &roi}) {
        std::printf("| %s | %d | %.2f | %.2f | %.2f |\n", s->name, s->tracked, percentile(s->ms, 0.5),
                    percentile(s->ms, 0.95), percentile(s->ms, 0.5) / base);
    }
    return 0;
}
