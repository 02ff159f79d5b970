// SPDX-License-Identifier: Apache-2.0
// mogao_small_tag_study: what DetectorSettings::upsample_pass_factor buys on tags too small for the
// full-resolution search, on synthetic ground truth (docs/tracking.md, "Small tags"). Not a test:
// prints a markdown table; time is a ratio against the detector without the pass, same images.
//
// Frames: 640x480, f = 500 px, no distortion (ideal_camera); one tag36h11 tag of a random id at a
// random hand-held pose (yaw and pitch within +-45 deg, any roll), its distance chosen so that its
// longest side spans the row's width in pixels, on a white card in front of a cluttered room;
// Gaussian noise sigma 3 grey levels, motion blur up to 1.5 px. A detection is correct when its id
// is the tag's and its centre within half a side of the truth; any other detection is wrong. The
// last row renders the same room without a tag: every detection there is wrong.
//
//   mogao_small_tag_study [--frames N] [--seed S]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "appliance/tracker/lab/synthetic_view.h"
#include "appliance/tracker/tag_bitmap.h"
#include "appliance/tracker/tag_detector.h"
#include "appliance/tracker/tag_pose.h"

namespace mogao {
namespace {

constexpr double kTagSize = 0.10;

struct Tally {
    int frames = 0;
    int correct = 0;
    int wrong = 0;
    double min_correct_margin = 1e9;
    double max_wrong_margin = 0.0;
    double ms = 0.0;
};

double uniform(std::mt19937& rng, double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }

struct Frame {
    GrayImage image;
    int id = -1;  // -1: no tag
    Eigen::Vector2d centre{0, 0};
    double side_px = 0.0;
};

Frame make_frame(std::mt19937& rng, const TagFamily& family, double width_px) {
    const CameraIntrinsics cam = ideal_camera(640, 480, 500.0);
    RenderEffects fx;
    fx.seed = rng();
    fx.clutter_seed = 1 + rng() % 1000;
    fx.noise_sigma = 3.0;
    fx.motion_blur_px = uniform(rng, 0.0, 1.5);
    fx.motion_blur_deg = uniform(rng, 0.0, 180.0);
    Frame f;
    const int id = static_cast<int>(rng() % static_cast<unsigned>(family.code_count()));
    const PlanarTarget target = tag_target(make_tag_bitmap(family, id), kTagSize);
    const double yaw = uniform(rng, -45, 45), pitch = uniform(rng, -45, 45), roll = uniform(rng, -180, 180);
    // The distance at which the tag faces the camera with this width; turned, it is narrower.
    const double d = 500.0 * kTagSize / std::max(width_px, 1.0);
    const TagPose pose =
        tag_pose_facing_camera(d, yaw, pitch, roll, uniform(rng, -0.3, 0.3) * d, uniform(rng, -0.2, 0.2) * d);
    if (width_px <= 0.0) {  // the room alone: the tag far behind the camera's field of view
        fx.supersample = 1;
        f.image = render_target(target, tag_pose_facing_camera(1000.0, 0, 0, 0, 5000.0, 0.0), cam, fx);
        return f;
    }
    f.image = render_target(target, pose, cam, fx);
    const auto corners = project_tag_corners(pose, cam, kTagSize);
    f.id = id;
    f.centre = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
    for (std::size_t k = 0; k < 4; ++k) f.side_px = std::max(f.side_px, (corners[k] - corners[(k + 1) % 4]).norm());
    return f;
}

std::string fmt_margin(double m) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", m);
    return text;
}

void score(const Frame& f, const std::vector<TagDetection>& found, Tally& t) {
    ++t.frames;
    bool hit = false;
    for (const auto& d : found) {
        const bool ok = !hit && d.id == f.id && (d.centre - f.centre).norm() < 0.5 * f.side_px;
        if (ok) {
            hit = true;
            ++t.correct;
            t.min_correct_margin = std::min<double>(t.min_correct_margin, d.decision_margin);
        } else {
            ++t.wrong;
            t.max_wrong_margin = std::max<double>(t.max_wrong_margin, d.decision_margin);
        }
    }
}

}  // namespace
}  // namespace mogao

int main(int argc, char** argv) {
    using namespace mogao;
    CLI::App app{"mogao_small_tag_study: the up-sampled search on small synthetic tags"};
    int frames = 60;
    unsigned seed = 7;
    app.add_option("--frames", frames, "frames per row")->check(CLI::Range(1, 10000))->capture_default_str();
    app.add_option("--seed", seed, "random seed")->capture_default_str();
    CLI11_PARSE(app, argc, argv);

    DetectorSettings without;
    without.upsample_pass_factor = 0;
    std::vector<std::pair<std::string, DetectorSettings>> settings = {{"without (coarse pass only)", without}};
    const DetectorSettings defaults;
    for (const auto& [factor, sharpening] : {std::pair{2, 0.25}, {2, 1.0}, {3, 0.25}, {3, 1.0}, {4, 1.0}}) {
        DetectorSettings s;
        s.upsample_pass_factor = factor;
        s.upsample_pass_sharpening = sharpening;
        const bool is_default =
            factor == defaults.upsample_pass_factor && sharpening == defaults.upsample_pass_sharpening;
        char name[64];
        std::snprintf(name, sizeof name, "x%d, sharpening %.2g%s", factor, sharpening, is_default ? " (default)" : "");
        settings.emplace_back(name, s);
    }
    std::vector<TagDetector> detectors;
    for (const auto& [name, s] : settings) detectors.emplace_back(s);
    const TagFamily family("tag36h11");

    std::printf("| tag width (px) | frames |");
    for (const auto& [name, s] : settings) std::printf(" %s: correct, wrong |", name.c_str());
    std::printf(" time of each up-sampled setting / without |\n|--:|--:|");
    for (std::size_t k = 0; k < settings.size(); ++k) std::printf("--:|");
    std::printf("--:|\n");
    std::vector<Tally> overall(settings.size());
    for (double width : {8.0, 10.0, 12.0, 14.0, 16.0, 20.0, 24.0, 32.0, 0.0}) {
        std::mt19937 rng(seed + static_cast<unsigned>(width * 10));
        std::vector<Tally> row(settings.size());
        for (int i = 0; i < frames; ++i) {
            const Frame f = make_frame(rng, family, width);
            for (std::size_t k = 0; k < settings.size(); ++k) {
                const auto t0 = std::chrono::steady_clock::now();
                const auto found = detectors[k].detect(f.image);
                row[k].ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
                score(f, found, row[k]);
                score(f, found, overall[k]);
            }
        }
        if (width > 0.0) std::printf("| %.0f | %d |", width, frames);
        else std::printf("| no tag | %d |", frames);
        for (const auto& t : row) std::printf(" %d, %d |", t.correct, t.wrong);
        for (std::size_t k = 1; k < row.size(); ++k) std::printf("%s%.1f", k == 1 ? " " : ", ", row[k].ms / row[0].ms);
        std::printf(" |\n");
    }
    std::printf("\nDecision margins (AprilTag's): ");
    for (std::size_t k = 0; k < settings.size(); ++k) {
        const std::string wrong =
            overall[k].wrong > 0 ? "highest " + fmt_margin(overall[k].max_wrong_margin) : std::string("none");
        std::printf("%s: lowest correct %.1f, wrong %s; ", settings[k].first.c_str(), overall[k].min_correct_margin,
                    wrong.c_str());
    }
    std::printf("\n");
    return 0;
}
