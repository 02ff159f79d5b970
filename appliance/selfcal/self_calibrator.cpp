// SPDX-License-Identifier: Apache-2.0
// The self-recalibration state machine (self_calibrator.h).
#include "appliance/selfcal/self_calibrator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <numbers>
#include <stdexcept>
#include <utility>

#include <Eigen/Cholesky>

#include "appliance/autocal/bundle_adjust.h"
#include "appliance/autocal/colour_calibration.h"
#include "appliance/selfcal/calibration_store.h"

namespace mogao::selfcal {

namespace {

// Whether measurement z (covariance r) is nearer "no change" than the filter's state x, in r's metric.
bool says_no_change(const Pose6& z, const Cov6& r, const Pose6& x) {
    const Eigen::LDLT<Cov6> ldlt(r);
    const Pose6 to_state = z - x;
    return z.dot(ldlt.solve(z)) < to_state.dot(ldlt.solve(to_state));
}

constexpr double kRad2Deg = 180.0 / std::numbers::pi;
// A matched feature's position error is not independent of its neighbours' (same blur, same
// content edge), so the fit's covariance is optimistic: its variance is inflated by this factor.
constexpr double kCovarianceInflation = 4.0;

double thread_cpu_ms() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

void check_options(const SelfcalOptions& o) {
    const auto fail = [](const std::string& what) { throw std::invalid_argument("SelfcalOptions: " + what); };
    if (!(o.drift_threshold_px > 0.0)) fail("drift_threshold_px > 0");
    if (!(o.hold_s >= 0.0) || !std::isfinite(o.hold_s)) fail("hold_s >= 0");
    if (!(o.transition_s >= 0.0) || !std::isfinite(o.transition_s)) fail("transition_s >= 0");
    if (o.min_matches < 6) fail("min_matches >= 6");
    if (!(o.max_offscreen_loss > 0.0 && o.max_offscreen_loss <= 1.0)) fail("max_offscreen_loss in (0, 1]");
    if (!(o.camera_rebase_px >= 0.0)) fail("camera_rebase_px >= 0");
    if (o.pattern.enabled) check_pattern_options(o.pattern);
}

std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0) {
    char buf[200];
    std::snprintf(buf, sizeof buf, f, a, b, c);
    return buf;
}

ScreenCalibration without_beta(ScreenCalibration calibration) {
    for (ProjectorCalibration& pc : calibration.projectors) pc.beta = {};
    return calibration;
}

}  // namespace

ScreenCalibration interpolate_calibration(const ScreenCalibration& a, const ScreenCalibration& b, double s) {
    if (a.projectors.size() != b.projectors.size()) throw std::invalid_argument("interpolate_calibration: layouts");
    if (!(s > 0.0)) return a;  // the ends exactly (x + 1 * (y - x) need not round to y)
    if (s >= 1.0) return b;
    ScreenCalibration out = b;
    const auto t = static_cast<float>(s);
    for (std::size_t k = 0; k < a.projectors.size(); ++k) {
        const ProjectorCalibration& pa = a.projectors[k];
        ProjectorCalibration& po = out.projectors[k];
        if (pa.warp.uv.size() != po.warp.uv.size() || pa.blend.weight.size() != po.blend.weight.size()) {
            throw std::invalid_argument("interpolate_calibration: projector " + pa.id + " grids differ");
        }
        for (std::size_t i = 0; i < po.warp.uv.size(); ++i) {
            const float x = pa.warp.uv[i];
            const float y = po.warp.uv[i];
            if (std::isfinite(x) && std::isfinite(y)) {
                po.warp.uv[i] = x + t * (y - x);
            } else if (t < 0.5f) {
                po.warp.uv[i] = x;
            }
        }
        for (std::size_t i = 0; i < po.blend.weight.size(); ++i) {
            po.blend.weight[i] = pa.blend.weight[i] + t * (po.blend.weight[i] - pa.blend.weight[i]);
        }
        if (pa.beta.rgb.size() == po.beta.rgb.size()) {
            for (std::size_t i = 0; i < po.beta.rgb.size(); ++i) {
                po.beta.rgb[i] = pa.beta.rgb[i] + t * (po.beta.rgb[i] - pa.beta.rgb[i]);
            }
        } else if (t < 0.5f) {
            po.beta = pa.beta;
        }
    }
    return out;
}

