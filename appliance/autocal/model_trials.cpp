// SPDX-License-Identifier: Apache-2.0
// The calibration's model trials: the bow, the camera's intrinsics, the projectors' distortion (model_trials.h).
#include "appliance/autocal/model_trials.h"

#include "appliance/autocal/colour_calibration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace mogao::autocal::trials {
namespace {

double mean_of(const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x;
    return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}

// The refined camera intrinsics must be what the screen and the projectors determine, near a chessboard's
// result: each within kMaxPriorSigmas of the prior's (else the prior or the screen's size is wrong), and
// each standard deviation at most options.camera_sigma_gate of the prior's (else the data barely see it
// and the prior decides). Throws CalibrationRefused naming the parameter.
void check_camera_intrinsics(const BundleResult& ba, const DeviceModel& prior, const AutocalOptions& o) {
    if (ba.camera_intrinsics_sigma.size() != 5) return;
    constexpr double kMaxPriorSigmas = 4.0;
    const double w = prior.resolution.width;
    const std::array<const char*, 5> names{"focal length fx", "principal point cx", "principal point cy",
                                           "distortion k1", "distortion k2"};
    const std::array<double, 5> fitted{ba.camera.fx_px, ba.camera.cx_px, ba.camera.cy_px, ba.camera.distortion[0],
                                       ba.camera.distortion[1]};
    const std::array<double, 5> told{prior.fx_px, prior.cx_px, prior.cy_px, prior.distortion[0], prior.distortion[1]};
    const std::array<double, 5> sigma{o.camera_sigma.focal * prior.fx_px, o.camera_sigma.principal_point * w,
                                      o.camera_sigma.principal_point * w, o.camera_sigma.distortion,
                                      o.camera_sigma.distortion};
    for (std::size_t i = 0; i < 5; ++i) {
        const double moved = std::abs(fitted[i] - told[i]) / sigma[i];
        const double seen = ba.camera_intrinsics_sigma[i] / sigma[i];
        if (!(moved <= kMaxPriorSigmas)) {
            throw CalibrationRefused("camera " + std::string(names[i]) + ": refined to " + std::to_string(fitted[i]) +
                                     " from the prior's " + std::to_string(told[i]) + ", " + std::to_string(moved) +
                                     " of its sigmas (limit " + std::to_string(kMaxPriorSigmas) +
                                     "): the camera's chessboard calibration or the screen's size is wrong");
        }
        if (!(seen <= o.camera_sigma_gate)) {
            throw CalibrationRefused("camera " + std::string(names[i]) +
                                     ": barely determined by the screen and the "
                                     "projectors (standard deviation " +
                                     std::to_string(ba.camera_intrinsics_sigma[i]) + ", " + std::to_string(seen) +
                                     " of the prior's, gate " + std::to_string(o.camera_sigma_gate) +
                                     "): the camera sees too little of the screen's edges or of the projectors");
        }
    }
}

// The cost of fit `b` in units of fit `unit`'s: each projector's inlier correspondences and the edges at
// unit's rms (its maximum-likelihood noise level), summed over the blocks' points and divided by their count;
// 1 for `unit` itself.
double relative_cost(const BundleResult& b, const BundleResult& unit, std::size_t edge_points) {
    double cost = 0.0;
    double points = 0.0;
    for (std::size_t k = 0; k < b.rms_sigma.size(); ++k) {
        const double ratio = b.rms_sigma[k] / std::max(unit.rms_sigma[k], 1e-12);
        cost += b.inliers[k] * ratio * ratio;
        points += unit.inliers[k];
    }
    const double e = static_cast<double>(edge_points);
    const double ratio = b.edge_rms_m / std::max(unit.edge_rms_m, 1e-12);
    cost += e * ratio * ratio;
    points += e;
    return points > 0.0 ? cost / points : 1.0;
}

}  // namespace

