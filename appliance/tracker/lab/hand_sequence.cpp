// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/lab/hand_sequence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <stdexcept>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "appliance/tracker/tag_bitmap.h"
#include "appliance/tracker/tag_family.h"

namespace mogao {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kScriptSeconds = 12.0;  // the script's own time base

double smoothstep(double a, double b, double t) {
    const double x = std::clamp((t - a) / (b - a), 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
}

// Piecewise: value v0 until the first ramp; each ramp (start, end, to) eases to `to`.
struct Ramp {
    double start;
    double end;
    double to;
};
double scripted(double t, double v0, std::initializer_list<Ramp> ramps) {
    double v = v0;
    for (const Ramp& r : ramps) v += (r.to - v) * smoothstep(r.start, r.end, t);
    return v;
}

void check(const HandSequenceSpec& s) {
    const auto bad = [](const std::string& m) { throw std::invalid_argument("HandSequenceSpec." + m); };
    if (!(s.seconds > 0.0 && s.seconds <= 600.0)) bad("seconds outside (0, 600]");
    if (!(s.frames_per_second > 0.0 && s.frames_per_second <= 240.0)) bad("frames_per_second outside (0, 240]");
    if (!(s.tag_size_m > 0.0 && s.tag_size_m <= 1.0)) bad("tag_size_m outside (0, 1]");
    if (!(s.rest_distance_m > 0.05 && s.rest_distance_m <= 10.0)) bad("rest_distance_m outside (0.05, 10]");
    if (!(s.noise_sigma >= 0.0 && s.noise_sigma <= 50.0)) bad("noise_sigma outside [0, 50]");
    if (!(s.exposure_s >= 0.0 && s.exposure_s <= 0.1)) bad("exposure_s outside [0, 0.1]");
    validate(s.camera);
}

}  // namespace

HandFrame hand_frame_at(double t_s, const HandSequenceSpec& spec) {
    check(spec);
    const double u = t_s * kScriptSeconds / spec.seconds;  // script time
    HandFrame f;
    f.time_ns = std::llround(t_s * 1e9);
    f.visible = !(u >= 11.0 && u < 11.6);
    const double yaw = scripted(u, 0.0, {{1.5, 3.0, 25.0}, {4.5, 5.5, 0.0}, {9.0, 9.4, -30.0}, {10.2, 10.6, 0.0}});
    const double push = scripted(u, 0.0, {{6.0, 7.0, 0.12}, {8.0, 8.8, 0.0}});
    // Tremor in real time (its frequency does not scale with the script) and a slow drift.
    const double tremor = std::sin(kTwoPi * 9.3 * t_s) + 0.7 * std::sin(kTwoPi * 11.7 * t_s + 1.0);
    const double drift = std::sin(kTwoPi * 0.23 * t_s);
    f.yaw_deg = yaw + 0.3 * tremor + 1.0 * drift;
    f.pitch_deg = 0.25 * std::sin(kTwoPi * 8.1 * t_s + 2.0) + 1.5 * std::sin(kTwoPi * 0.17 * t_s + 0.5);
    f.roll_deg = 3.0 + 0.5 * drift;
    f.distance_m = spec.rest_distance_m - push + 0.0004 * tremor + 0.005 * drift;
    f.x_m = 0.0004 * std::sin(kTwoPi * 10.1 * t_s) + 0.01 * std::sin(kTwoPi * 0.11 * t_s);
    f.y_m = 0.0003 * std::sin(kTwoPi * 8.7 * t_s + 0.3);
    f.pose = tag_pose_facing_camera(f.distance_m, f.yaw_deg, f.pitch_deg, f.roll_deg, f.x_m, f.y_m);
    return f;
}

std::vector<HandFrame> hand_trajectory(const HandSequenceSpec& spec) {
    check(spec);
    const auto n = static_cast<std::size_t>(std::floor(spec.seconds * spec.frames_per_second));
    std::vector<HandFrame> frames;
    frames.reserve(n);
    for (std::size_t i = 0; i < n; ++i)
        frames.push_back(hand_frame_at(static_cast<double>(i) / spec.frames_per_second, spec));
    return frames;
}

void write_hand_sequence(const std::filesystem::path& folder, const HandSequenceSpec& spec) {
    const auto frames = hand_trajectory(spec);
    std::filesystem::create_directories(folder);
    const TagFamily family(spec.family);
    const PlanarTarget target = tag_target(make_tag_bitmap(family, spec.tag_id), spec.tag_size_m);
    nlohmann::json truth{{"tag", {{"family", spec.family}, {"id", spec.tag_id}, {"size_m", spec.tag_size_m}}},
                         {"frames_per_second", spec.frames_per_second},
                         {"frames", nlohmann::json::array()}};
    std::ofstream stamps(folder / "timestamps.txt");
    for (std::size_t i = 0; i < frames.size(); ++i) {
        const HandFrame& f = frames[i];
        char name[32];
        std::snprintf(name, sizeof name, "frame-%05zu.png", i);
        RenderEffects fx;
        fx.noise_sigma = spec.noise_sigma;
        fx.seed = spec.seed * 1'000'003 + i;
        fx.supersample = 4;           // a sequence has hundreds of frames; 1/8 px edges are plenty
        fx.clutter_seed = spec.seed;  // the same room behind the visitor in every frame
        // Motion blur: how far the tag centre's image moved during the exposure.
        const double t = static_cast<double>(f.time_ns) * 1e-9;
        const HandFrame before = hand_frame_at(std::max(0.0, t - spec.exposure_s), spec);
        const auto c1 = project_tag_corners(f.pose, spec.camera, spec.tag_size_m);
        const auto c0 = project_tag_corners(before.pose, spec.camera, spec.tag_size_m);
        Eigen::Vector2d motion = Eigen::Vector2d::Zero();
        for (std::size_t k = 0; k < 4; ++k) motion += (c1[k] - c0[k]) / 4.0;
        if (motion.norm() > 0.3) {
            fx.motion_blur_px = std::min(motion.norm(), 100.0);
            fx.motion_blur_deg = std::atan2(motion.y(), motion.x()) * 180.0 / std::numbers::pi;
        }
        // A hidden tag: the hand took it out of view; the camera sees the background only.
        // (Rendered as a card the colour of the background, so the image statistics stay alike.)
        if (!f.visible) fx.black = fx.white = fx.background;
        const GrayImage image = render_target(target, f.pose, spec.camera, fx);
        const cv::Mat mat(image.height, image.width, CV_8UC1, const_cast<std::uint8_t*>(image.pixels.data()));
        const auto path = folder / name;
        if (!cv::imwrite(path.string(), mat)) throw std::runtime_error(path.string() + ": cannot be written");
        stamps << f.time_ns << '\n';
        std::vector<double> r;
        for (int a = 0; a < 3; ++a) {
            for (int b = 0; b < 3; ++b) r.push_back(f.pose.rotation(a, b));
        }
        truth["frames"].push_back(
            {{"file", name},
             {"time_ns", f.time_ns},
             {"visible", f.visible},
             {"yaw_deg", f.yaw_deg},
             {"pitch_deg", f.pitch_deg},
             {"distance_m", f.distance_m},
             {"x_m", f.x_m},
             {"rotation", r},
             {"translation_m", {f.pose.translation_m.x(), f.pose.translation_m.y(), f.pose.translation_m.z()}}});
    }
    if (!stamps) throw std::runtime_error((folder / "timestamps.txt").string() + ": cannot be written");
    std::ofstream(folder / "truth.json") << truth.dump(1) << '\n';
    write_intrinsics(folder / "camera.json", spec.camera);
}

}  // namespace mogao