SelfCalibrator::SelfCalibrator(const SystemModel& model, const ScreenCalibration& calibration,
                               const SelfcalOptions& options)
    : options_(options),
      monitor_(model, calibration, options.monitor),
      wall_(calibration),
      camera_filter_(options.camera_kalman) {
    check_options(options);
    try {
        colour_ = autocal::measured_colour(calibration, model.projectors, model.screen);
    } catch (const std::invalid_argument& e) {
        // Beta maps made some other way: kept as they are through corrections (the responses still are).
        colour_ = autocal::measured_colour(without_beta(calibration), model.projectors, model.screen);
        for (const ProjectorCalibration& pc : calibration.projectors) kept_beta_.push_back(pc.beta);
        pending_journal_ = std::string("selfcal: ") + e.what() + "; corrections keep those maps as they are";
    }
    filters_.assign(model.projectors.size(), PoseKalman(options.kalman));
    typical_matches_.assign(model.projectors.size(), -1.0);
    contested_.assign(model.projectors.size(), 0);
    seen_above_.assign(model.projectors.size(), 0);
    stepped_.assign(model.projectors.size(), 0);
    lost_since_.assign(model.projectors.size(), -1.0);
}

bool SelfCalibrator::check_lost(double t_s, StepResult& r) {
    const std::size_t n = filters_.size();
    for (std::size_t k = 0; k < n; ++k) {
        const ProjectorStatus& ps = r.status.projectors[k];
        bool others_fine = n > 1;
        for (std::size_t j = 0; j < n; ++j) {
            if (j != k && !(typical_matches_[j] > 0.0 && r.status.projectors[j].matches >= 0.5 * typical_matches_[j])) {
                others_fine = false;
            }
        }
        const bool lost = typical_matches_[k] > 0.0 && ps.matches < 0.2 * typical_matches_[k] && others_fine;
        if (!lost) {
            lost_since_[k] = -1.0;
            continue;
        }
        if (lost_since_[k] < 0.0) lost_since_[k] = t_s;
        if (t_s - lost_since_[k] < options_.hold_s) continue;
        if (state_ != SelfcalState::cannot_correct) {
            reason_ = ps.id + " lost: " + std::to_string(ps.matches) + " matches, typically " +
                      std::to_string(static_cast<int>(typical_matches_[k])) +
                      ", while the others see theirs (moved beyond what the monitor can follow)";
            r.journal.push_back("selfcal: cannot correct (needs a full calibration): " + reason_);
        }
        state_ = SelfcalState::cannot_correct;
        return true;
    }
    return false;
}

// Mean displacement, in the device's pixels, of a 16x9 grid of its pixel centres when it moves by
// `delta`: each pixel's ray meets the screen, and the moved device sees that point elsewhere.
double SelfCalibrator::device_drift_px(const autocal::DeviceModel& d, const Pose6& delta) const {
    const SystemModel& m = monitor_.model();
    const autocal::DeviceModel moved = apply_delta(d, delta);
    double sum = 0.0;
    int n = 0;
    constexpr int kGx = 16;
    constexpr int kGy = 9;
    for (int j = 0; j < kGy; ++j) {
        for (int i = 0; i < kGx; ++i) {
            const double x = (i + 0.5) * d.resolution.width / kGx;
            const double y = (j + 0.5) * d.resolution.height / kGy;
            // Through the device's lens distortion both ways (a bump moves the pose, not the lens).
            const Eigen::Vector3d s = autocal::ray_on_screen(m.screen, d, autocal::device_ray(d, x, y));
            if (!s.allFinite()) continue;
            const Eigen::Vector2d seen = project_normalised(moved.rotation, moved.position_m, s);
            if (!seen.allFinite()) continue;
            const Eigen::Vector2d q = autocal::device_image(d, {seen.x(), seen.y(), 1.0});
            if (!q.allFinite()) continue;
            sum += std::hypot(q.x() - x, q.y() - y);
            ++n;
        }
    }
    return n > 0 ? sum / n : 0.0;
}

