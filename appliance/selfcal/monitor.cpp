// SPDX-License-Identifier: Apache-2.0
// Prediction, feature matching and per-frame pose fits (monitor.h).
#include "appliance/selfcal/monitor.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "appliance/autocal/bundle_adjust.h"
#include "appliance/autocal/screen_geometry.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao::selfcal {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

cv::Mat camera_matrix(const autocal::DeviceModel& c) {
    return (cv::Mat_<double>(3, 3) << c.fx_px, 0.0, c.cx_px, 0.0, c.fy_px, c.cy_px, 0.0, 0.0, 1.0);
}

// Undistorted normalised coordinates of camera image positions (same convention for points and cx).
std::vector<cv::Point2d> undistort(const autocal::DeviceModel& c, const std::vector<cv::Point2d>& image) {
    std::vector<cv::Point2d> out;
    if (image.empty()) return out;
    cv::undistortPoints(image, out, camera_matrix(c), cv::Mat(c.distortion, true));
    return out;
}

// Exposure-independent 8-bit view for the detector: scaled so the 99th percentile of the lit
// pixels is full scale, then gamma 1/2.2 (features in the darks count as much as in the lights).
cv::Mat1b to_u8(const cv::Mat1f& img, double gamma = 1.0 / 2.2) {
    std::vector<float> v;
    for (int y = 0; y < img.rows; y += 4)
        for (int x = 0; x < img.cols; x += 4) v.push_back(img(y, x));
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() * 99 / 100), v.end());
    const float p = std::max(1e-4f, v[v.size() * 99 / 100]);
    cv::Mat1f s;
    cv::max(img * (1.0f / p), 0.0f, s);
    cv::min(s, 1.0f, s);
    if (gamma != 1.0) cv::pow(s, gamma, s);
    cv::Mat1b out;
    s.convertTo(out, CV_8U, 255.0);
    return out;
}

double bilinear(const cv::Mat1f& m, double x, double y) {
    const int x0 = static_cast<int>(std::floor(x));
    const int y0 = static_cast<int>(std::floor(y));
    if (x0 < 0 || y0 < 0 || x0 + 1 >= m.cols || y0 + 1 >= m.rows) return std::nan("");
    const double fx = x - x0;
    const double fy = y - y0;
    return (1 - fy) * ((1 - fx) * m(y0, x0) + fx * m(y0, x0 + 1)) +
           fy * ((1 - fx) * m(y0 + 1, x0) + fx * m(y0 + 1, x0 + 1));
}

// Blend weight of projector k at screen point s under its reference model (0 outside its image).
double blend_at(const autocal::DeviceModel& d, const ProjectorCalibration& pc, const Eigen::Vector3d& s) {
    const Eigen::Vector2d n = project_normalised(d.rotation, d.position_m, s);
    if (!n.allFinite()) return 0.0;
    const Eigen::Vector2d px = autocal::device_image(d, {n.x(), n.y(), 1.0});  // through its lens distortion
    const double x = px.x();
    const double y = px.y();
    if (!(x >= 0.0 && y >= 0.0 && x < d.resolution.width && y < d.resolution.height)) return 0.0;
    return sample_blend(pc.blend, pc.output, static_cast<int>(x), static_cast<int>(y));
}

struct Match {
    cv::Point2d predicted;  // image positions
    cv::Point2d observed;
};

