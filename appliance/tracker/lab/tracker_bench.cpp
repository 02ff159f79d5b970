// SPDX-License-Identifier: Apache-2.0
// Tracker accuracy and speed on synthetic ground truth (docs/tracking.md, "Measurements"). Not a
// test: prints markdown tables; every speed figure is a ratio against the default settings
// measured in the same run.
//
//   1. Per scenario (random poses around a nominal one, seeded): detection rate, corner error
//      (px, against the projected truth), pose error of the best IPPE solution (mm, degrees).
//   2. Detection time per 800x600 frame with the default settings (median).
//   3. The speed/accuracy trade of the settings (the extra passes, decimation and blur): time,
//      corner error and detection rate relative to the defaults, on the same images; --csv FILE
//      writes it for bench/tracking-eval's plot.
//
// Camera: 800x600, f = 700 px, no distortion; tag36h11, 10 cm on a white card, in front of a
// cluttered background (synthetic_view.h). Usage:
//   mogao_tracker_bench [--frames N] [--quick] [--csv FILE]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "appliance/tracker/lab/synthetic_view.h"
#include "appliance/tracker/tag_detector.h"
#include "appliance/tracker/tag_pose.h"

namespace mogao {
namespace {

constexpr double kTagSize = 0.10;
constexpr int kTagId = 7;

struct Sample {
    GrayImage image;
    TagPose truth;
    std::array<Eigen::Vector2d, 4> corners;  // truth, AprilTag convention
    double width_px;                         // longest side of the projected tag
};

struct Scenario {
    std::string name;
    std::function<Sample(std::mt19937&, const PlanarTarget&)> make;
};

double uniform(std::mt19937& rng, double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
double sign(std::mt19937& rng) { return uniform(rng, 0.0, 1.0) < 0.5 ? -1.0 : 1.0; }

Sample render(const PlanarTarget& target, const TagPose& pose, const RenderEffects& fx) {
    const CameraIntrinsics cam = ideal_camera();
    Sample s{render_target(target, pose, cam, fx), pose, project_tag_corners(pose, cam, kTagSize), 0.0};
    for (std::size_t k = 0; k < 4; ++k)
        s.width_px = std::max(s.width_px, (s.corners[k] - s.corners[(k + 1) % 4]).norm());
    return s;
}

// A hand-held pose: distance d, yaw/pitch within +-a degrees, any roll, off-centre.
TagPose hand_pose(std::mt19937& rng, double d, double a) {
    return tag_pose_facing_camera(d, uniform(rng, -a, a), uniform(rng, -a, a), uniform(rng, -180, 180),
                                  uniform(rng, -0.12, 0.12) * d, uniform(rng, -0.08, 0.08) * d);
}

// Noise seeded per image; every image has the same cluttered room behind the tag.
RenderEffects fx_seeded(std::mt19937& rng) {
    RenderEffects fx;
    fx.seed = rng();
    fx.clutter_seed = 42;
    return fx;
}

std::vector<Scenario> scenarios() {
    std::vector<Scenario> s;
    s.push_back({"frontal, 0.5 m (~140 px)", [](std::mt19937& r, const PlanarTarget& t) {
                     return render(t, hand_pose(r, 0.5, 10), fx_seeded(r));
                 }});
    s.push_back({"turned 45 deg, 0.5 m", [](std::mt19937& r, const PlanarTarget& t) {
                     return render(
                         t, tag_pose_facing_camera(0.5, 45 * sign(r), uniform(r, -10, 10), uniform(r, -180, 180)),
                         fx_seeded(r));
                 }});
    s.push_back({"tilted 70 deg, 0.4 m", [](std::mt19937& r, const PlanarTarget& t) {
                     const bool yaw = uniform(r, 0, 1) < 0.5;
                     return render(t,
                                   tag_pose_facing_camera(0.4, yaw ? 70 * sign(r) : 0, yaw ? 0 : 70 * sign(r),
                                                          uniform(r, -180, 180)),
                                   fx_seeded(r));
                 }});
    s.push_back({"small: ~20 px at 3.5 m", [](std::mt19937& r, const PlanarTarget& t) {
                     return render(t, hand_pose(r, 3.5, 20), fx_seeded(r));
                 }});
    s.push_back({"motion blur 8 px, 0.5 m", [](std::mt19937& r, const PlanarTarget& t) {
                     RenderEffects fx = fx_seeded(r);
                     fx.motion_blur_px = 8.0;
                     fx.motion_blur_deg = uniform(r, 0, 180);
                     return render(t, hand_pose(r, 0.5, 20), fx);
                 }});
    s.push_back({"sensor noise sigma 10, 0.5 m", [](std::mt19937& r, const PlanarTarget& t) {
                     RenderEffects fx = fx_seeded(r);
                     fx.noise_sigma = 10.0;
                     return render(t, hand_pose(r, 0.5, 20), fx);
                 }});
    s.push_back({"low contrast 110/150 + noise 2, 0.5 m", [](std::mt19937& r, const PlanarTarget& t) {
                     RenderEffects fx = fx_seeded(r);
                     fx.black = 110;
                     fx.white = 150;
                     fx.background = 130;
                     fx.noise_sigma = 2.0;
                     return render(t, hand_pose(r, 0.5, 20), fx);
                 }});
    s.push_back({"occluded: finger over one edge, 0.5 m", [](std::mt19937& r, const PlanarTarget& t) {
                     const TagPose pose = hand_pose(r, 0.5, 20);
                     const auto c = project_tag_corners(pose, ideal_camera(), kTagSize);
                     const auto k = static_cast<std::size_t>(r() % 4);
                     // A disc over the middle of one edge, a fifth of the side across, partly
                     // covering the black border and the data cells next to it.
                     const Eigen::Vector2d mid = (c[k] + c[(k + 1) % 4]) / 2.0;
                     const double side = (c[k] - c[(k + 1) % 4]).norm();
                     RenderEffects fx = fx_seeded(r);
                     fx.occluders.push_back({mid, 0.1 * side, 150.0});
                     return render(t, pose, fx);
                 }});
    s.push_back({"hand-held: 0.6 m, 30 deg, blur 3 px, noise 4", [](std::mt19937& r, const PlanarTarget& t) {
                     RenderEffects fx = fx_seeded(r);
                     fx.motion_blur_px = 3.0;
                     fx.motion_blur_deg = uniform(r, 0, 180);
                     fx.noise_sigma = 4.0;
                     return render(t, hand_pose(r, 0.6, 30), fx);
                 }});
    return s;
}

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return std::nan("");
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(std::lround(p * static_cast<double>(v.size() - 1)))];
}

struct Outcome {
    int found = 0;
    int wrong = 0;  // detections of another id: false positives
    std::vector<double> corner_px, translation_mm, rotation_deg, time_ms;
};

// Scores one sample's detections into `o` (the first detection of the tag's id; other ids are
// false positives).
void score(const Sample& s, const std::vector<TagDetection>& found, Outcome& o) {
    for (const TagDetection& d : found) {
        if (d.id != kTagId) {
            ++o.wrong;
            continue;
        }
        ++o.found;
        for (std::size_t k = 0; k < 4; ++k) o.corner_px.push_back((d.corners[k] - s.corners[k]).norm());
        const TagPose best = solve_tag_pose(d.corners, ideal_camera(), kTagSize)[0];
        o.translation_mm.push_back((best.translation_m - s.truth.translation_m).norm() * 1000.0);
        o.rotation_deg.push_back(rotation_angle_deg(best.rotation, s.truth.rotation));
        break;
    }
}

// Detects every sample with each of `settings`, interleaved (every setting in turn on each image,
// so the load of a shared machine biases none of them); each image is detected `repeats` times per
// setting and the fastest time kept (the minimum is the least disturbed).
std::vector<Outcome> run(const std::vector<Sample>& samples, const std::vector<DetectorSettings>& settings,
                         int repeats) {
    std::vector<TagDetector> detectors;
    for (const DetectorSettings& s : settings) detectors.emplace_back(s);
    std::vector<Outcome> outcomes(settings.size());
    for (const Sample& s : samples) {
        for (std::size_t v = 0; v < detectors.size(); ++v) {
            std::vector<TagDetection> found;
            double best_ms = 1e300;
            for (int i = 0; i < repeats; ++i) {
                const auto t0 = std::chrono::steady_clock::now();
                found = detectors[v].detect(s.image);
                best_ms = std::min(
                    best_ms, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            }
            outcomes[v].time_ms.push_back(best_ms);
            score(s, found, outcomes[v]);
        }
    }
    return outcomes;
}

Outcome run(const std::vector<Sample>& samples, const DetectorSettings& settings, int repeats) {
    return run(samples, std::vector<DetectorSettings>{settings}, repeats).front();
}

// One point of the settings sweep: a label, whether it is the defaults, and the settings.
struct Variant {
    std::string label;
    bool is_default = false;
    DetectorSettings settings;
};

// The quad search's decimation and blur on their own (no second or third pass, as AprilTag runs
// them), then the defaults with each extra pass turned off in turn, and the former defaults
// (decimation 2, blur 0.8; CHANGELOG.md): the same images for every row.
std::vector<Variant> settings_variants(const DetectorSettings& defaults, bool quick) {
    std::vector<Variant> v{{"defaults", true, defaults}};
    DetectorSettings tracker = defaults;
    tracker.upsample_pass_factor = 0;
    v.push_back({"defaults without the up-sampled pass (TagTracker)", false, tracker});
    DetectorSettings single = tracker;
    single.coarse_pass_decimation = 0;
    v.push_back({"defaults without the coarse or up-sampled pass", false, single});
    DetectorSettings no_refine = defaults;
    no_refine.refine_edges = false;
    v.push_back({"defaults, refine_edges off", false, no_refine});
    const std::vector<float> decimations =
        quick ? std::vector<float>{1.0f, 2.0f} : std::vector<float>{1.0f, 1.5f, 2.0f, 3.0f, 4.0f};
    const std::vector<float> blurs = quick ? std::vector<float>{0.0f} : std::vector<float>{0.0f, 0.8f};
    for (float dec : decimations) {
        for (float blur : blurs) {
            DetectorSettings s = single;
            s.decimation = dec;
            s.blur_sigma = blur;
            char label[96];
            std::snprintf(label, sizeof label, "single pass, decimation %.1f, blur %.1f%s", static_cast<double>(dec),
                          static_cast<double>(blur), dec == 2.0f && blur == 0.8f ? " (the former defaults)" : "");
            v.push_back({label, false, s});
        }
    }
    return v;
}

void print_sweep(const std::vector<Variant>& variants, const std::vector<Outcome>& outcomes, std::size_t images) {
    const double base_time = percentile(outcomes[0].time_ms, 0.5);
    const double base_corner = percentile(outcomes[0].corner_px, 0.5);
    std::printf(
        "speed/accuracy of the detector settings on %zu images (frontal, 70 deg, 20 px, noise, low contrast), "
        "relative to the defaults (%.2f ms median in this run):\n\n",
        images, base_time);
    std::printf(
        "| settings | median time (ms) | time/default | detected | wrong id | corner error median (px) | corner "
        "error/default |\n");
    std::printf("|---|--:|--:|--:|--:|--:|--:|\n");
    for (std::size_t i = 0; i < variants.size(); ++i) {
        const Outcome& o = outcomes[i];
        const double t = percentile(o.time_ms, 0.5);
        const double c = percentile(o.corner_px, 0.5);
        const char* b = variants[i].is_default ? "**" : "";
        std::printf("| %s%s%s | %.2f | %.2f | %d/%zu | %d | %.3f | %.2f |\n", b, variants[i].label.c_str(), b, t,
                    t / base_time, o.found, images, o.wrong, c, c / base_corner);
    }
}

// CSV for the plot (bench/tracking-eval): one row per variant, the defaults flagged.
std::string write_sweep_csv(const std::string& path, const std::vector<Variant>& variants,
                            const std::vector<Outcome>& outcomes, std::size_t images) {
    std::FILE* f = std::fopen(path.c_str(), "we");
    if (!f) return path + ": cannot open for writing: " + std::strerror(errno);
    std::fprintf(f,
                 "label,is_default,decimation,blur_sigma,coarse_pass_decimation,upsample_pass_factor,refine_edges,"
                 "median_time_ms,detected,images,wrong,corner_median_px,corner_p95_px\n");
    for (std::size_t i = 0; i < variants.size(); ++i) {
        const DetectorSettings& s = variants[i].settings;
        const Outcome& o = outcomes[i];
        std::fprintf(f, "\"%s\",%d,%.2f,%.2f,%.2f,%d,%d,%.4f,%d,%zu,%d,%.4f,%.4f\n", variants[i].label.c_str(),
                     variants[i].is_default ? 1 : 0, static_cast<double>(s.decimation),
                     static_cast<double>(s.blur_sigma), static_cast<double>(s.coarse_pass_decimation),
                     s.upsample_pass_factor, s.refine_edges ? 1 : 0, percentile(o.time_ms, 0.5), o.found, images,
                     o.wrong, percentile(o.corner_px, 0.5), percentile(o.corner_px, 0.95));
    }
    const bool ok = std::fclose(f) == 0;
    return ok ? std::string() : path + ": write failed";
}

}  // namespace
}  // namespace mogao