// AutocalOptions::fit_bow: a second bundle adjustment from the first's result with the bow free; its
// result replaces the first only when the projectors' mean fit rms falls by more than bow_min_gain.
void try_bow(BundleResult& ba, const std::vector<EdgeObservation>& edges,
             const std::vector<ProjectorObservations>& observations, BundleOptions bo, const AutocalOptions& options,
             BowTrial& trial) {
    if (edges.empty() || !bo.refine_camera) return;  // the bow needs the edges and the camera with it
    bo.refine_bow = true;
    BundleResult bowed = bundle_adjust(ba.screen, ba.camera, ba.projectors, edges, observations, bo);
    trial.tried = true;
    trial.cylinder_rms_sigma = mean_of(ba.rms_sigma);
    trial.bowed_rms_sigma = mean_of(bowed.rms_sigma);
    trial.bow_m = bowed.screen.bow_m;
    // A bow beyond 10 % of the radius is no bow of a cylinder screen but a fit gone astray.
    const bool plausible = std::all_of(trial.bow_m.begin(), trial.bow_m.end(),
                                       [&](double a) { return std::abs(a) < 0.1 * bowed.screen.radius_m; });
    // Each adjustment drops its own outliers: a bowed fit that only rejected more points does not count,
    // nor one whose projector fits fail the gate the cylinder's passed.
    int kept_cylinder = 0;
    int kept_bowed = 0;
    for (std::size_t k = 0; k < ba.inliers.size(); ++k) {
        kept_cylinder += ba.inliers[k];
        kept_bowed += bowed.inliers[k];
    }
    const bool same_points = kept_bowed >= 0.99 * kept_cylinder;
    const bool within_gate = std::all_of(bowed.rms_sigma.begin(), bowed.rms_sigma.end(),
                                         [&](double r) { return r <= options.max_projector_rms; });
    trial.kept = plausible && same_points && within_gate &&
                 trial.bowed_rms_sigma < (1.0 - options.bow_min_gain) * trial.cylinder_rms_sigma;
    if (trial.kept) ba = std::move(bowed);
}

// AutocalOptions::refine_camera_intrinsics: a second bundle adjustment from `ba`'s result (the prior's
// intrinsics taken as exact) with the camera's intrinsics free. Its result replaces `ba` only when the cost
// falls by more than intrinsics_min_gain on about the same correspondences (as the bow's trial); a kept
// result must pass check_camera_intrinsics. The conditioning reported is the free adjustment's.
void try_camera_intrinsics(BundleResult& ba, const CalibrationPrior& prior, const std::vector<EdgeObservation>& edges,
                           const std::vector<ProjectorObservations>& observations, BundleOptions bo,
                           const AutocalOptions& options, AutocalReport& report) {
    report.condition_number = ba.condition_number;
    if (!options.refine_camera_intrinsics || edges.empty()) return;
    bo.refine_camera_intrinsics = true;
    BundleResult free = bundle_adjust(ba.screen, ba.camera, ba.projectors, edges, observations, bo);
    IntrinsicsTrial& trial = report.intrinsics;
    trial.tried = true;
    trial.relative_cost = relative_cost(free, ba, edges.size());
    report.camera_intrinsics_sigma = free.camera_intrinsics_sigma;
    report.condition_number = free.condition_number;
    int kept_fixed = 0;
    int kept_free = 0;
    for (std::size_t k = 0; k < ba.inliers.size(); ++k) {
        kept_fixed += ba.inliers[k];
        kept_free += free.inliers[k];
    }
    // A free fit that only rejected more points does not count; one that fits much better may reject more, its
    // outlier limit (4x its median) being tighter: its cost's fall must then be ten times the points it lost.
    const double lost = 1.0 - static_cast<double>(kept_free) / std::max(kept_fixed, 1);
    const bool same_points = lost <= 0.01 || 1.0 - trial.relative_cost >= 10.0 * lost;
    trial.kept = same_points && trial.relative_cost < 1.0 - options.intrinsics_min_gain;
    if (!trial.kept) return;
    check_camera_intrinsics(free, prior.camera, options);
    ba = std::move(free);
}