// Sub-pixel refinement of a match (ORB's keypoints sit on pyramid-level grids): the predicted
// patch around the predicted keypoint's pixel is correlated (normalised cross-correlation) with the
// camera frame around the observed keypoint, and the peak located to sub-pixel by a parabola
// through it and its neighbours on each axis (the usual 3-point fit, e.g. Szeliski, "Computer
// Vision", 2nd ed., 9.1). Returns false where the patch leaves the image or the peak is weak.
bool refine_match(const cv::Mat1b& pred, const cv::Mat1b& obs, cv::Point2f a, cv::Point2f b, Match& out) {
    constexpr int kHalf = 8;
    constexpr int kSearch = 3;
    const cv::Point ia(cvRound(a.x), cvRound(a.y));
    const cv::Point ib(cvRound(b.x), cvRound(b.y));
    const cv::Rect pr(ia.x - kHalf, ia.y - kHalf, 2 * kHalf + 1, 2 * kHalf + 1);
    const cv::Rect sr(ib.x - kHalf - kSearch, ib.y - kHalf - kSearch, 2 * (kHalf + kSearch) + 1,
                      2 * (kHalf + kSearch) + 1);
    const cv::Rect img(0, 0, pred.cols, pred.rows);
    if ((pr & img) != pr || (sr & img) != sr) return false;
    cv::Mat1f score;
    cv::matchTemplate(obs(sr), pred(pr), score, cv::TM_CCOEFF_NORMED);
    cv::Point peak;
    double best = 0.0;
    cv::minMaxLoc(score, nullptr, &best, nullptr, &peak);
    if (best < 0.7 || peak.x < 1 || peak.y < 1 || peak.x >= score.cols - 1 || peak.y >= score.rows - 1) return false;
    const auto vertex = [](float l, float c, float r) {
        const float d = l - 2.0f * c + r;
        return d < 0.0f ? 0.5f * (l - r) / d : 0.0f;
    };
    const float dx = vertex(score(peak.y, peak.x - 1), score(peak.y, peak.x), score(peak.y, peak.x + 1));
    const float dy = vertex(score(peak.y - 1, peak.x), score(peak.y, peak.x), score(peak.y + 1, peak.x));
    out.predicted = {ia.x + 0.5, ia.y + 0.5};
    out.observed = {ib.x - kSearch + peak.x + static_cast<double>(dx) + 0.5,
                    ib.y - kSearch + peak.y + static_cast<double>(dy) + 0.5};
    return true;
}

std::vector<Match> match_features(const cv::Mat1b& pred, const cv::Mat1b& mask, const cv::Mat1b& obs,
                                  const MonitorOptions& o, FrameMeasurement& m) {
    cv::Ptr<cv::ORB> orb = cv::ORB::create(o.orb_features);
    std::vector<cv::KeyPoint> kp, ko;
    cv::Mat dp, dob;
    orb->detectAndCompute(pred, mask, kp, dp);
    orb->detectAndCompute(obs, cv::noArray(), ko, dob);
    m.predicted_features = static_cast<int>(kp.size());
    m.observed_features = static_cast<int>(ko.size());
    std::vector<Match> out;
    if (kp.size() < 2 || ko.size() < 2) return out;
    cv::BFMatcher matcher(cv::NORM_HAMMING);
    std::vector<std::vector<cv::DMatch>> knn;
    matcher.knnMatch(dp, dob, knn, 2);
    for (const auto& k : knn) {
        if (k.size() < 2 || !(k[0].distance < o.ratio * k[1].distance)) continue;
        const cv::Point2f a = kp[static_cast<std::size_t>(k[0].queryIdx)].pt;
        const cv::Point2f b = ko[static_cast<std::size_t>(k[0].trainIdx)].pt;
        Match refined;
        if (cv::norm(a - b) > o.max_shift_px || !refine_match(pred, obs, a, b, refined)) continue;
        out.push_back(refined);
    }
    m.matches = static_cast<int>(out.size());
    return out;
}

constexpr double kWitnessNcc = 0.8;