int main(int argc, char** argv) {
    using namespace mogao;
    CLI::App app{"tracker accuracy and speed on synthetic ground truth"};
    int frames = 40;
    bool quick = false;
    app.add_option("--frames", frames, "images per scenario")->check(CLI::Range(1, 10000))->capture_default_str();
    app.add_flag("--quick", quick, "a few images, fewer settings (smoke test)");
    std::string csv_path;
    app.add_option("--csv", csv_path, "also write the settings sweep as CSV to this file");
    CLI11_PARSE(app, argc, argv);
    if (quick) frames = 3;
    const int repeats = quick ? 1 : 3;

    const TagFamily family("tag36h11");
    const PlanarTarget target = tag_target(make_tag_bitmap(family, kTagId), kTagSize);
    std::vector<std::vector<Sample>> sets;
    const auto all = scenarios();
    for (std::size_t i = 0; i < all.size(); ++i) {
        std::mt19937 rng(1000U + static_cast<unsigned>(i));
        std::vector<Sample> set;
        for (int f = 0; f < frames; ++f) set.push_back(all[i].make(rng, target));
        sets.push_back(std::move(set));
    }
    const DetectorSettings defaults;
    std::printf(
        "camera 800x600, f = 700 px; tag36h11 id %d, %.0f mm, cluttered background; %d images per scenario; default "
        "settings: decimation %.1f, blur %.1f, coarse pass at decimation %.1f, up-sampled pass x%d (frames up to %d "
        "pixels), refine_edges %s, max_hamming %d, 1 thread\n\n",
        kTagId, kTagSize * 1000, frames, static_cast<double>(defaults.decimation),
        static_cast<double>(defaults.blur_sigma), static_cast<double>(defaults.coarse_pass_decimation),
        defaults.upsample_pass_factor, defaults.upsample_pass_max_pixels, defaults.refine_edges ? "on" : "off",
        defaults.max_hamming);

    std::printf(
        "| scenario | tag side (px, median) | detected | corner error median / p95 (px) | position error median / p95 "
        "(mm) | rotation error median / p95 (deg) |\n");
    std::printf("|---|---|---|---|---|---|\n");
    std::vector<double> all_times;
    for (std::size_t i = 0; i < all.size(); ++i) {
        const Outcome o = run(sets[i], defaults, repeats);
        std::vector<double> widths;
        for (const auto& s : sets[i]) widths.push_back(s.width_px);
        all_times.insert(all_times.end(), o.time_ms.begin(), o.time_ms.end());
        std::printf("| %s | %.0f | %d/%d%s | %.2f / %.2f | %.1f / %.1f | %.2f / %.2f |\n", all[i].name.c_str(),
                    percentile(widths, 0.5), o.found, frames,
                    o.wrong > 0 ? (" (+" + std::to_string(o.wrong) + " wrong id)").c_str() : "",
                    percentile(o.corner_px, 0.5), percentile(o.corner_px, 0.95), percentile(o.translation_mm, 0.5),
                    percentile(o.translation_mm, 0.95), percentile(o.rotation_deg, 0.5),
                    percentile(o.rotation_deg, 0.95));
    }
    std::printf(
        "\ndetection time per 800x600 frame, default settings: median %.2f ms, p95 %.2f ms (all scenarios, fastest of "
        "%d runs per image)\n\n",
        percentile(all_times, 0.5), percentile(all_times, 0.95), repeats);

    // The trade-off, on frontal, small, noisy and tilted views together.
    std::vector<Sample> mixed;
    for (std::size_t i : {0UL, 2UL, 3UL, 5UL, 6UL}) mixed.insert(mixed.end(), sets[i].begin(), sets[i].end());
    const std::vector<Variant> variants = settings_variants(defaults, quick);
    std::vector<DetectorSettings> settings;
    for (const Variant& v : variants) settings.push_back(v.settings);
    const std::vector<Outcome> outcomes = run(mixed, settings, repeats);
    print_sweep(variants, outcomes, mixed.size());
    if (!csv_path.empty()) {
        if (auto s = write_sweep_csv(csv_path, variants, outcomes, mixed.size()); !s.empty()) {
            std::fprintf(stderr, "mogao_tracker_bench: %s\n", s.c_str());
            return 1;
        }
    }
    return 0;
}
