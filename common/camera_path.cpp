// SPDX-License-Identifier: Apache-2.0
#include "common/camera_path.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace mogao {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

struct Keyframe {
    Eigen::Vector3d floor;
    double yaw_deg;
    double pitch_deg;
};

// Yaw that looks from `from` toward `to` (yaw 0 looks along -z, positive turns toward -x).
double yaw_toward(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
    const Eigen::Vector3d d = to - from;
    return std::atan2(-d.x(), -d.z()) * kDeg;
}

// Spreads frames evenly over the path's length so the visitor moves at a constant pace: a segment's
// length is its floor distance plus 1 m per 90 degrees of turn (so turning on the spot takes time too).
std::vector<ViewerPose> sample(const std::vector<Keyframe>& keys, const Viewer& viewer, int frames) {
    std::vector<double> along{0.0};
    for (std::size_t k = 1; k < keys.size(); ++k) {
        const double turn = std::abs(std::remainder(keys[k].yaw_deg - keys[k - 1].yaw_deg, 360.0)) +
                            std::abs(keys[k].pitch_deg - keys[k - 1].pitch_deg);
        along.push_back(along.back() + (keys[k].floor - keys[k - 1].floor).norm() + turn / 90.0);
    }
    std::vector<ViewerPose> poses;
    poses.reserve(static_cast<std::size_t>(frames));
    std::size_t i = 0;
    for (int f = 0; f < frames; ++f) {
        const double s = frames == 1 ? 0.0 : along.back() * f / (frames - 1);
        while (i + 2 < keys.size() && along[i + 1] < s) ++i;
        const std::size_t j = std::min(i + 1, keys.size() - 1);
        const double length = along[j] - along[i];
        const double t = length > 0 ? std::clamp((s - along[i]) / length, 0.0, 1.0) : 0.0;
        const Keyframe& a = keys[i];
        const Keyframe& b = keys[j];
        const double dyaw = std::remainder(b.yaw_deg - a.yaw_deg, 360.0);
        ViewerPose pose;
        pose.eye = a.floor + t * (b.floor - a.floor) + Eigen::Vector3d(0, viewer.eye_height_m, 0);
        pose.yaw_deg = a.yaw_deg + t * dyaw;
        pose.pitch_deg = a.pitch_deg + t * (b.pitch_deg - a.pitch_deg);
        poses.push_back(pose);
    }
    return poses;
}

}  // namespace

std::vector<ViewerPose> make_camera_path(const std::string& name_or_file, const Viewer& viewer, int frames) {
    if (frames < 1 || frames > 1'000'000) throw PathError(fmt::format("frames = {} is outside [1, 1000000]", frames));
    const Eigen::Vector3d start = viewer.start;
    const Eigen::Vector3d centre(0, start.y(), 0);
    const double radius = std::hypot(start.x(), start.z());
    const double start_angle = std::atan2(start.x(), start.z());  // 0 = +z
    const auto on_circle = [&](double r, double angle) {
        return Eigen::Vector3d(r * std::sin(angle), start.y(), r * std::cos(angle));
    };
    std::vector<Keyframe> keys;
    if (name_or_file == "orbit") {
        if (radius < 1e-6) throw PathError("orbit: the viewer's start is on the centre; nothing to orbit around");
        const int steps = 64;  // fine enough that linear interpolation stays on the circle
        for (int k = 0; k <= steps; ++k) {
            const Eigen::Vector3d p = on_circle(radius, start_angle + 2 * std::numbers::pi * k / steps);
            keys.push_back({p, yaw_toward(p, centre), 0.0});
        }
        return sample(keys, viewer, frames);
    }
    if (name_or_file == "walk") {
        // Walk in looking ahead, stop at 0.6 of the distance, then circle 240° around the centre
        // while looking at it: a visitor's first minute in the grotto.
        keys.push_back({start, viewer.start_yaw_deg, 0.0});
        const double inner = std::max(0.6 * radius, 1.0);
        const Eigen::Vector3d near = on_circle(inner, start_angle);
        keys.push_back({near, yaw_toward(near, centre), 0.0});
        const int steps = 24;
        for (int k = 1; k <= steps; ++k) {
            const Eigen::Vector3d p = on_circle(inner, start_angle - (4.0 / 3.0) * std::numbers::pi * k / steps);
            keys.push_back({p, yaw_toward(p, centre), k == steps / 2 ? 8.0 : 0.0});
        }
        return sample(keys, viewer, frames);
    }
    return read_path_file(name_or_file, viewer, frames);
}

std::vector<ViewerPose> read_path_file(const std::filesystem::path& file, const Viewer& viewer, int frames) {
    if (frames < 1 || frames > 1'000'000) throw PathError(fmt::format("frames = {} is outside [1, 1000000]", frames));
    std::ifstream in(file);
    if (!in)
        throw PathError(
            fmt::format("{}: cannot open path file (expected walk, orbit or a JSON path file)", file.string()));
    nlohmann::json root;
    try {
        root = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        throw PathError(fmt::format("{}: not valid JSON: {}", file.string(), e.what()));
    }
    const auto fail = [&](const std::string& field, const std::string& what) {
        throw PathError(fmt::format("{}: {}: {}", file.string(), field, what));
    };
    if (!root.is_object() || !root.contains("keyframes") || !root["keyframes"].is_array() || root["keyframes"].empty())
        fail("keyframes", "expected a non-empty array");
    std::vector<Keyframe> keys;
    for (std::size_t i = 0; i < root["keyframes"].size(); ++i) {
        const auto& k = root["keyframes"][i];
        const std::string field = fmt::format("keyframes[{}]", i);
        if (!k.is_object() || !k.contains("position") || !k["position"].is_array() || k["position"].size() != 3)
            fail(field + ".position", "expected an array of 3 numbers");
        Keyframe key{};
        for (int c = 0; c < 3; ++c) {
            const auto& v = k["position"][static_cast<std::size_t>(c)];
            if (!v.is_number() || !std::isfinite(v.get<double>()) || std::abs(v.get<double>()) > 1e9)
                fail(fmt::format("{}.position[{}]", field, c), "expected a finite number within ±1e9");
            key.floor[c] = v.get<double>();
        }
        for (const char* angle : {"yaw_deg", "pitch_deg"}) {
            if (!k.contains(angle)) continue;
            const auto& v = k[angle];
            if (!v.is_number() || !std::isfinite(v.get<double>()) || std::abs(v.get<double>()) > 3600)
                fail(field + "." + angle, "expected a finite number within ±3600");
        }
        key.yaw_deg = k.value("yaw_deg", 0.0);
        key.pitch_deg = k.value("pitch_deg", 0.0);
        if (std::abs(key.pitch_deg) > 89) fail(field + ".pitch_deg", "must be within ±89 degrees");
        keys.push_back(key);
    }
    return sample(keys, viewer, frames);
}

}  // namespace mogao