double SelfCalibrator::drift_px(int k, const Pose6& delta) const {
    return device_drift_px(monitor_.model().projectors[static_cast<std::size_t>(k)], delta);
}

double SelfCalibrator::camera_drift_px(const Pose6& delta) const {
    return device_drift_px(monitor_.model().camera, delta);
}

double SelfCalibrator::on_screen_fraction(const autocal::DeviceModel& d) const {
    const autocal::ScreenModel& s = monitor_.model().screen;
    const double half_arc = s.arc_deg / 2.0 / kRad2Deg;
    int on = 0;
    constexpr int kG = 24;
    for (int j = 0; j < kG; ++j) {
        for (int i = 0; i < kG; ++i) {
            const double x = (i + 0.5) * d.resolution.width / kG;
            const double y = (j + 0.5) * d.resolution.height / kG;
            const Eigen::Vector3d p = autocal::ray_on_screen(s, d, autocal::device_ray(d, x, y));
            if (!p.allFinite()) continue;
            const double theta = std::atan2(p.x(), -p.z());
            if (std::abs(theta) <= half_arc && p.y() >= s.bottom_m && p.y() <= s.top_m) ++on;
        }
    }
    return static_cast<double>(on) / (kG * kG);
}

void SelfCalibrator::filter(const FrameMeasurement& m, double dt, StepResult& r) {
    int short_of_evidence = 0;
    for (std::size_t k = 0; k < filters_.size(); ++k) {
        filters_[k].predict(dt);
        const ProjectorMeasurement& pm = m.projectors[k];
        ProjectorStatus& ps = r.status.projectors[k];
        ps.matches = pm.matches;
        if (pm.matches < options_.min_matches || !pm.fit.ok) {
            ++short_of_evidence;
            continue;
        }
        const Pose6 before = filters_[k].state();
        const Cov6 rk = kCovarianceInflation * pm.fit.covariance;
        const KalmanUpdate u = filters_[k].update(pm.delta, rk);
        contested_[k] = u == KalmanUpdate::rejected && says_no_change(pm.delta, rk, before);
        stepped_[k] = u == KalmanUpdate::step_accepted;
        ps.measured = true;
        const double seen = static_cast<double>(pm.matches);
        typical_matches_[k] = typical_matches_[k] < 0.0 ? seen : 0.8 * typical_matches_[k] + 0.2 * seen;
    }
    camera_filter_.predict(dt);
    if (m.camera.ok) (void)camera_filter_.update(m.camera_delta, kCovarianceInflation * m.camera.covariance);
    if (m.camera_edges_disagree && !edges_disagree_) {
        r.journal.push_back(
            fmt("selfcal: t=%.2f s: the camera fit moved but the screen's edges did not: ", r.status.t_s) +
            "projectors moving together, not the camera (no camera measurement)");
    }
    edges_disagree_ = m.camera_edges_disagree;
    if (short_of_evidence > 0) {
        r.status.waiting = true;
        r.status.reason = std::to_string(short_of_evidence) + " projector(s) under " +
                          std::to_string(options_.min_matches) + " matches (" + std::to_string(m.matches) + " in all)";
        if (m.occluded_fraction > 0.0) {
            r.status.reason += fmt("; visitors hide %.0f %% of the screen (%.0f matches dropped)",
                                   100.0 * m.occluded_fraction, m.occluded_matches);
        }
    }
}