// Occluders (visitors in front of the screen) are where the observed image disagrees with the
// predicted one in a spatially coherent blob: the photometric test of occluder and shadow
// detection in projector-camera displays (Sukthankar, Cham, Sukthankar 2001, "Dynamic shadow
// elimination for multi-projector displays", CVPR; Jaynes et al. 2004, "Camera-based detection
// and removal of shadows from interactive multiprojector displays", IEEE TVCG 10(3)). Compared on
// cells of `occluder_cell_px` camera pixels (area means: a texture moved by a few pixels, as by a
// bumped projector, hardly changes a cell's mean, while a body hides or replaces the light), after
// the frame's photometric map observed = a * predicted + b (exposure and ambient light) fitted by
// least squares on the cells within the ratio band, starting from their median ratio. Only cells
// whose texture agrees with the prediction in place (normalised cross-correlation above
// kWitnessNcc) pin the exposure: an occluder shows displaced or no content, so however much of
// the view it hides it cannot set the exposure (a brightness median alone took the occluders for
// the screen once they covered half of it). Flagged cells in connected blobs of at least `occluder_min_cells`
// are kept and grown by one cell (a feature's patch reaches over a blob's border). Returns a
// camera-resolution mask (255: occluded) and the share of the compared cells it covers.
cv::Mat1b occluder_mask(const cv::Mat1f& pred, const cv::Mat1f& obs, const cv::Mat1b& lit, const MonitorOptions& o,
                        double& fraction) {
    fraction = 0.0;
    const cv::Size cells(std::max(1, pred.cols / o.occluder_cell_px), std::max(1, pred.rows / o.occluder_cell_px));
    const auto cell_mean = [&](const cv::Mat& m) {
        cv::Mat1f out;
        cv::resize(m, out, cells, 0, 0, cv::INTER_AREA);
        return out;
    };
    cv::Mat1f litf;
    lit.convertTo(litf, CV_32F, 1.0 / 255.0);
    const cv::Mat1f mp = cell_mean(pred), mo = cell_mean(obs), ml = cell_mean(litf);
    cv::Mat pp, oo, po;
    cv::multiply(pred, pred, pp);
    cv::multiply(obs, obs, oo);
    cv::multiply(pred, obs, po);
    const cv::Mat1f mpp = cell_mean(pp), moo = cell_mean(oo), mpo = cell_mean(po);
    std::vector<cv::Point> used;
    std::vector<cv::Point> agree;  // cells whose texture matches the prediction in place: the exposure's witnesses
    std::vector<float> ratios;
    for (int y = 0; y < cells.height; ++y)
        for (int x = 0; x < cells.width; ++x) {
            if (!(ml(y, x) > 0.99f && mp(y, x) > 0.02f)) continue;
            used.emplace_back(x, y);
            const double vp = mpp(y, x) - mp(y, x) * mp(y, x);
            const double vo = moo(y, x) - mo(y, x) * mo(y, x);
            const double ncc = (mpo(y, x) - mp(y, x) * mo(y, x)) / std::sqrt(std::max(vp * vo, 1e-20));
            if (vp > 1e-5 && ncc > kWitnessNcc) {
                agree.emplace_back(x, y);
                ratios.push_back(mo(y, x) / mp(y, x));
            }
        }
    cv::Mat1b out(pred.size(), 0);
    if (agree.size() < 8) return out;  // nothing to pin the exposure on (e.g. the camera moved): no mask
    std::nth_element(ratios.begin(), ratios.begin() + static_cast<long>(ratios.size() / 2), ratios.end());
    double a = ratios[ratios.size() / 2];
    double b = 0.0;
    const auto outside = [&](cv::Point c) {
        const double expect = a * mp(c) + b;
        return mo(c) < o.occluder_ratio * expect || mo(c) * o.occluder_ratio > expect;
    };
    for (int iteration = 0; iteration < 3; ++iteration) {
        double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
        for (const cv::Point& c : agree) {
            if (outside(c)) continue;
            n += 1;
            sx += mp(c);
            sy += mo(c);
            sxx += static_cast<double>(mp(c)) * mp(c);
            sxy += static_cast<double>(mp(c)) * mo(c);
        }
        const double det = n * sxx - sx * sx;
        if (n < 8 || !(det > 1e-12)) break;
        a = (n * sxy - sx * sy) / det;
        b = (sy - a * sx) / n;
    }
    cv::Mat1b flagged(cells, 0);
    for (const cv::Point& c : used) flagged(c) = outside(c) ? 255 : 0;
    cv::Mat1i labels, stats;
    cv::Mat1d centroids;
    const int n = cv::connectedComponentsWithStats(flagged, labels, stats, centroids, 8, CV_32S);
    cv::Mat1b kept(cells, 0);
    for (int y = 0; y < cells.height; ++y)
        for (int x = 0; x < cells.width; ++x) {
            const int l = labels(y, x);
            if (l > 0 && l < n && stats(l, cv::CC_STAT_AREA) >= o.occluder_min_cells) kept(y, x) = 255;
        }
    cv::dilate(kept, kept, cv::Mat());
    int hidden = 0;
    for (const cv::Point& c : used) hidden += kept(c) ? 1 : 0;
    fraction = static_cast<double>(hidden) / static_cast<double>(used.size());
    cv::resize(kept, out, pred.size(), 0, 0, cv::INTER_NEAREST);
    return out;
}

