// SPDX-License-Identifier: Apache-2.0
// Tracker-to-view latency: the time from a camera frame handed to the tracker to the ViewerPose the
// kiosk submits for it — AprilTag detection, IPPE pose + ambiguity resolution, then the navigator's
// observe (One Euro filtering, flip gate) and advance — measured frame by frame on the synthetic
// hand-held sequence (known poses, 800x600). The filter adds its own lag on top of this processing
// time (One Euro vs low-pass: mogao_navigation_bench). Times are wall clock of this thread; the
// detector alone on the same frames is the baseline measured in the same run.
//   mogao_tracker_to_view_bench [--frames N]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include <CLI/CLI.hpp>

#include "appliance/navigation/navigator.h"
#include "appliance/tracker/hand_sequence.h"
#include "appliance/tracker/synthetic_view.h"
#include "appliance/tracker/tag_bitmap.h"
#include "appliance/tracker/tag_family.h"
#include "appliance/navigation/tag_sample_of.h"
#include "appliance/tracker/tag_tracker.h"

namespace {

using Clock = std::chrono::steady_clock;

double percentile(std::vector<double> v, double p) {
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

}  // namespace

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
    TagDetector detector(config.detector);
    TagTracker tracker(config);
    Navigator navigator(NavigationParams{}, ViewerPose{});
    std::vector<double> detect_ms, view_ms;
    int tracked = 0;
    for (const CameraFrame& frame : camera_frames) {
        auto t0 = Clock::now();
        (void)detector.detect(frame.image);
        detect_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());

        t0 = Clock::now();
        const TrackedTag tag = tracker.track(frame);
        navigator.observe(tag_sample_of(tag));
        (void)navigator.advance(frame.timestamp_ns);
        view_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        tracked += tag.visible ? 1 : 0;
    }
    const double base = percentile(detect_ms, 0.5);
    std::printf("| stage (%zu frames 800x600, tag tracked in %d) | median ms | p95 ms | median / detection |\n",
                camera_frames.size(), tracked);
    std::printf("|---|--:|--:|--:|\n");
    std::printf("| AprilTag detection alone (baseline) | %.2f | %.2f | 1.00 |\n", base, percentile(detect_ms, 0.95));
    std::printf("| frame -> ViewerPose (detect + pose + disambiguation + One Euro + navigator) | %.2f | %.2f | %.2f |\n",
                percentile(view_ms, 0.5), percentile(view_ms, 0.95), percentile(view_ms, 0.5) / base);
    return 0;
}
