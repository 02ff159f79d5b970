// SPDX-License-Identifier: Apache-2.0
// mogao_tracking_eval grotto: detector settings, ROI tracking and the independent corner reference
// (tag_reference.h) on the rendered grotto set, against the exact corners the renderer's camera
// gives (tracking_eval_grotto.h; docs/tracking.md, "Rendered grotto set").
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "appliance/tracker/lab/tag_reference.h"
#include "appliance/tracker/lab/tracking_eval.h"
#include "appliance/tracker/lab/tracking_eval_grotto.h"
#include "appliance/tracker/tag_detector.h"
#include "appliance/tracker/tag_tracker.h"
#include "drivers/camera/image_file.h"

namespace mogao::eval {
namespace {

double quantile(std::vector<double> v, double q) {
    if (v.empty()) return NAN;
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

Eigen::Vector2d centre_of(const TagCorners& c) { return (c[0] + c[1] + c[2] + c[3]) / 4.0; }
double side_of(const TagCorners& c) { return ((c[1] - c[0]).norm() + (c[2] - c[3]).norm()) / 2.0; }

// Found: a detection of the set's id within half a tag side of the true centre (the first one);
// every other detection is a false positive. Corner errors in AprilTag order, no reordering: a
// detection decoded in the wrong rotation shows as an error of a tag side.
struct Score {
    int tags = 0, found = 0, false_positives = 0;
    std::vector<double> errors_px;
    double rate() const { return tags == 0 ? NAN : static_cast<double>(found - false_positives) / tags; }
    void add(const Score& s) {
        tags += s.tags;
        found += s.found;
        false_positives += s.false_positives;
        errors_px.insert(errors_px.end(), s.errors_px.begin(), s.errors_px.end());
    }
};

Score score_frame(const GrottoSet& set, const GrottoFrame& frame, const std::vector<TagDetection>& found) {
    Score s;
    s.tags = 1;
    const TagCorners& truth = frame.corners;
    for (const auto& d : found) {
        const bool near = (d.centre - centre_of(truth)).norm() <= side_of(truth) / 2.0;
        if (s.found == 0 && d.id == set.tag_id && near) {
            s.found = 1;
            for (std::size_t k = 0; k < 4; ++k) s.errors_px.push_back((d.corners[k] - truth[k]).norm());
        } else {
            ++s.false_positives;
        }
    }
    return s;
}

struct SettingResult {
    Score all;
    std::vector<Score> per_frame;
    std::map<std::string, Score> by_variant;
    double total_ms = 0.0;
};

std::vector<SettingResult> evaluate_settings(const GrottoSet& set, const std::vector<GrayImage>& images,
                                             const std::vector<NamedSettings>& settings, int repeat) {
    std::vector<TagDetector> detectors;
    for (const auto& named : settings) {
        DetectorSettings s = named.settings;
        s.family = set.family;
        detectors.emplace_back(s);
    }
    std::vector<SettingResult> results(settings.size());
    for (std::size_t i = 0; i < images.size(); ++i) {
        // Interleaved timing: each repeat runs every setting in turn (a shared machine's load
        // changes bias no setting).
        std::vector<std::vector<TagDetection>> found(settings.size());
        std::vector<double> best(settings.size(), 1e300);
        for (int r = 0; r < repeat; ++r) {
            for (std::size_t k = 0; k < settings.size(); ++k) {
                const auto t0 = std::chrono::steady_clock::now();
                found[k] = detectors[k].detect(images[i]);
                best[k] = std::min(best[k], ms_since(t0));
            }
        }
        for (std::size_t k = 0; k < settings.size(); ++k) {
            const Score s = score_frame(set, set.frames[i], found[k]);
            results[k].all.add(s);
            results[k].per_frame.push_back(s);
            results[k].by_variant[set.frames[i].variant].add(s);
            results[k].total_ms += best[k];
        }
    }
    return results;
}

void print_settings_table(const std::vector<NamedSettings>& settings, const std::vector<SettingResult>& results,
                          std::size_t frames) {
    std::printf("| settings | tags | found | false positives | rate |");
    for (const auto& [variant, score] : results.front().by_variant) std::printf(" rate %s |", variant.c_str());
    std::printf(" corner error median (px) | p90 (px) | max (px) | ms/frame | time/defaults |\n|---|--:|--:|--:|--:|");
    for (std::size_t v = 0; v < results.front().by_variant.size(); ++v) std::printf("--:|");
    std::printf("--:|--:|--:|--:|--:|\n");
    for (std::size_t k = 0; k < settings.size(); ++k) {
        const auto& r = results[k];
        std::printf("| %s | %d | %d | %d | %.1f %% |", settings[k].name.c_str(), r.all.tags, r.all.found,
                    r.all.false_positives, 100.0 * r.all.rate());
        for (const auto& [variant, score] : r.by_variant) std::printf(" %.1f %% |", 100.0 * score.rate());
        std::printf(" %.3f | %.3f | %.3f | %.1f | %.2f |\n", quantile(r.all.errors_px, 0.5),
                    quantile(r.all.errors_px, 0.9), quantile(r.all.errors_px, 1.0),
                    r.total_ms / static_cast<double>(frames), r.total_ms / results.front().total_ms);
    }
}

// The independent reference of the real photographs (ArUco + edge-line fits) against the exact
// corners, beside the detector's defaults on the same frames.
void print_reference_check(const GrottoSet& set, const std::vector<GrayImage>& images) {
    TagDetector detector([&] {
        DetectorSettings s;
        s.family = set.family;
        return s;
    }());
    std::vector<double> ref_errors, det_errors;
    int with_reference = 0;
    for (std::size_t i = 0; i < images.size(); ++i) {
        const auto refs = reference_tags(images[i], set.family);
        const auto it = std::find_if(refs.begin(), refs.end(),
                                     [&](const ReferenceTag& r) { return r.id == set.tag_id && r.refined; });
        if (it == refs.end()) continue;
        ++with_reference;
        for (const double e : matched_corner_errors(it->corners, set.frames[i].corners)) ref_errors.push_back(e);
        const Score s = score_frame(set, set.frames[i], detector.detect(images[i]));
        det_errors.insert(det_errors.end(), s.errors_px.begin(), s.errors_px.end());
    }
    std::printf("\n| corners against the exact ones | frames | corner error median (px) | p90 (px) | max (px) |\n");
    std::printf("|---|--:|--:|--:|--:|\n");
    std::printf("| reference (ArUco + edge-line fits, tag_reference.h) | %d of %zu | %.3f | %.3f | %.3f |\n",
                with_reference, images.size(), quantile(ref_errors, 0.5), quantile(ref_errors, 0.9),
                quantile(ref_errors, 1.0));
    std::printf("| detector defaults, same frames | %zu | %.3f | %.3f | %.3f |\n", det_errors.size() / 4,
                quantile(det_errors, 0.5), quantile(det_errors, 0.9), quantile(det_errors, 1.0));
}

// ROI tracking over each variant's sequence (the frames are consecutive samples of one hand
// trajectory at set.fps), against the same tracker searching every whole frame (the tracker's
// detector: the defaults without the up-sampled pass, tag_tracker.h).
void print_roi_table(const GrottoSet& set, const std::vector<GrayImage>& images, int repeat) {
    std::printf(
        "\n| mode | frames | detected | lost | false | mean ms/frame | mean/whole frame | corner error median "
        "(px) | max (px) |\n|---|--:|--:|--:|--:|--:|--:|--:|--:|\n");
    double baseline = 0.0;
    for (const bool roi : {false, true}) {
        Score score;
        double total_ms = 0.0;
        for (int pass = 0; pass < repeat; ++pass) {
            std::map<std::string, TagTracker> trackers;
            double pass_ms = 0.0;
            for (std::size_t i = 0; i < images.size(); ++i) {
                TrackerConfig config;
                config.roi.enabled = roi;
                config.detector.family = set.family;
                config.camera = set.camera;
                config.tag_size_m = set.tag_size_m;
                config.tag_id = set.tag_id;
                auto& tracker = trackers.try_emplace(set.frames[i].variant, config).first->second;
                CameraFrame frame;
                frame.image = images[i];
                frame.timestamp_ns = static_cast<std::int64_t>(std::llround(set.frames[i].time_s * 1e9));
                const auto t0 = std::chrono::steady_clock::now();
                const TrackedTag tag = tracker.track(frame);
                pass_ms += ms_since(t0);
                if (pass == 0) {
                    std::vector<TagDetection> found;
                    if (tag.visible) found.push_back(tag.detection);
                    score.add(score_frame(set, set.frames[i], found));
                }
            }
            total_ms = pass == 0 ? pass_ms : std::min(total_ms, pass_ms);
        }
        const double mean = total_ms / static_cast<double>(images.size());
        if (!roi) baseline = mean;
        std::printf("| %s | %d | %d | %d | %d | %.2f | %.3f | %.3f | %.3f |\n",
                    roi ? "TagTracker, ROI tracking (defaults)" : "TagTracker, ROI off (whole frame)", score.tags,
                    score.found, score.tags - score.found, score.false_positives, mean, mean / baseline,
                    quantile(score.errors_px, 0.5), quantile(score.errors_px, 1.0));
    }
}

// The defaults by the motion blur of the tag centre over the exposure (pixels).
void print_by_blur(const GrottoSet& set, const SettingResult& defaults) {
    const std::vector<std::pair<double, double>> bins{{0.0, 1.0}, {1.0, 2.0}, {2.0, 4.0}, {4.0, 8.0}, {8.0, 1e9}};
    std::printf("\n| motion blur (px) | frames | found (defaults) | corner error median (px) | p90 (px) |\n");
    std::printf("|---|--:|--:|--:|--:|\n");
    for (const auto& [lo, hi] : bins) {
        Score bin;
        for (std::size_t i = 0; i < set.frames.size(); ++i) {
            if (set.frames[i].blur_px >= lo && set.frames[i].blur_px < hi) bin.add(defaults.per_frame[i]);
        }
        if (bin.tags == 0) continue;
        const std::string range =
            hi > 1e8 ? "≥ " + std::to_string(static_cast<int>(lo))
                     : std::to_string(static_cast<int>(lo)) + "–" + std::to_string(static_cast<int>(hi));
        std::printf("| %s | %d | %d | %.3f | %.3f |\n", range.c_str(), bin.tags, bin.found,
                    quantile(bin.errors_px, 0.5), quantile(bin.errors_px, 0.9));
    }
}

void print_variants(const GrottoSet& set) {
    std::map<std::string, std::vector<const GrottoFrame*>> by_variant;
    for (const auto& f : set.frames) by_variant[f.variant].push_back(&f);
    for (const auto& [variant, frames] : by_variant) {
        std::vector<double> blur, dist;
        for (const auto* f : frames) {
            blur.push_back(f->blur_px);
            dist.push_back(f->distance_m);
        }
        std::printf(
            "%s%s: %zu frames of %dx%d px at %.0f fps, exposure %.0f ms, gain %.2f, tag at %.2f-%.2f m, "
            "motion blur of the tag centre median %.1f px, max %.1f px",
            variant == by_variant.begin()->first ? "\n" : "; ", variant.c_str(), frames.size(), set.camera.width,
            set.camera.height, set.fps, frames.front()->exposure_ms, frames.front()->gain, quantile(dist, 0.0),
            quantile(dist, 1.0), quantile(blur, 0.5), quantile(blur, 1.0));
    }
    std::printf(".\n");
}

}  // namespace

int run_grotto(const GrottoOptions& options) {
    const GrottoSet set = read_grotto_set(options.set);
    std::vector<GrayImage> images;
    for (const auto& frame : set.frames) {
        auto image = read_gray_image(set.developed(frame));
        if (!image) throw std::runtime_error(image.error().message + " (mogao_tracking_eval grotto-develop writes it)");
        if (image->width != set.camera.width || image->height != set.camera.height)
            throw std::runtime_error(set.developed(frame).string() + ": size differs from set.json's width/height");
        images.push_back(std::move(*image));
    }
    const auto settings = compared_settings();
    const auto results = evaluate_settings(set, images, settings, options.repeat);
    print_settings_table(settings, results, images.size());
    print_by_blur(set, results.front());
    print_reference_check(set, images);
    print_roi_table(set, images, options.repeat);
    print_variants(set);
    const auto& defaults = results.front().all;
    const double median = quantile(defaults.errors_px, 0.5);
    int status = 0;
    if (options.min_rate >= 0.0 && !(defaults.rate() >= options.min_rate)) {
        std::fprintf(stderr, "grotto: the defaults' rate %.3f is below --min-rate %.3f\n", defaults.rate(),
                     options.min_rate);
        status = 1;
    }
    if (options.max_median_px >= 0.0 && !(median <= options.max_median_px)) {
        std::fprintf(stderr, "grotto: the defaults' median corner error %.3f px exceeds --max-median-px %.3f\n", median,
                     options.max_median_px);
        status = 1;
    }
    return status;
}

}  // namespace mogao::eval