// Drops the matches whose predicted or observed position lies on an occluder.
int drop_occluded(std::vector<Match>& matches, const cv::Mat1b& occluded) {
    const auto hit = [&](const cv::Point2d& p) {
        const int x = std::clamp(static_cast<int>(p.x), 0, occluded.cols - 1);
        const int y = std::clamp(static_cast<int>(p.y), 0, occluded.rows - 1);
        return occluded(y, x) != 0;
    };
    const auto before = matches.size();
    std::erase_if(matches, [&](const Match& m) { return hit(m.predicted) || hit(m.observed); });
    return static_cast<int>(before - matches.size());
}

// Whether the camera ray (normalised, undistorted) meets the screen inside its edges.
bool sees_screen(const autocal::ScreenModel& s, const autocal::DeviceModel& c, const cv::Point2d& q) {
    const Eigen::Vector3d p = autocal::ray_on_screen(s, c, Eigen::Vector3d(q.x, q.y, 1.0));
    const double theta = std::atan2(p.x(), -p.z());
    return p.allFinite() && std::abs(theta) <= s.arc_deg * kDeg / 2 && p.y() >= s.bottom_m && p.y() <= s.top_m;
}

}  // namespace

Eigen::Vector3d screen_point(const autocal::ScreenModel& s, double u, double v) {
    const double arc = s.arc_deg * kDeg;
    const double theta = u * arc - arc / 2.0;
    const double h = s.top_m - v * (s.top_m - s.bottom_m);
    return autocal::screen_position(s, theta, h);  // a bowed screen's own distance from the axis
}

Monitor::Monitor(const SystemModel& model, const ScreenCalibration& calibration, const MonitorOptions& options)
    : options_(options) {
    set_reference(model, calibration);
}

void Monitor::set_reference(const SystemModel& model, const ScreenCalibration& calibration) {
    if (model.projectors.size() != calibration.projectors.size() || model.projectors.empty() ||
        model.projectors.size() > 254) {
        throw std::invalid_argument("Monitor: the calibration and the models must have the same 1..254 projectors");
    }
    model_ = model;
    const autocal::DeviceModel& c = model.camera;
    const int w = c.resolution.width;
    const int h = c.resolution.height;
    std::vector<cv::Point2d> px;
    px.reserve(static_cast<std::size_t>(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) px.emplace_back(x + 0.5, y + 0.5);
    const std::vector<cv::Point2d> n = undistort(c, px);
    map_u_.create(h, w);
    map_v_.create(h, w);
    owner_.create(h, w);
    owner_weight_.create(h, w);
    mask_.create(h, w);
    const autocal::ScreenModel& s = model.screen;
    const double arc = s.arc_deg * kDeg;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const cv::Point2d& q = n[static_cast<std::size_t>(y) * w + x];
            const Eigen::Vector3d p = autocal::ray_on_screen(s, c, Eigen::Vector3d(q.x, q.y, 1.0));
            const double theta = std::atan2(p.x(), -p.z());
            const bool on = p.allFinite() && std::abs(theta) <= arc / 2 && p.y() >= s.bottom_m && p.y() <= s.top_m;
            double best = 0.0;
            int who = 255;
            double sum = 0.0;
            for (std::size_t k = 0; k < model.projectors.size() && on; ++k) {
                const double b = blend_at(model.projectors[k], calibration.projectors[k], p);
                sum += b;
                if (b > best) {
                    best = b;
                    who = static_cast<int>(k);
                }
            }
            const bool lit = sum > 0.0;
            map_u_(y, x) = lit ? static_cast<float>((theta + arc / 2) / arc) : std::nanf("");
            map_v_(y, x) = lit ? static_cast<float>((s.top_m - p.y()) / (s.top_m - s.bottom_m)) : std::nanf("");
            owner_(y, x) = static_cast<std::uint8_t>(best >= options_.owner_min_blend ? who : 255);
            owner_weight_(y, x) = best >= options_.owner_min_blend ? static_cast<float>(best) : 0.0f;
            mask_(y, x) = lit ? 255 : 0;
        }
    }
    // The screen's edges in the camera image (pixels within kEdgeBand of them), for edges_moved().
    cv::Mat1b on(h, w);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) on(y, x) = sees_screen(s, c, n[static_cast<std::size_t>(y) * w + x]) ? 255 : 0;
    }
    cv::Mat1b grown;
    cv::Mat1b shrunk;
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * kEdgeBand + 1, 2 * kEdgeBand + 1));
    cv::dilate(on, grown, kernel);
    cv::erode(on, shrunk, kernel);
    edge_band_.clear();
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            if (grown(y, x) != shrunk(y, x)) {
                edge_band_.push_back({x, y, n[static_cast<std::size_t>(y) * w + x], on(y, x) != 0});
            }
        }
    }
    // Features need their whole patch on the lit screen: keep them off its border.
    cv::erode(mask_, mask_, cv::Mat(), cv::Point(-1, -1), 8);
}