void SelfCalibrator::start_correction(double t_s, const std::vector<int>& drifting, StepResult& r) {
    const SystemModel& m = monitor_.model();
    after_models_ = m.projectors;
    for (int k : drifting) {
        const auto uk = static_cast<std::size_t>(k);
        after_models_[uk] = apply_delta(m.projectors[uk], filters_[uk].state());
        const Cov6& p = filters_[uk].covariance();
        r.journal.push_back("selfcal: correcting " + m.projectors[uk].id +
                            fmt(": before: drift %.2f px (rotation %.3f deg, ", r.status.projectors[uk].drift_px,
                                r.status.projectors[uk].rotation_deg) +
                            fmt("shift %.1f mm); estimate sd %.4f deg, %.2f mm", r.status.projectors[uk].shift_mm,
                                std::sqrt(p.topLeftCorner<3, 3>().trace()) * kRad2Deg,
                                std::sqrt(p.bottomRightCorner<3, 3>().trace()) * 1e3) +
                            fmt(", blended in over %.1f s", options_.transition_s));
    }
    before_ = wall_;
    after_ = corrected_calibration(after_models_, r);
    correction_start_ = t_s;
    state_ = SelfcalState::correcting;
    advance_correction(t_s, r);
}

// The geometry from the corrected models, with the calibration's measured colour re-derived for it
// (self_calibrator.h: responses kept, black-level maps and blend scale from the new overlaps).
ScreenCalibration SelfCalibrator::corrected_calibration(const std::vector<autocal::DeviceModel>& models,
                                                        StepResult& r) const {
    const SystemModel& m = monitor_.model();
    ScreenCalibration out = autocal::calibration_from_models(models, m.screen, wall_.content, options_.build);
    const double scale = autocal::apply_measured_colour(colour_, models, m.screen, out);
    for (std::size_t k = 0; k < kept_beta_.size(); ++k) out.projectors[k].beta = kept_beta_[k];
    bool black = false;
    for (const auto& b : colour_.black) black = black || b[0] > 0.0 || b[1] > 0.0 || b[2] > 0.0;
    if (black) {
        r.journal.push_back(
            fmt("selfcal: measured colour kept: responses as calibrated, black-level maps "
                "re-derived for the new overlaps (blend scale %.4f)",
                scale));
    }
    return out;
}

void SelfCalibrator::advance_correction(double t_s, StepResult& r) {
    const double s = options_.transition_s > 0.0 ? (t_s - correction_start_) / options_.transition_s : 1.0;
    if (s < 1.0) {
        wall_ = interpolate_calibration(before_, after_, s);
        r.calibration = wall_;
        return;
    }
    wall_ = after_;
    r.calibration = wall_;
    SystemModel m = monitor_.model();
    m.projectors = after_models_;
    monitor_.set_reference(m, wall_);
    for (PoseKalman& f : filters_) f.reset();
    std::fill(contested_.begin(), contested_.end(), 0);
    std::fill(seen_above_.begin(), seen_above_.end(), 0);
    std::fill(stepped_.begin(), stepped_.end(), 0);
    state_ = SelfcalState::calibrated;
    std::string saved = "not saved (no store)";
    if (!options_.store.empty()) {
        try {
            save_calibration(options_.store, wall_);
            saved = "saved to '" + options_.store.string() + "' (previous kept as .last-good)";
            if (!options_.models_store.empty()) {
                save_models(options_.models_store, {m.screen, m.camera, m.projectors});
                saved += ", models to '" + options_.models_store.string() + "'";
            }
        } catch (const std::exception& e) {
            saved = std::string("NOT saved: ") + e.what();
        }
    }
    r.journal.push_back(fmt("selfcal: correction applied at t=%.2f s; ", t_s) + saved +
                        "; after-correction drift follows in the next measured frames");
    report_after_ = true;
}