// AutocalOptions::fit_projector_distortion: a bundle adjustment from `ba`'s result (with what the earlier trials
// kept free: `bo`) with every projector's distortion free; a projector keeps it where its own cost, in units of
// `ba`'s, falls by more than distortion_min_gain on about the same correspondences, and so does the whole fit's. Where
// only some keep it, the adjustment is run again with only theirs free. Kept intrinsics are checked again
// (check_camera_intrinsics).
void try_projector_distortion(BundleResult& ba, const CalibrationPrior& prior,
                              const std::vector<EdgeObservation>& edges,
                              const std::vector<ProjectorObservations>& observations, BundleOptions bo,
                              const AutocalOptions& options, AutocalReport& report) {
    const std::size_t n = ba.projectors.size();
    if (!options.fit_projector_distortion || n == 0) return;
    bo.refine_projector_distortion.assign(n, true);
    BundleResult free = bundle_adjust(ba.screen, ba.camera, ba.projectors, edges, observations, bo);
    report.distortion.assign(n, DistortionTrial{});
    std::vector<bool> keep(n, false);
    for (std::size_t k = 0; k < n; ++k) {
        DistortionTrial& t = report.distortion[k];
        t.tried = true;
        const double ratio = free.rms_sigma[k] / std::max(ba.rms_sigma[k], 1e-12);
        t.relative_cost = free.inliers[k] * ratio * ratio / std::max(ba.inliers[k], 1);
        for (std::size_t i = 0; i < t.distortion.size(); ++i) t.distortion[i] = free.projectors[k].distortion[i];
        // As the intrinsics' trial: a fit that only rejected more points does not count; a much better one may
        // reject more (its outlier limit is tighter), its fall then ten times the points it lost.
        const double lost = 1.0 - static_cast<double>(free.inliers[k]) / std::max(ba.inliers[k], 1);
        const bool same_points = lost <= 0.01 || 1.0 - t.relative_cost >= 10.0 * lost;
        keep[k] = same_points && t.relative_cost < 1.0 - options.distortion_min_gain;
    }
    // And the whole fit's cost (every projector and the edges, as the intrinsics' trial counts it) must fall by
    // more than the gain too: one projector's fall of a percent or two on a noisy rig is its noise taken up.
    const double whole = relative_cost(free, ba, edges.size());
    for (DistortionTrial& t : report.distortion) t.fit_relative_cost = whole;
    if (!(whole < 1.0 - options.distortion_min_gain)) keep.assign(n, false);
    const auto kept = static_cast<std::size_t>(std::count(keep.begin(), keep.end(), true));
    if (kept == 0) return;
    if (kept < n) {
        bo.refine_projector_distortion = keep;
        free = bundle_adjust(ba.screen, ba.camera, ba.projectors, edges, observations, bo);
    }
    for (std::size_t k = 0; k < n; ++k) {
        report.distortion[k].kept = keep[k];
        if (keep[k]) {
            for (std::size_t i = 0; i < 4; ++i) report.distortion[k].distortion[i] = free.projectors[k].distortion[i];
        }
    }
    if (bo.refine_camera_intrinsics) {
        check_camera_intrinsics(free, prior.camera, options);
        report.camera_intrinsics_sigma = free.camera_intrinsics_sigma;
    }
    report.condition_number = free.condition_number;
    ba = std::move(free);
}

// AutocalOptions::check_heights: the final adjustment again with the top edge free, from its result. The shift is
// measured on content, not on the screen: where each fit's warp puts content (u, v) in the projector's image, so
// that it counts only what a told span that is off would move on the wall (the fitted projectors take up part of
// it). Content u spans the arc and v the span (autocal.h's content convention, v = 0 at the top).
void check_told_heights(const BundleResult& ba, const std::vector<EdgeObservation>& edges,
                        const std::vector<ProjectorObservations>& observations, BundleOptions bo,
                        const AutocalOptions& options, HeightsCheck& check) {
    if (!options.check_heights || edges.empty() || !bo.refine_camera) return;
    bo.refine_heights = true;
    const BundleResult fitted = bundle_adjust(ba.screen, ba.camera, ba.projectors, edges, observations, bo);
    constexpr int kColumns = 17;
    constexpr int kRows = 9;
    const double arc = ba.screen.arc_deg * std::numbers::pi / 180.0;
    double sum = 0.0;
    double largest = 0.0;
    int n = 0;
    for (std::size_t k = 0; k < ba.projectors.size(); ++k) {
        for (int i = 0; i < kColumns; ++i) {
            for (int j = 0; j < kRows; ++j) {
                const double theta = ((i + 0.5) / kColumns - 0.5) * arc;
                const double v = (j + 0.5) / kRows;
                const auto h = [v](const ScreenModel& s) { return s.top_m - v * (s.top_m - s.bottom_m); };
                const Eigen::Vector2d told = model_pixel(ba.projectors[k], ba.screen, theta, h(ba.screen));
                const Eigen::Vector2d seen = model_pixel(fitted.projectors[k], fitted.screen, theta, h(fitted.screen));
                if (!told.allFinite() || !seen.allFinite()) continue;  // not this projector's content
                const double d = (told - seen).norm();
                sum += d;
                largest = std::max(largest, d);
                ++n;
            }
        }
    }
    check.tried = true;
    check.fitted_top_m = fitted.screen.top_m;
    check.shift_mean_px = n > 0 ? sum / n : 0.0;
    check.shift_max_px = largest;
}

}  // namespace mogao::autocal::trials