std::optional<bool> Monitor::edges_prefer(const autocal::DeviceModel& a, const autocal::DeviceModel& b,
                                          const cv::Mat1f& frame) const {
    double only_a = 0.0;  // mean brightness where a sees the screen and b does not
    double only_b = 0.0;  // and the other way round
    int n_a = 0;
    int n_b = 0;
    for (const EdgePixel& e : edge_band_) {
        const bool on_a = sees_screen(model_.screen, a, e.ray);
        const bool on_b = &b == &model_.camera ? e.on_reference : sees_screen(model_.screen, b, e.ray);
        if (on_a == on_b) continue;
        const double v = frame(e.y, e.x);
        if (on_a) {
            only_a += v;
            ++n_a;
        } else {
            only_b += v;
            ++n_b;
        }
    }
    if (n_a < kMinEdgePixels || n_b < kMinEdgePixels) return std::nullopt;  // edges not seen or the same
    only_a /= n_a;
    only_b /= n_b;
    // The screen is lit where the right camera says it is: a's strip lit and b's dark favours a.
    if (only_a > 2.0 * only_b + kEdgeContrast) return true;
    if (only_b > 2.0 * only_a + kEdgeContrast) return false;
    return std::nullopt;
}

std::optional<bool> Monitor::edges_moved(const autocal::DeviceModel& camera, const cv::Mat1f& frame) const {
    return edges_prefer(camera, model_.camera, frame);
}

std::optional<PoseFit> Monitor::camera_from_one_projector(const autocal::DeviceModel& camera,
                                                          const std::vector<Eigen::Vector3d>& points,
                                                          const std::vector<Eigen::Vector2d>& image,
                                                          const std::vector<int>& owner, const cv::Mat1f& frame) const {
    std::vector<PoseFit> moved;  // fits whose edges moved as the frame shows
    for (std::size_t k = 0; k < model_.projectors.size(); ++k) {
        std::vector<Eigen::Vector3d> p;
        std::vector<Eigen::Vector2d> q;
        for (std::size_t i = 0; i < points.size(); ++i) {
            if (owner[i] != static_cast<int>(k)) continue;
            p.push_back(points[i]);
            q.push_back(image[i]);
        }
        if (static_cast<int>(p.size()) < kMinHypothesisMatches) continue;
        // One projector's part of the screen hardly tells a turn from a shift: settle that
        // direction on "turn" (a knocked mount mostly turns) with the projectors' position prior.
        RobustPoseOptions narrow = options_.camera_fit;
        narrow.prior_position_sd_m = options_.projector_fit.prior_position_sd_m;
        PoseFit fit = fit_pose_robust(camera, p, q, narrow);
        if (fit.ok && edges_moved(fit.model, frame) == true) moved.push_back(std::move(fit));
    }
    if (moved.empty()) return std::nullopt;
    // A fit that moved part of the way also moves the edges the right way: among those, the one
    // whose edges the frame prefers to every other's (most pairwise wins; then most inliers).
    std::size_t best = 0;
    int best_wins = -1;
    for (std::size_t i = 0; i < moved.size(); ++i) {
        int wins = 0;
        for (std::size_t j = 0; j < moved.size(); ++j) {
            if (i != j && edges_prefer(moved[i].model, moved[j].model, frame) == true) ++wins;
        }
        if (wins > best_wins || (wins == best_wins && moved[i].inliers > moved[best].inliers)) {
            best = i;
            best_wins = wins;
        }
    }
    return std::move(moved[best]);
}