void SelfCalibrator::decide(double t_s, StepResult& r) {
    const SystemModel& m = monitor_.model();
    std::vector<int> drifting;
    for (std::size_t k = 0; k < filters_.size(); ++k) {
        ProjectorStatus& ps = r.status.projectors[k];
        const Pose6& x = filters_[k].state();
        ps.drift_px = drift_px(static_cast<int>(k), x);
        ps.rotation_deg = x.head<3>().norm() * kRad2Deg;
        ps.shift_mm = x.tail<3>().norm() * 1e3;
        // Hysteresis: once detected, a drift stays until it falls under half the threshold, so a
        // drift near the threshold cannot restart the hold time frame after frame.
        const bool holding = state_ == SelfcalState::drift_detected || state_ == SelfcalState::cannot_correct;
        // A measurement the filter rejected that says "no change" contests the drift: the state came from
        // an earlier, wrong measurement (few matches behind visitors, errors its covariance understates),
        // and correcting on it would move a projector that never moved. It stays contested until a
        // measurement is accepted or the rejected ones make a step (PoseKalman).
        // A fresh drift must be seen in two measured frames in a row: one measurement the filter accepted
        // can carry it past the threshold alone. A step (PoseKalman: rejected measurements that agree, a
        // bump's way into the filter) is that agreement already.
        const bool fresh = ps.drift_px > options_.drift_threshold_px &&
                           filters_[k].significance() > options_.kalman.gate_chi2 && !contested_[k];
        if (ps.measured) seen_above_[k] = fresh ? std::max(seen_above_[k] + 1, stepped_[k] ? 2 : 0) : 0;
        const bool above = !contested_[k] &&
                           (holding ? ps.drift_px > 0.5 * options_.drift_threshold_px : fresh && seen_above_[k] >= 2);
        if (above) {
            drifting.push_back(static_cast<int>(k));
        }
    }
    if (report_after_ && !r.status.waiting) {
        std::string line = "selfcal: after correction:";
        for (const ProjectorStatus& ps : r.status.projectors) line += fmt(" %.2f px", ps.drift_px) + " (" + ps.id + ")";
        r.journal.push_back(line);
        report_after_ = false;
    }
    if (check_lost(t_s, r)) return;
    if (drifting.empty()) {
        if (state_ != SelfcalState::calibrated) r.journal.push_back(fmt("selfcal: t=%.2f s: drift gone", t_s));
        state_ = SelfcalState::calibrated;
        reason_.clear();
        return;
    }
    if (state_ == SelfcalState::calibrated) {
        state_ = SelfcalState::drift_detected;
        drift_since_ = t_s;
        for (int k : drifting) {
            r.journal.push_back(fmt("selfcal: t=%.2f s: drift detected on ", t_s) +
                                m.projectors[static_cast<std::size_t>(k)].id +
                                fmt(": %.2f px", r.status.projectors[static_cast<std::size_t>(k)].drift_px));
        }
    }
    if (state_ != SelfcalState::drift_detected || t_s - drift_since_ < options_.hold_s) return;
    for (int k : drifting) {
        const auto uk = static_cast<std::size_t>(k);
        const double before = on_screen_fraction(m.projectors[uk]);
        const double after = on_screen_fraction(apply_delta(m.projectors[uk], filters_[uk].state()));
        if (after < (1.0 - options_.max_offscreen_loss) * before) {
            state_ = SelfcalState::cannot_correct;
            reason_ = m.projectors[uk].id +
                      fmt(" on-screen share %.0f %% of its calibrated %.0f %%", 100.0 * after, 100.0 * before);
            r.journal.push_back("selfcal: cannot correct (needs a full calibration): " + reason_);
            return;
        }
    }
    start_correction(t_s, drifting, r);
}

void SelfCalibrator::rebase_camera(double t_s, StepResult& r) {
    const Pose6& x = camera_filter_.state();
    const double deg = x.head<3>().norm() * kRad2Deg;
    r.status.camera_rotation_deg = deg;
    const bool moved = camera_drift_px(x) > options_.camera_rebase_px &&
                       camera_filter_.significance() > options_.camera_kalman.gate_chi2;
    if (!moved) {
        camera_since_ = -1.0;
        return;
    }
    if (camera_since_ < 0.0) camera_since_ = t_s;
    if (t_s - camera_since_ < options_.hold_s) return;
    const double shift_mm = x.tail<3>().norm() * 1e3;  // x is the filter's state: read before the reset
    const double moved_px = camera_drift_px(x);
    SystemModel m = monitor_.model();
    m.camera = apply_delta(m.camera, x);
    monitor_.set_reference(m, wall_);
    camera_filter_.reset();
    camera_since_ = -1.0;
    r.journal.push_back(fmt("selfcal: t=%.2f s: camera moved by %.3f deg, %.1f mm", t_s, deg, shift_mm) +
                        fmt(" (%.2f camera px): monitor re-based on it (the projectors are unaffected)", moved_px));
}

