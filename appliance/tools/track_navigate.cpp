// SPDX-License-Identifier: Apache-2.0
// mogao-track navigate: frames from a replay folder or a V4L2 camera -> TagTracker -> Navigator ->
// ViewerPose at the display rate, as JSON lines. With the folder's truth.json (mogao-tag-sequence), also prints how
// far the tracker's yaw and distance were from the truth: the noise the One Euro filter is tuned
// for (docs/tracking.md).
#include <time.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "appliance/navigation/navigator.h"
#include "appliance/navigation/tag_sample_of.h"
#include "appliance/tools/track_commands.h"
#include "appliance/tracker/tag_tracker.h"
#include "drivers/camera/camera_source.h"

namespace mogao::track {
namespace {

// Running mean and standard deviation (Welford).
struct Stats {
    int n = 0;
    double mean = 0.0;
    double m2 = 0.0;
    void add(double x) {
        ++n;
        const double d = x - mean;
        mean += d / n;
        m2 += d * (x - mean);
    }
    [[nodiscard]] double sd() const { return n > 1 ? std::sqrt(m2 / (n - 1)) : 0.0; }
};

// CPU time of the calling thread (ms): what tracking costs, whatever else the machine runs.
double thread_cpu_ms() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// The frame source: the replay folder, or the camera --camera names at the calibration's size. Returns 0, or the
// exit status (2: a camera that is no capture device) after the message.
int source_spec(const NavigateOptions& o, const CameraIntrinsics& camera, CameraSourceSpec& spec) {
    if (o.device.empty()) {
        spec.kind = CameraSourceSpec::Kind::replay;
        spec.folder = o.replay;
        spec.replay_fps = o.fps;
    } else {
        // "/dev/videoN" alone is V4L2; otherwise any camera the kiosk accepts (v4l2:, libcamera:).
        const std::string named = o.device.starts_with("/") ? "v4l2:" + o.device : o.device;
        std::string why;
        if (!parse_camera_source(named, spec, &why) || spec.kind == CameraSourceSpec::Kind::replay) {
            std::fprintf(stderr, "mogao-track navigate: --camera '%s': %s\n", o.device.c_str(),
                         why.empty() ? "give /dev/videoN, v4l2:/dev/videoN or libcamera:[<id>]" : why.c_str());
            return 2;
        }
        spec.width = camera.width;  // the calibrated size; the tracker refuses any other
        spec.height = camera.height;
    }
    return 0;
}

// One display tick's pose as a JSON line.
void write_pose(std::ostream& out, std::int64_t t_ns, const ViewerPose& p, const Navigator& navigator) {
    out << nlohmann::json{{"t_ns", t_ns},
                          {"eye", {p.eye.x(), p.eye.y(), p.eye.z()}},
                          {"yaw_deg", p.yaw_deg},
                          {"pitch_deg", p.pitch_deg},
                          {"tracking", navigator.tracking()},
                          {"turn_deg_s", navigator.velocity().turn_deg_s},
                          {"forward_m_s", navigator.velocity().forward_m_s}}
               .dump()
        << '\n';
}

// The tracked tag's yaw and distance against truth.json's frame `f` (mogao-tag-sequence's rotation and translation).
void add_truth_errors(const nlohmann::json& f, const TrackedTag& tag, Stats& yaw_error, Stats& distance_error_mm) {
    const ControlSignals measured = control_signals(tag.pose.rotation, tag.pose.translation_m);
    Eigen::Matrix3d r;
    for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = f["rotation"][static_cast<std::size_t>(i)].get<double>();
    const Eigen::Vector3d t(f["translation_m"][0].get<double>(), f["translation_m"][1].get<double>(),
                            f["translation_m"][2].get<double>());
    const ControlSignals expected = control_signals(r, t);
    yaw_error.add(measured.yaw_deg - expected.yaw_deg);
    distance_error_mm.add((measured.distance_m - expected.distance_m) * 1000.0);
}

}  // namespace

int navigate(const NavigateOptions& o) {
    TrackerConfig config;
    config.detector = o.detector;
    config.roi.enabled = o.roi;
    config.roi.window_tag_px = o.window_tag_px;
    config.camera = read_intrinsics(o.camera.empty() ? o.replay / "camera.json" : o.camera);
    CameraSourceSpec spec;
    if (const int status = source_spec(o, config.camera, spec); status != 0) return status;
    auto opened = open_camera_source(spec);
    if (!opened) {
        std::fprintf(stderr, "mogao-track navigate: %s\n", opened.error().message.c_str());
        return 1;
    }
    std::unique_ptr<FrameSource> source = std::move(opened).value();
    std::fprintf(stderr, "source: %s\n", source->description().c_str());
    config.tag_size_m = o.tag_size_mm / 1000.0;
    config.tag_id = o.id;
    TagTracker tracker(config);
    Navigator navigator(NavigationParams{}, ViewerPose{});

    nlohmann::json truth;
    if (std::ifstream in(o.replay / "truth.json"); !o.replay.empty() && in)
        truth = nlohmann::json::parse(in, nullptr, false);
    std::ofstream file;
    if (!o.out.empty()) {
        file.open(o.out);
        if (!file) {
            std::fprintf(stderr, "mogao-track navigate: cannot write %s\n", o.out.string().c_str());
            return 1;
        }
    }
    std::ostream& out = o.out.empty() ? std::cout : file;

    const auto period = static_cast<std::int64_t>(std::llround(1e9 / o.display_hz));
    std::int64_t next_display = 0;
    bool started = false;
    int frames = 0, visible = 0, ambiguous = 0, poses = 0;
    double tracking_cpu_ms = 0.0;
    Stats yaw_error, distance_error_mm;
    for (;;) {
        auto frame = source->next_frame();
        if (!frame) {
            if (frame.code() == ENODATA) break;
            std::fprintf(stderr, "mogao-track navigate: %s\n", frame.error().message.c_str());
            if (frame.code() == EBADMSG) continue;
            return 1;
        }
        // Display frames due before this capture see only the samples captured before them.
        if (!started) {
            next_display = frame->timestamp_ns;
            started = true;
        }
        for (; next_display < frame->timestamp_ns; next_display += period, ++poses) {
            write_pose(out, next_display, navigator.advance(next_display), navigator);
        }
        const double cpu_before = thread_cpu_ms();
        const TrackedTag tag = tracker.track(*frame);
        tracking_cpu_ms += thread_cpu_ms() - cpu_before;
        navigator.observe(tag_sample_of(tag));
        const std::size_t index = static_cast<std::size_t>(frames++);
        visible += tag.visible ? 1 : 0;
        ambiguous += tag.ambiguous ? 1 : 0;
        if (tag.visible && truth.is_object() && index < truth["frames"].size())
            add_truth_errors(truth["frames"][index], tag, yaw_error, distance_error_mm);
    }
    std::fprintf(
        stderr,
        "%d frames, tag visible in %d (%d ambiguous), %d samples rejected by the flip gate, %d poses at %.0f Hz\n",
        frames, visible, ambiguous, navigator.rejected_samples(), poses, o.display_hz);
    std::fprintf(stderr, "tracking: %.2f ms CPU per frame (TagTracker::track, this thread's CPU time)\n",
                 frames > 0 ? tracking_cpu_ms / frames : 0.0);
    if (yaw_error.n > 0) {
        std::fprintf(stderr,
                     "against truth.json: yaw error mean %+.3f sd %.3f deg; distance error mean %+.2f sd %.2f mm\n",
                     yaw_error.mean, yaw_error.sd(), distance_error_mm.mean, distance_error_mm.sd());
    }
    return 0;
}

}  // namespace mogao::track