cv::Mat1f Monitor::predict(const cv::Mat1f& content) const {
    if (content.empty()) throw std::invalid_argument("Monitor::predict: empty content frame");
    cv::Mat1f mx(map_u_.size());
    cv::Mat1f my(map_u_.size());
    for (int y = 0; y < mx.rows; ++y) {
        for (int x = 0; x < mx.cols; ++x) {
            const float u = map_u_(y, x);
            mx(y, x) = std::isfinite(u) ? u * static_cast<float>(content.cols) - 0.5f : -1e4f;
            my(y, x) = std::isfinite(u) ? map_v_(y, x) * static_cast<float>(content.rows) - 0.5f : -1e4f;
        }
    }
    cv::Mat1f out;
    cv::remap(content, out, mx, my, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0.0);
    return out;
}

Monitor::ScreenMatches Monitor::match_on_screen(const cv::Mat1f& content, const cv::Mat1f& camera_frame,
                                                bool pattern_pair, FrameMeasurement& m) const {
    std::vector<Match> matches;
    if (pattern_pair) {
        // A difference of two frames: the dots on a zero background with the noise of two frames.
        // Linear mapping (a gamma would lift the background's noise to half scale) after a
        // Gaussian of 1 camera pixel on both images (the dots are wider; it halves the noise).
        cv::Mat1f pred;
        cv::Mat1f seen;
        cv::GaussianBlur(predict(content), pred, cv::Size(), 1.0);
        cv::GaussianBlur(camera_frame, seen, cv::Size(), 1.0);
        matches = match_features(to_u8(pred, 1.0), mask_, to_u8(seen, 1.0), options_, m);
    } else {
        const cv::Mat1f pred = predict(content);
        matches = match_features(to_u8(pred), mask_, to_u8(camera_frame), options_, m);
        if (options_.occluder_ratio > 0.0) {
            const cv::Mat1b occluded = occluder_mask(pred, camera_frame, mask_, options_, m.occluded_fraction);
            m.occluded_matches = drop_occluded(matches, occluded);
            m.matches = static_cast<int>(matches.size());
        }
    }
    ScreenMatches sm;
    std::vector<cv::Point2d> observed;
    for (const Match& mt : matches) {
        const double u = bilinear(map_u_, mt.predicted.x - 0.5, mt.predicted.y - 0.5);
        const double v = bilinear(map_v_, mt.predicted.x - 0.5, mt.predicted.y - 0.5);
        if (!std::isfinite(u) || !std::isfinite(v)) continue;
        sm.s_pred.push_back(screen_point(model_.screen, u, v));
        observed.push_back(mt.observed);
        const int px = static_cast<int>(mt.predicted.x);
        const int py = static_cast<int>(mt.predicted.y);
        sm.owner.push_back(owner_(py, px));
        const double w = owner_weight_(py, px);
        const bool small = cv::norm(mt.observed - mt.predicted) < options_.unmix_max_shift_px;
        sm.unmix.push_back(small && w > 0.0 && w < 1.0 ? 1.0 / w : 1.0);
    }
    for (const cv::Point2d& p : undistort(model_.camera, observed)) sm.obs_n.emplace_back(p.x, p.y);
    return sm;
}