StepResult SelfCalibrator::step(const cv::Mat1f& content, const cv::Mat1f& camera_frame, double t_s) {
    StepResult r = run_step(content, camera_frame, t_s);
    // Too little texture: the pattern pair is asked for (only if configured) from the next frame on.
    if (options_.pattern.enabled && r.status.waiting && state_ != SelfcalState::correcting && !pattern_mode_) {
        pattern_mode_ = true;
        pattern_since_ = t_s;
        r.journal.push_back(fmt("selfcal: t=%.2f s: too little texture in the content: asking for the ", t_s) +
                            fmt("imperceptible pattern pair (amplitude %.3f) for %.0f s", options_.pattern.amplitude,
                                options_.pattern.recheck_s));
    }
    return r;
}

std::optional<cv::Mat1f> SelfCalibrator::pattern_for_refresh(std::int64_t k, cv::Size content_size) const {
    if (!pattern_mode_) return std::nullopt;
    if (pattern_.size() != content_size) pattern_ = fallback_pattern(content_size, options_.pattern);
    const double a = options_.pattern.amplitude * (k % 2 == 0 ? 1.0 : -1.0);
    cv::Mat1f out;
    pattern_.convertTo(out, CV_32F, a);
    return out;
}

StepResult SelfCalibrator::step_pattern(const cv::Mat1f& content, const cv::Mat1f& camera_plus,
                                        const cv::Mat1f& camera_minus, double t_s) {
    if (!options_.pattern.enabled) {
        throw std::invalid_argument("SelfCalibrator::step_pattern: the pattern fallback is off (pattern.enabled)");
    }
    if (camera_plus.size() != camera_minus.size()) {
        throw std::invalid_argument("SelfCalibrator::step_pattern: the two camera frames differ in size");
    }
    if (content.empty()) throw std::invalid_argument("SelfCalibrator::step_pattern: empty content frame");
    // The difference holds 2a P as the screen shows it: the prediction is P's, not the content's.
    if (pattern_.size() != content.size()) pattern_ = fallback_pattern(content.size(), options_.pattern);
    cv::Mat1f difference;
    cv::subtract(camera_plus, camera_minus, difference);
    StepResult r = run_step(pattern_, difference, t_s, true);
    r.status.from_pattern = true;
    if (pattern_mode_ && t_s - pattern_since_ >= options_.pattern.recheck_s) pattern_mode_ = false;
    return r;
}

StepResult SelfCalibrator::run_step(const cv::Mat1f& content, const cv::Mat1f& camera_frame, double t_s,
                                    bool pattern_pair) {
    if (!std::isfinite(t_s) || (started_ && t_s < last_t_)) {
        throw std::invalid_argument("SelfCalibrator::step: t_s must be finite and non-decreasing");
    }
    const double cpu0 = thread_cpu_ms();
    const double dt = started_ ? t_s - last_t_ : 0.0;
    started_ = true;
    last_t_ = t_s;
    StepResult r;
    r.status.t_s = t_s;
    if (!pending_journal_.empty()) r.journal.push_back(std::exchange(pending_journal_, std::string()));
    for (const autocal::DeviceModel& d : monitor_.model().projectors) r.status.projectors.push_back({d.id});
    if (state_ == SelfcalState::correcting) {
        advance_correction(t_s, r);
    } else {
        // Projectors moving (or about to step) stay out of the camera fit.
        std::vector<bool> suspects;
        for (std::size_t k = 0; k < filters_.size(); ++k) {
            suspects.push_back(filters_[k].pending() > 0 ||
                               drift_px(static_cast<int>(k), filters_[k].state()) > 0.5 * options_.drift_threshold_px);
        }
        const FrameMeasurement m = monitor_.measure(content, camera_frame, suspects, pattern_pair);
        filter(m, dt, r);
        rebase_camera(t_s, r);
        decide(t_s, r);
    }
    r.status.state = state_;
    if (state_ == SelfcalState::cannot_correct) r.status.reason = reason_;
    r.cpu_ms = thread_cpu_ms() - cpu0;
    return r;
}

}  // namespace mogao::selfcal
