// SPDX-License-Identifier: Apache-2.0
// mogao_tracking_eval roi: region-of-interest tracking against whole-frame detection on the
// hand-held sequence (hand_sequence.h), every mode over the same frames in the same run.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include "appliance/tracker/lab/hand_sequence.h"
#include "appliance/tracker/lab/synthetic_view.h"
#include "appliance/tracker/lab/tag_reference.h"
#include "appliance/tracker/lab/tracking_eval.h"
#include "appliance/tracker/tag_tracker.h"
#include "drivers/camera/image_file.h"

namespace mogao::eval {
namespace {

struct Mode {
    std::string name;
    TrackerConfig config;
};

struct ModeResult {
    int visible = 0, detected = 0, lost = 0, false_detections = 0;
    long full_searches = 0;
    std::vector<double> ms;  // per frame, fastest pass
    std::vector<double> corner_errors_px;
};

double quantile(std::vector<double> v, double q) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

ModeResult run_mode(const Mode& mode, const std::vector<CameraFrame>& frames, const std::vector<HandFrame>& truth,
                    const HandSequenceSpec& spec, int repeat) {
    ModeResult r;
    r.ms.assign(frames.size(), 1e300);
    for (int pass = 0; pass < repeat; ++pass) {
        TagTracker tracker(mode.config);
        for (std::size_t i = 0; i < frames.size(); ++i) {
            const auto t0 = std::chrono::steady_clock::now();
            const TrackedTag tag = tracker.track(frames[i]);
            r.ms[i] = std::min(
                r.ms[i], std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            if (pass > 0) continue;
            const bool visible = truth[i].visible;
            r.visible += visible ? 1 : 0;
            if (tag.visible && (!visible || tag.id != spec.tag_id)) ++r.false_detections;
            if (visible && !(tag.visible && tag.id == spec.tag_id)) ++r.lost;
            if (!visible || !tag.visible || tag.id != spec.tag_id) continue;
            ++r.detected;
            const auto c = project_tag_corners(truth[i].pose, spec.camera, spec.tag_size_m);
            for (std::size_t k = 0; k < 4; ++k) r.corner_errors_px.push_back((tag.detection.corners[k] - c[k]).norm());
        }
        if (pass == 0) r.full_searches = tracker.full_searches();
    }
    return r;
}

}  // namespace

int run_roi(const RoiOptions& options) {
    HandSequenceSpec spec;
    spec.seconds = options.seconds;
    const auto folder = std::filesystem::temp_directory_path() / ("mogao-roi-eval-" + std::to_string(::getpid()));
    write_hand_sequence(folder, spec);  // as `mogao-tag-sequence`
    const auto all_truth = hand_trajectory(spec);
    std::vector<HandFrame> truth;  // every `stride`-th frame, as a busy tracker that skips frames sees them
    std::vector<CameraFrame> frames;
    for (std::size_t i = 0; i < all_truth.size(); i += static_cast<std::size_t>(options.stride)) {
        truth.push_back(all_truth[i]);
        char name[32];
        std::snprintf(name, sizeof name, "frame-%05zu.png", i);
        auto image = read_gray_image(folder / name);
        if (!image) throw std::runtime_error(image.error().message);
        CameraFrame f;
        f.image = std::move(*image);
        f.timestamp_ns = all_truth[i].time_ns;
        frames.push_back(std::move(f));
    }
    std::filesystem::remove_all(folder);

    std::vector<Mode> modes(4);
    modes[0].name = "full frame, full resolution (defaults; baseline)";
    modes[0].config.roi.enabled = false;
    modes[1].name = "full frame, old defaults (2, 0.8)";
    modes[1].config.roi.enabled = false;
    modes[1].config.detector.decimation = 2.0f;
    modes[1].config.detector.blur_sigma = 0.8f;
    modes[2].name = "ROI, window at full resolution (window_tag_px 0)";
    modes[2].config.roi.window_tag_px = 0.0;
    const auto px_name = [](double px) {
        char text[64];
        std::snprintf(text, sizeof text, "window_tag_px %g", px);
        return std::string(text);
    };
    modes[3].name = "ROI tracking (defaults: " + px_name(RoiSettings{}.window_tag_px) + ")";
    for (const double px : options.window_tag_px) {
        Mode m;
        m.name = "ROI, " + px_name(px);
        m.config.roi.window_tag_px = px;
        modes.push_back(m);
    }
    for (auto& m : modes) m.config.camera = spec.camera;

    std::printf(
        "| mode | frames with the tag | detected | lost | false | whole-frame searches | mean ms/frame | median ms | "
        "p95 ms | max ms | mean/baseline | corner error median (px) | max (px) |\n");
    std::printf("|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n");
    double baseline = 0.0;
    for (const auto& mode : modes) {
        const ModeResult r = run_mode(mode, frames, truth, spec, options.repeat);
        double mean = 0.0;
        for (const double ms : r.ms) mean += ms / static_cast<double>(r.ms.size());
        if (baseline == 0.0) baseline = mean;
        std::printf("| %s | %d | %d | %d | %d | %ld | %.2f | %.2f | %.2f | %.2f | %.3f | %.3f | %.3f |\n",
                    mode.name.c_str(), r.visible, r.detected, r.lost, r.false_detections, r.full_searches, mean,
                    quantile(r.ms, 0.5), quantile(r.ms, 0.95), quantile(r.ms, 1.0), mean / baseline,
                    quantile(r.corner_errors_px, 0.5), quantile(r.corner_errors_px, 1.0));
    }
    std::printf(
        "\n%zu frames of %.0fx%.0f px (every %d. of %.1f s at %.0f fps); time: fastest of %d passes per frame.\n",
        frames.size(), static_cast<double>(spec.camera.width), static_cast<double>(spec.camera.height), options.stride,
        spec.seconds, spec.frames_per_second, options.repeat);
    return 0;
}

}  // namespace mogao::eval