void Monitor::fit_camera(const ScreenMatches& sm, const cv::Mat1f& camera_frame, const std::vector<bool>& suspects,
                         bool pattern_pair, FrameMeasurement& m) const {
    const autocal::DeviceModel& cam = model_.camera;
    const bool any_suspect = std::find(suspects.begin(), suspects.end(), true) != suspects.end();
    std::vector<Eigen::Vector3d> cam_points;
    std::vector<Eigen::Vector2d> cam_image;
    for (std::size_t i = 0; i < sm.s_pred.size(); ++i) {
        const bool suspect = sm.owner[i] == 255 ? any_suspect
                                                : (static_cast<std::size_t>(sm.owner[i]) < suspects.size() &&
                                                   suspects[static_cast<std::size_t>(sm.owner[i])]);
        if (suspect) continue;
        cam_points.push_back(sm.s_pred[i]);
        cam_image.push_back(sm.obs_n[i]);
    }
    m.camera = fit_pose_robust(cam, cam_points, cam_image, options_.camera_fit);
    // The screen does not move: a camera fit whose screen edges the frame shows where they were is
    // projectors moving together (e.g. two of three by the same yaw), not the camera.
    std::optional<bool> moved;
    if (m.camera.ok && !pattern_pair && options_.check_edges) {
        moved = edges_moved(m.camera.model, camera_frame);
        if (moved == false) {
            m.camera.ok = false;
            m.camera_edges_disagree = true;
        }
    }
    // The consensus can also hide a camera that did move: when the camera and two projectors
    // moved, one of those projectors may move with the camera in the image (a yaw of each) and
    // outvote the projector that stayed. The edges then moved while the accepted fit says they did
    // not; a camera fitted to one projector's matches alone whose edges did move is the camera.
    // Only where the consensus is contested (projectors suspected, or a tenth of the matches
    // against it): a static wall pays nothing for it.
    const bool contested = any_suspect || !m.camera.ok ||
                           static_cast<double>(m.camera.inliers) < 0.9 * static_cast<double>(cam_points.size());
    if (!pattern_pair && options_.check_edges && contested) {
        auto edge_camera = camera_from_one_projector(cam, sm.s_pred, sm.obs_n, sm.owner, camera_frame);
        // A consensus fit that moved the edges too stays unless the frame prefers the other's edges.
        if (edge_camera && moved == true && edges_prefer(edge_camera->model, m.camera.model, camera_frame) != true)
            edge_camera.reset();
        if (edge_camera) {
            m.camera = std::move(*edge_camera);
            m.camera_edges_disagree = false;
            m.camera_from_edges = true;
        }
    }
    if (m.camera.ok) m.camera_delta = pose_delta(cam, m.camera.model);
}

void Monitor::fit_projectors(const ScreenMatches& sm, FrameMeasurement& m) const {
    const autocal::DeviceModel& cam = model_.camera;
    const autocal::DeviceModel camera = m.camera.ok ? m.camera.model : cam;
    for (std::size_t k = 0; k < model_.projectors.size(); ++k) {
        const autocal::DeviceModel& d = model_.projectors[k];
        std::vector<Eigen::Vector3d> s_obs;
        std::vector<Eigen::Vector2d> x_k;
        for (std::size_t i = 0; i < sm.s_pred.size(); ++i) {
            if (sm.owner[i] != static_cast<int>(k)) continue;
            Eigen::Vector3d so = autocal::ray_on_screen(model_.screen, camera, {sm.obs_n[i].x(), sm.obs_n[i].y(), 1.0});
            // Un-mixing (MonitorOptions::unmix_max_shift_px); the cylinder's curvature over a
            // sub-pixel step is negligible, so the scaled point stays on the screen to ~1e-7 m.
            so = sm.s_pred[i] + sm.unmix[i] * (so - sm.s_pred[i]);
            const Eigen::Vector2d xn = project_normalised(d.rotation, d.position_m, sm.s_pred[i]);
            if (!so.allFinite() || !xn.allFinite()) continue;
            s_obs.push_back(so);
            x_k.push_back(xn);
        }
        ProjectorMeasurement& pm = m.projectors[k];
        pm.matches = static_cast<int>(s_obs.size());
        pm.fit = fit_pose_robust(d, s_obs, x_k, options_.projector_fit);
        if (pm.fit.ok) pm.delta = pose_delta(d, pm.fit.model);
    }
}

FrameMeasurement Monitor::measure(const cv::Mat1f& content, const cv::Mat1f& camera_frame,
                                  const std::vector<bool>& suspects, bool pattern_pair) const {
    const autocal::DeviceModel& cam = model_.camera;
    if (camera_frame.cols != cam.resolution.width || camera_frame.rows != cam.resolution.height) {
        throw std::invalid_argument("Monitor::measure: camera frame must be " + std::to_string(cam.resolution.width) +
                                    "x" + std::to_string(cam.resolution.height));
    }
    FrameMeasurement m;
    m.projectors.resize(model_.projectors.size());
    const ScreenMatches sm = match_on_screen(content, camera_frame, pattern_pair, m);
    fit_camera(sm, camera_frame, suspects, pattern_pair, m);
    fit_projectors(sm, m);
    return m;
}

}  // namespace mogao::selfcal
