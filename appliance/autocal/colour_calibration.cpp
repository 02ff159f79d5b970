// SPDX-License-Identifier: Apache-2.0
// Response, black level and matching of the projectors (colour_calibration.h, method there).
#include "appliance/autocal/colour_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "appliance/autocal/camera_clipping.h"
#include "appliance/autocal/colour_correction.h"
#include "appliance/autocal/screen_bounce.h"
#include "appliance/autocal/screen_geometry.h"
#include "appliance/warp/calibration_validation.h"
#include "appliance/warp/response_curve.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao::autocal {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::string channel_name(std::size_t c) { return std::string(1, "RGB"[c]); }

void check_options(const ColourOptions& o) {
    const auto fail = [](const std::string& what) { throw std::invalid_argument("calibrate_colour: " + what); };
    if (o.ramp_steps < 3 || o.ramp_steps > 64) fail("ramp_steps must be 3..64");
    if (o.dark_frames < 1 || o.dark_frames > 64) fail("dark_frames must be 1..64");
    if (!(o.dark_exposure >= 1.0 && o.dark_exposure <= 1000.0)) fail("dark_exposure must be in [1, 1000]");
    if (!(o.low_end_exposure >= 1.0 && o.low_end_exposure <= 1000.0)) fail("low_end_exposure must be in [1, 1000]");
    if (o.dither_frames < 1 || o.dither_frames > 64) fail("dither_frames must be 1..64");
    if (o.full_level_frames < 1 || o.full_level_frames > 64) fail("full_level_frames must be 1..64");
    if (!(o.dither_span >= 0.0 && o.dither_span <= 0.5)) fail("dither_span must be in [0, 0.5]");
    if (o.lut_entries < 2 || o.lut_entries > kMaxResponseEntries) fail("lut_entries must be 2..2^20");
    if (!(o.min_amplitude > 0.0 && o.min_amplitude < 1.0)) fail("min_amplitude must be in (0, 1)");
    if (!(o.max_fit_rms > 0.0)) fail("max_fit_rms must be > 0");
    if (o.mask_erode_px < 0 || o.mask_erode_px > 32) fail("mask_erode_px must be 0..32");
    if (o.falloff_min_samples < 6) fail("falloff_min_samples must be >= 6");
    if (!(o.vignetting_prior_sigma > 0.0)) fail("vignetting_prior_sigma must be > 0");
    if (o.vignetting_step_px < 1 || o.vignetting_step_px > 16) fail("vignetting_step_px must be 1..16");
}

// Projector k shows channel c at level s (the other channels and projectors black).
std::vector<cv::Mat> channel_signal(const std::vector<DeviceModel>& projectors, std::size_t k, std::size_t c,
                                    double s) {
    std::vector<cv::Mat> signals(projectors.size());
    const ImageSize r = projectors[k].resolution;
    cv::Scalar v(0.0, 0.0, 0.0);
    v[static_cast<int>(c)] = s;
    signals[k] = cv::Mat(r.height, r.width, CV_32FC3, v);
    return signals;
}

double masked_mean(const cv::Mat1f& image, const cv::Mat1b& mask) { return cv::mean(image, mask)[0]; }

double fit_gamma(const ChannelResponse& r, double* rms) {
    // Golden-section search of sum (R_i - s_i^g)^2 over g in [0.2, 8] (unimodal for monotone data).
    const auto cost = [&](double g) {
        double e = 0.0;
        for (std::size_t i = 0; i < r.levels.size(); ++i) e += std::pow(r.measured[i] - std::pow(r.levels[i], g), 2);
        return e;
    };
    double lo = 0.2;
    double hi = 8.0;
    const double phi = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int it = 0; it < 80; ++it) {
        const double a = hi - phi * (hi - lo);
        const double b = lo + phi * (hi - lo);
        (cost(a) < cost(b) ? hi : lo) = (cost(a) < cost(b) ? b : a);
    }
    const double g = (lo + hi) / 2.0;
    *rms = std::sqrt(cost(g) / static_cast<double>(r.levels.size()));
    return g;
}

struct Captured {
    cv::Mat2f screen;  // per camera pixel: the screen point (theta, h) it sees, NaN off the screen
    cv::Mat1f black;
    cv::Mat1f black_low;                        // all-black at low_end_exposure, averaged
    std::vector<cv::Mat1b> inside;              // per projector: camera pixels it clearly lights
    std::vector<cv::Mat1b> outside;             // per projector: camera pixels it clearly does not light
    std::vector<cv::Mat1f> full;                // per projector: its channels' full levels summed, minus black
    std::vector<std::array<cv::Mat1f, 3>> top;  // per projector and channel: its full level minus black
    // Per projector: its white minus black at low_end_exposure, in base exposure units, NaN where the camera
    // saturates (step 0's measurement where it does not light the screen); empty: not taken.
    std::vector<cv::Mat1f> white_low;
    cv::Mat1f flat;  // the camera's vignetting V per pixel (step 1a), empty: 1
    // Per projector, per camera pixel: the screen's gain G toward the camera (ScreenModel's comment) for that
    // projector's light there; empty on a matte screen (G = 1).
    std::vector<cv::Mat1f> to_camera;
};

// Camera pixel (x, y)'s value as the screen's light: divided by the camera's vignetting there.
float unvignetted(const cv::Mat1f& image, const Captured& cap, int x, int y) {
    return cap.flat.empty() ? image(y, x) : image(y, x) / cap.flat(y, x);
}

// G toward the camera of projector k's light at camera pixel (x, y) (1 on a matte screen).
double toward_camera(const Captured& cap, std::size_t k, int x, int y) {
    return cap.to_camera.empty() ? 1.0 : static_cast<double>(cap.to_camera[k](y, x));
}

// Captured::to_camera for the fitted models (a gain screen only).
std::vector<cv::Mat1f> gain_toward_camera(const cv::Mat2f& screen_at, const ScreenModel& screen,
                                          const DeviceModel& camera, const std::vector<DeviceModel>& projectors) {
    std::vector<cv::Mat1f> out;
    if (screen.gain == 1.0) return out;
    for (const DeviceModel& p : projectors) {
        cv::Mat1f g(screen_at.size(), 1.0F);
        for (int y = 0; y < g.rows; ++y) {
            for (int x = 0; x < g.cols; ++x) {
                const cv::Vec2f s = screen_at(y, x);
                if (std::isnan(s[0])) continue;
                g(y, x) = static_cast<float>(screen_gain_at(screen, s[0], s[1], p.position_m, camera.position_m));
            }
        }
        out.push_back(g);
    }
    return out;
}

// The screen point (theta, h) each camera pixel's centre sees through the camera model, NaN where
// it sees no screen (beyond the arc's ends or the heights).
cv::Mat2f camera_screen_points(const DeviceModel& camera, const ScreenModel& screen) {
    const ImageSize r = camera.resolution;
    std::vector<cv::Point2d> image;
    image.reserve(static_cast<std::size_t>(r.pixel_count()));
    for (int y = 0; y < r.height; ++y) {
        for (int x = 0; x < r.width; ++x) image.emplace_back(x + 0.5, y + 0.5);
    }
    const std::vector<Eigen::Vector3d> rays = camera_rays(camera, image);
    const double half_arc = screen.arc_deg * kDeg / 2.0;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    cv::Mat2f out(r.height, r.width, cv::Vec2f(nan, nan));
    for (int y = 0; y < r.height; ++y) {
        for (int x = 0; x < r.width; ++x) {
            const auto hit = cylinder_hit(screen, camera.position_m,
                                          camera.rotation * rays[static_cast<std::size_t>(y) * r.width + x]);
            if (!hit) continue;
            const double theta = std::atan2(hit->x(), -hit->z());
            if (std::abs(theta) <= half_arc && hit->y() >= screen.bottom_m && hit->y() <= screen.top_m) {
                out(y, x) = cv::Vec2f(static_cast<float>(theta), static_cast<float>(hit->y()));
            }
        }
    }
    return out;
}

// Projector d's image position that camera pixel (x, y) sees (NaN where none).
Eigen::Vector2d seen_pixel(const cv::Mat2f& screen_at, const DeviceModel& d, const ScreenModel& screen, int x, int y) {
    const cv::Vec2f s = screen_at(y, x);
    if (std::isnan(s[0])) return {std::nan(""), std::nan("")};
    return model_pixel(d, screen, s[0], s[1]);
}

// Step 1b: projector k's lens fall-off, the quadratic that fits its full-white image `full` (the
// channels summed, minus black) over the camera pixels `in` at the projector positions the
// models give them, in least squares; scaled to a mean of 1 over those pixels, which are
// returned in `samples` (the amplitudes A_kc are then their means, so that A_kc F(p) is the light).
LensFalloff fit_falloff(const Captured& cap, std::size_t k, const DeviceModel& d, const ScreenModel& screen,
                        const ColourOptions& o, std::vector<cv::Point>& samples) {
    const cv::Mat1f& full = cap.full[k];
    const cv::Mat1b& in = cap.inside[k];
    const cv::Mat2f& screen_at = cap.screen;
    Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
    Eigen::Matrix<double, 6, 1> basis_sum = Eigen::Matrix<double, 6, 1>::Zero();
    samples.clear();
    for (int y = 0; y < full.rows; ++y) {
        for (int x = 0; x < full.cols; ++x) {
            if (in(y, x) == 0) continue;
            const Eigen::Vector2d p = seen_pixel(screen_at, d, screen, x, y);
            if (!p.allFinite()) continue;
            const std::array<double, 6> b = falloff_basis(d, p.x(), p.y());
            const Eigen::Map<const Eigen::Matrix<double, 6, 1>> q(b.data());
            ata += q * q.transpose();
            atb += q * (static_cast<double>(unvignetted(full, cap, x, y)) / toward_camera(cap, k, x, y));
            basis_sum += q;
            samples.emplace_back(x, y);
        }
    }
    const std::string who = "projector " + std::to_string(k) + " '" + d.id + "'";
    if (static_cast<int>(samples.size()) < o.falloff_min_samples) {
        throw CalibrationRefused(
            who + ": the camera sees " + std::to_string(samples.size()) +
            " of its pixels where the models place it (need >= " + std::to_string(o.falloff_min_samples) +
            ") to measure its lens fall-off (ColourOptions::lens_falloff = false skips it)");
    }
    const Eigen::Matrix<double, 6, 1> g = ata.ldlt().solve(atb);
    const double mean = g.dot(basis_sum) / static_cast<double>(samples.size());
    LensFalloff f;
    for (int i = 0; i < 6; ++i) f.c[static_cast<std::size_t>(i)] = g[i] / mean;
    DeviceModel fitted = d;
    fitted.falloff = f;
    if (const auto bad = falloff_out_of_range(fitted)) {  // what the models file accepts (model_store.h)
        throw CalibrationRefused(who + ": its measured lens fall-off gives " + std::to_string(bad->z()) +
                                 " at image position (" + std::to_string(bad->x()) + ", " + std::to_string(bad->y()) +
                                 "), outside [0.05, 5] of its mean: not a lens (a changing exposure?)");
    }
    return f;
}

// The mean image of `signals` over camera images at relative exposure `exposure`, in its units. Raw frames:
// `frames` images at that exposure. Lossy frames (PatternSource::lossy_frames): max(frames, dithered) images at
// exposure (1 + span frac(j phi)), j = 0, 1, ... (phi the golden ratio's fraction: spread evenly over the span for
// any count), each divided by its factor (1 + ...); the span is cut where the first image's 99.9th percentile would
// pass 0.95 of full scale. 1 (full scale) wherever a frame saturates (>= 0.98), so that the callers' saturation
// tests see it. Changes the source's exposure only when it must (a dither, or exposure != 1), and then leaves it at
// the locked one (1), also when show() throws.
// Why (ColourOptions::dither_frames): a Motion-JPEG camera quantises each 8 x 8 block's mean in steps of about a
// code and drops the noise that would dither it, so a flat field's slowly varying light gives wide areas the same
// rounding, the same in every frame at one exposure. At quality 72 the full-level images were off by up to 0.7 %
// of a channel's white: the joint fit of step 1a read the camera's vignetting as a 0.175, b 0.051 for a 0.208,
// b 0 (raw frames: 0.205, 0.005), and the ramp's lower levels and black were off by more. Each exposure moves every
// block's light by a different fraction of its step, so the mean over several dithers the rounding out.
cv::Mat1f exposure_dithered_mean(PatternSource& source, const std::vector<cv::Mat>& signals, double exposure,
                                 int frames, int dithered, double span, int& captures) {
    const bool dither = source.lossy_frames() && dithered > 1 && span > 0.0;
    const int n = dither ? std::max(frames, dithered) : frames;
    const bool changes = dither || exposure != 1.0;
    const double phi = (std::sqrt(5.0) - 1.0) / 2.0;
    cv::Mat1f sum;
    cv::Mat1f peak;
    try {
        for (int j = 0; j < n; ++j) {
            const double factor = dither ? 1.0 + span * std::fmod(j * phi, 1.0) : 1.0;
            if (changes && (j == 0 || dither)) source.set_relative_exposure(exposure * factor);
            const cv::Mat1f img = source.show(signals);
            ++captures;
            if (j == 0) {
                sum = cv::Mat1f(img.size(), 0.0f);
                peak = img.clone();
                if (dither) {
                    std::vector<float> v(img.begin(), img.end());
                    const auto at = v.begin() + static_cast<long>(v.size() * 999 / 1000);
                    std::nth_element(v.begin(), at, v.end());
                    span = std::clamp(0.95 / std::max(static_cast<double>(*at), 1e-6) - 1.0, 0.0, span);
                }
            }
            sum += img / static_cast<float>(factor);
            peak = cv::max(peak, img);
        }
    } catch (...) {
        if (changes) source.set_relative_exposure(1.0);
        throw;
    }
    if (changes) source.set_relative_exposure(1.0);
    sum /= static_cast<float>(n);
    sum.setTo(1.0f, peak >= kCameraClipLevel);
    return sum;
}

// Step 1's low end for channel c of projector k: levels up to 1/4 again, and 1/32, 1/16, at
// low_end_exposure x the locked exposure (a few camera codes at the base exposure), in base
// exposure units; replaces or adds to the measured levels unless the camera saturates there.
void measure_low_end(PatternSource& source, const std::vector<DeviceModel>& projectors, std::size_t k, std::size_t c,
                     const ColourOptions& o, const Captured& cap, const cv::Mat1b& in, ChannelResponse& r,
                     int& captures) {
    std::vector<double> low{1.0 / 32.0, 1.0 / 16.0};
    for (const double s : r.levels) {
        if (s > 0.0 && s <= 0.25 && s != low[0] && s != low[1]) low.push_back(s);
    }
    std::vector<std::pair<double, double>> got;
    for (const double s : low) {
        const cv::Mat1f img = exposure_dithered_mean(source, channel_signal(projectors, k, c, s), o.low_end_exposure, 1,
                                                     o.dither_frames, o.dither_span, captures);
        double peak = 0.0;
        cv::minMaxLoc(img, nullptr, &peak, nullptr, nullptr, in);
        if (peak >= 0.98) continue;  // saturated: keep the base-exposure value
        cv::Mat1f d;
        cv::subtract(img, cap.black_low, d);
        got.emplace_back(s, masked_mean(d, in) / o.low_end_exposure);
    }
    for (const auto& [s, v] : got) {
        const auto it = std::find(r.levels.begin(), r.levels.end(), s);
        if (it != r.levels.end()) {
            r.measured[static_cast<std::size_t>(it - r.levels.begin())] = v;
            continue;
        }
        const auto pos = std::upper_bound(r.levels.begin(), r.levels.end(), s) - r.levels.begin();
        r.levels.insert(r.levels.begin() + pos, s);
        r.measured.insert(r.measured.begin() + pos, v);
    }
}

// Refused where a channel's full level saturates the camera on more than 1 % of the pixels the projector lights:
// the response, the fall-off, the vignetting and the screen's bounce are all measured from those images, and a
// clipped hot spot (a gain screen filmed brightly) reads as a dimmer projector there (seams of 5 % at white on
// realistic-screen at exposure 2.4 at half scale, where the geometry still calibrates).
void require_unclipped_channels(const cv::Mat1b& clipped, const cv::Mat1b& in, std::size_t k, const std::string& id) {
    cv::Mat1b both;
    cv::bitwise_and(clipped, in, both);
    const int n_clipped = cv::countNonZero(both);
    const int n_in = cv::countNonZero(in);
    if (n_clipped <= n_in / 100) return;
    char why[400];
    std::snprintf(why, sizeof why,
                  "colour: projector %zu '%s': a channel's full level saturates the camera on %d of the %d pixels it "
                  "lights (more than 1 %%): its response and brightness cannot be measured there; the camera is set "
                  "too bright for the colour step; lower its exposure or gain",
                  k, id.c_str(), n_clipped, n_in);
    throw CalibrationRefused(why);
}

// Step 1 for projector k: ramps per channel, the coverage masks from the full-level images.
ProjectorPhotometry measure_projector(PatternSource& source, const std::vector<DeviceModel>& projectors, std::size_t k,
                                      const ColourOptions& o, Captured& cap, int& captures) {
    ProjectorPhotometry pp;
    pp.id = projectors[k].id;
    const int n = o.ramp_steps;
    std::array<std::vector<cv::Mat1f>, 3> diffs;
    cv::Mat1f full(cap.black.size(), 0.0f);
    cv::Mat1b clipped(cap.black.size(), uchar{0});  // a channel's full level saturates the camera
    for (std::size_t c = 0; c < 3; ++c) {
        for (int i = 1; i < n; ++i) {
            const double s = static_cast<double>(i) / (n - 1);
            const cv::Mat1f seen =
                exposure_dithered_mean(source, channel_signal(projectors, k, c, s), 1.0, 1,
                                       i == n - 1 ? o.full_level_frames : o.dither_frames, o.dither_span, captures);
            if (i == n - 1) clipped.setTo(1, seen >= kCameraClipLevel);
            cv::Mat1f d;
            cv::subtract(seen, cap.black, d);
            diffs[c].push_back(d);
        }
        full += diffs[c].back();
    }
    // Coverage: above half the bright end (99th percentile) of the summed full-level difference.
    std::vector<float> values(full.begin(), full.end());
    std::nth_element(values.begin(), values.begin() + static_cast<long>(values.size() * 99 / 100), values.end());
    const double top = values[values.size() * 99 / 100];
    const cv::Mat kernel =
        cv::getStructuringElement(cv::MORPH_RECT, {2 * o.mask_erode_px + 1, 2 * o.mask_erode_px + 1});
    cv::Mat1b in;
    cv::Mat1b out;
    cv::compare(full, 0.5 * top, in, cv::CMP_GT);
    cv::compare(full, 0.1 * top, out, cv::CMP_LT);
    cv::erode(in, in, kernel);
    cv::erode(out, out, kernel);
    cap.inside.push_back(in);
    cap.outside.push_back(out);
    if (cv::countNonZero(in) < 100) {
        throw CalibrationRefused("projector " + std::to_string(k) + " '" + pp.id + "': the camera sees only " +
                                 std::to_string(cv::countNonZero(in)) +
                                 " pixels of it (need >= 100) to measure its response");
    }
    require_unclipped_channels(clipped, in, k, pp.id);
    cap.full.push_back(full);
    cap.top.push_back({diffs[0].back(), diffs[1].back(), diffs[2].back()});
    for (std::size_t c = 0; c < 3; ++c) {
        ChannelResponse& r = pp.channels[c];
        r.levels.push_back(0.0);
        r.measured.push_back(0.0);
        for (int i = 1; i < n; ++i) {
            r.levels.push_back(static_cast<double>(i) / (n - 1));
            r.measured.push_back(masked_mean(diffs[c][static_cast<std::size_t>(i - 1)], in));
        }
        r.amplitude = r.measured.back();
        measure_low_end(source, projectors, k, c, o, cap, in, r, captures);
        if (!(r.amplitude >= o.min_amplitude)) {
            throw CalibrationRefused("projector " + std::to_string(k) + " '" + pp.id + "' channel " + channel_name(c) +
                                     ": full white reaches " + std::to_string(r.amplitude) +
                                     " of the camera's range (need >= " + std::to_string(o.min_amplitude) +
                                     "): raise the camera's locked exposure");
        }
        double running = 0.0;
        for (double& v : r.measured) {
            v = std::max(running, std::clamp(v / r.amplitude, 0.0, 1.0));  // non-decreasing (noise)
            running = v;
        }
        r.gamma = fit_gamma(r, &r.gamma_rms);
        if (!(r.gamma_rms <= o.max_fit_rms)) {
            throw CalibrationRefused("projector " + std::to_string(k) + " '" + pp.id + "' channel " + channel_name(c) +
                                     ": measured response is " + std::to_string(r.gamma_rms) +
                                     " rms from the nearest gamma (gate " + std::to_string(o.max_fit_rms) +
                                     "): not a projector response (saturation, changing exposure?)");
        }
    }
    return pp;
}

// Step 1b for projector k (after step 1a): its fall-off, and A_kc with it: the full level's mean (the screen's
// light, unvignetted) over the pixels the fall-off was fitted on.
void measure_falloff(const Captured& cap, const ScreenModel& screen, const DeviceModel& d, std::size_t k,
                     const ColourOptions& o, ProjectorPhotometry& pp) {
    std::vector<cv::Point> samples;
    pp.falloff = fit_falloff(cap, k, d, screen, o, samples);
    for (std::size_t c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (const cv::Point& p : samples)
            sum += unvignetted(cap.top[k][c], cap, p.x, p.y) / toward_camera(cap, k, p.x, p.y);
        pp.channels[c].amplitude = sum / static_cast<double>(samples.size());
    }
}

// Step 1a: the camera's vignetting from every projector's full-level image (camera_vignetting.h), and its map
// over the camera's pixels into cap.flat.
CameraVignetting measure_vignetting(Captured& cap, const ScreenModel& screen, const DeviceModel& camera,
                                    const std::vector<DeviceModel>& projectors, const ColourOptions& o) {
    std::vector<FlatFieldSample> samples;
    const int step = o.vignetting_step_px;
    for (std::size_t k = 0; k < projectors.size(); ++k) {
        for (int y = step / 2; y < cap.full[k].rows; y += step) {
            for (int x = step / 2; x < cap.full[k].cols; x += step) {
                if (cap.inside[k](y, x) == 0) continue;
                const Eigen::Vector2d p = seen_pixel(cap.screen, projectors[k], screen, x, y);
                if (!p.allFinite()) continue;
                samples.push_back({k, static_cast<double>(cap.full[k](y, x)) / toward_camera(cap, k, x, y),
                                   radial_rho2(camera, x + 0.5, y + 0.5), radial_rho2(projectors[k], p.x(), p.y())});
            }
        }
    }
    if (static_cast<int>(samples.size()) < o.falloff_min_samples) return {};  // fit_falloff refuses next
    const CameraVignetting v = fit_camera_vignetting(samples, projectors.size(), o.vignetting_prior_sigma);
    cap.flat = cv::Mat1f(cap.full[0].size());
    for (int y = 0; y < cap.flat.rows; ++y) {
        for (int x = 0; x < cap.flat.cols; ++x) {
            cap.flat(y, x) = static_cast<float>(vignetting_at(v, radial_rho2(camera, x + 0.5, y + 0.5)));
        }
    }
    return v;
}

// The black images' exposure multiplier: dark_exposure, or less where the brightest black a projector lights (the
// 99.9th percentile of cap.black, measured at low_end_exposure) would pass kDarkHeadroom of full scale at it: a
// camera exposed brightly (a gain screen's hot spot) then still measures every black instead of clipping the
// brightest (which the least squares would drop, biasing the blacks low) or refusing. Not below low_end_exposure,
// where the ramp's low end is measured; a camera that bright is refused below (saturated pixels).
constexpr double kDarkHeadroom = 0.9;

double dark_exposure_for(const Captured& cap, const ColourOptions& o) {
    std::vector<float> lit_black;
    for (int y = 0; y < cap.black.rows; ++y) {
        for (int x = 0; x < cap.black.cols; ++x) {
            bool lit = false;
            for (const cv::Mat1b& in : cap.inside) lit = lit || in(y, x) != 0;
            if (lit) lit_black.push_back(cap.black(y, x));
        }
    }
    if (lit_black.empty()) return o.dark_exposure;
    const auto at = lit_black.begin() + static_cast<long>(lit_black.size() * 999 / 1000);
    std::nth_element(lit_black.begin(), at, lit_black.end());
    const double brightest = std::max(static_cast<double>(*at), 1e-9);
    return std::clamp(kDarkHeadroom / brightest, std::min(o.low_end_exposure, o.dark_exposure), o.dark_exposure);
}

// Step 2: betas and ambient by least squares on the long-exposure black image; a projector's black
// passes its lens, so its regressor is its fall-off at the pixel (1 where it is flat).
void measure_black(PatternSource& source, const ColourOptions& o, const Captured& cap, const ScreenModel& screen,
                   const std::vector<DeviceModel>& projectors, std::vector<ProjectorPhotometry>& pps, double& ambient,
                   int& captures) {
    const std::size_t n = pps.size();
    const double exposure = dark_exposure_for(cap, o);
    const cv::Mat1f dark = exposure_dithered_mean(source, std::vector<cv::Mat>(n), exposure, o.dark_frames,
                                                  o.dither_frames, o.dither_span, captures);
    Eigen::MatrixXd ata = Eigen::MatrixXd::Zero(static_cast<long>(n) + 1, static_cast<long>(n) + 1);
    Eigen::VectorXd atb = Eigen::VectorXd::Zero(static_cast<long>(n) + 1);
    long rows = 0;
    long overlaps = 0;
    long saturated = 0;
    for (int y = 0; y < dark.rows; ++y) {
        for (int x = 0; x < dark.cols; ++x) {
            Eigen::VectorXd a = Eigen::VectorXd::Zero(static_cast<long>(n) + 1);
            a[0] = 1.0;
            int lit = 0;
            bool clear = true;
            for (std::size_t k = 0; k < n && clear; ++k) {
                const bool in = cap.inside[k](y, x) != 0;
                clear = in || cap.outside[k](y, x) != 0;
                double f = 1.0;
                if (in && !projectors[k].falloff.flat()) {
                    const Eigen::Vector2d p = seen_pixel(cap.screen, projectors[k], screen, x, y);
                    if (p.allFinite()) f = falloff_at(projectors[k], p.x(), p.y());
                }
                a[static_cast<long>(k) + 1] = in ? f * toward_camera(cap, k, x, y) : 0.0;
                lit += in;
            }
            if (!clear || lit == 0) continue;
            if (dark(y, x) >= 0.999f) {
                ++saturated;
                continue;
            }
            ata += a * a.transpose();
            atb += a * (static_cast<double>(unvignetted(dark, cap, x, y)) / exposure);
            ++rows;
            overlaps += lit >= 2;
        }
    }
    if (saturated > rows / 100) {
        char why[320];
        std::snprintf(why, sizeof why,
                      "black level: %ld camera pixels (of %ld) saturate in the black images, filmed at %g times the "
                      "camera's locked exposure (as low as the black's measurement allows): the camera is set too "
                      "bright for the projectors' black; lower its exposure or gain",
                      saturated, saturated + rows, exposure);
        throw CalibrationRefused(why);
    }
    ambient = 0.0;
    for (ProjectorPhotometry& pp : pps) pp.black = 0.0;
    if (overlaps < 50) return;  // no overlap seen: the betas are not separable, and nothing to compensate
    const Eigen::VectorXd sol = ata.ldlt().solve(atb);
    ambient = sol[0];
    for (std::size_t k = 0; k < n; ++k) pps[k].black = std::max(0.0, sol[static_cast<long>(k) + 1]);
}

// The all-black image at the locked exposure (cap.black) and at low_end_exposure (4 averaged, into cap.black_low);
// cap.black then from cap.black_low wherever that is not saturated (the camera is linear in exposure): a camera
// clips its noise at 0, so a dark image's mean reads high (by 0.008 of full scale on the noisy rig, 3 % read
// noise), and every ramp level minus that black read low, most at the low end: the response looked steeper (gamma
// 2.29 for 2.2) and the seams got worse. Returns the captures taken.
int capture_blacks(PatternSource& source, const ColourOptions& options, std::size_t n, Captured& cap) {
    int captures = 0;
    cap.black = exposure_dithered_mean(source, std::vector<cv::Mat>(n), 1.0, 1, options.dither_frames,
                                       options.dither_span, captures);
    cap.black_low = exposure_dithered_mean(source, std::vector<cv::Mat>(n), options.low_end_exposure, 4,
                                           options.dither_frames, options.dither_span, captures);
    for (int y = 0; y < cap.black.rows; ++y) {
        for (int x = 0; x < cap.black.cols; ++x) {
            if (cap.black_low(y, x) < kCameraClipLevel) {
                cap.black(y, x) = cap.black_low(y, x) / static_cast<float>(options.low_end_exposure);
            }
        }
    }
    return captures;
}

}  // namespace

Eigen::Vector2d model_pixel(const DeviceModel& d, const ScreenModel& s, double theta, double h) {
    const Eigen::Vector3d q = d.rotation.transpose() * (screen_position(s, theta, h) - d.position_m);
    const Eigen::Vector2d xy = device_image(d, q);  // through its distortion (NaN fails the test below)
    if (q.z() <= 0.0 ||
        !(xy.x() >= 0.0 && xy.x() < d.resolution.width && xy.y() >= 0.0 && xy.y() < d.resolution.height)) {
        return {std::nan(""), std::nan("")};
    }
    return xy;
}

double response_at(const ChannelResponse& r, double s) {
    s = std::clamp(s, 0.0, 1.0);
    const std::vector<double>& l = r.levels;
    const std::vector<double>& m = r.measured;
    std::size_t i = 1;
    while (i + 1 < l.size() && s > l[i + 1]) ++i;
    // Segment [l[i], l[i + 1]] (i >= 1); below l[1] the first segment's power law continues.
    if (i + 1 >= l.size()) return m.back();
    const double a = m[i];
    const double b = m[i + 1];
    if (s <= 0.0) return 0.0;
    if (a > 0.0 && b > a) {
        const double e = std::log(b / a) / std::log(l[i + 1] / l[i]);
        return std::min(1.0, a * std::pow(s / l[i], e));
    }
    return s <= l[i] ? a * s / l[i] : a + (b - a) * (s - l[i]) / (l[i + 1] - l[i]);
}

// Step 0's measurement: each projector's white (every channel at full level) at low_end_exposure, minus the black
// at that exposure, in base exposure units; NaN where the camera saturates. Where the projector does not light the
// screen its light's bounce is a few camera codes at the base exposure, and a Motion-JPEG camera quantises a flat
// dark area's 8 x 8 block means in steps of about a code, the same error in every block: fitted there, a matte
// screen read rho 0.02 (0.0004 from raw frames), and the bounce taken out left each projector a spurious
// fall-off. At this exposure the same step is low_end_exposure times smaller. Returns the captures taken.
int capture_bounce_whites(PatternSource& source, const std::vector<DeviceModel>& projectors, const ColourOptions& o,
                          Captured& cap) {
    int captures = 0;
    for (std::size_t k = 0; k < projectors.size(); ++k) {
        std::vector<cv::Mat> signals(projectors.size());
        const ImageSize r = projectors[k].resolution;
        signals[k] = cv::Mat(r.height, r.width, CV_32FC3, cv::Scalar(1.0, 1.0, 1.0));
        const cv::Mat1f img =
            exposure_dithered_mean(source, signals, o.low_end_exposure, 1, o.dither_frames, o.dither_span, captures);
        cv::Mat1f d(img.size());
        for (int y = 0; y < img.rows; ++y) {
            for (int x = 0; x < img.cols; ++x) {
                d(y, x) = img(y, x) >= kCameraClipLevel
                              ? std::numeric_limits<float>::quiet_NaN()
                              : (img(y, x) - cap.black_low(y, x)) / static_cast<float>(o.low_end_exposure);
            }
        }
        cap.white_low.push_back(d);
    }
    return captures;
}

// Step 0: the screen's own light out of every full-level image (ColourOptions::screen_bounce): the bounce of the
// light each image shows on the screen's patches (divided by the gain toward the camera, the light leaving them
// matte), rho fitted where the projector does not light the screen (its `outside` mask eroded by 8 more
// pixels, away from its blurred edge; from capture_bounce_whites' images where taken), then rho times that bounce
// subtracted.
void remove_screen_bounce(Captured& cap, const ScreenModel& screen, ColourResult& res) {
    const ScreenBounce patches(screen);
    cv::Mat1i patch_of(cap.screen.size(), -1);
    std::vector<double> pixels_in(static_cast<std::size_t>(patches.patches()), 0.0);
    for (int y = 0; y < patch_of.rows; ++y) {
        for (int x = 0; x < patch_of.cols; ++x) {
            const cv::Vec2f s = cap.screen(y, x);
            if (std::isnan(s[0])) continue;
            patch_of(y, x) = patches.patch_at(s[0], s[1]);
            if (patch_of(y, x) >= 0) pixels_in[static_cast<std::size_t>(patch_of(y, x))] += 1.0;
        }
    }
    const auto bounce_image = [&](const cv::Mat1f& image, std::size_t k) {
        std::vector<double> leaving(pixels_in.size(), 0.0);
        for (int y = 0; y < image.rows; ++y)
            for (int x = 0; x < image.cols; ++x)
                if (patch_of(y, x) >= 0 && cap.outside[k](y, x) == 0)
                    leaving[static_cast<std::size_t>(patch_of(y, x))] += image(y, x) / toward_camera(cap, k, x, y);
        for (std::size_t p = 0; p < leaving.size(); ++p) leaving[p] /= std::max(1.0, pixels_in[p]);
        const std::vector<double> field = patches.bounce(leaving);
        cv::Mat1f out(image.size(), 0.0f);
        for (int y = 0; y < image.rows; ++y)
            for (int x = 0; x < image.cols; ++x)
                if (patch_of(y, x) >= 0)
                    out(y, x) = static_cast<float>(patches.at(field, cap.screen(y, x)[0], cap.screen(y, x)[1]));
        return out;
    };
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, {17, 17});
    // Per projector, each channel's bounce; the bounce is linear in the light and `full` is the channels' sum,
    // so its bounce is theirs.
    std::vector<std::array<cv::Mat1f, 3>> bounce_top;
    double sxy = 0.0, sxx = 0.0;
    for (std::size_t k = 0; k < cap.full.size(); ++k) {
        bounce_top.push_back(
            {bounce_image(cap.top[k][0], k), bounce_image(cap.top[k][1], k), bounce_image(cap.top[k][2], k)});
        cv::Mat1f bounce_full;
        cv::add(bounce_top[k][0], bounce_top[k][1], bounce_full);
        bounce_full += bounce_top[k][2];
        cv::Mat1b far;
        cv::erode(cap.outside[k], far, kernel);
        for (int y = 0; y < far.rows; ++y) {
            for (int x = 0; x < far.cols; ++x) {
                if (far(y, x) == 0 || patch_of(y, x) < 0) continue;
                const float seen = cap.white_low.empty() ? cap.full[k](y, x) : cap.white_low[k](y, x);
                if (std::isnan(seen)) continue;
                sxy += static_cast<double>(seen) * bounce_full(y, x);
                sxx += static_cast<double>(bounce_full(y, x)) * bounce_full(y, x);
                ++res.screen_bounce_samples;
            }
        }
    }
    res.screen_bounce_reflectance = sxx > 0.0 ? std::max(0.0, sxy / sxx) : 0.0;
    const auto rho = static_cast<float>(res.screen_bounce_reflectance);
    if (rho == 0.0f) return;
    for (std::size_t k = 0; k < cap.full.size(); ++k) {
        for (std::size_t c = 0; c < 3; ++c) {
            cap.full[k] -= rho * bounce_top[k][c];
            cap.top[k][c] -= rho * bounce_top[k][c];
        }
    }
}

// The screen lobe's half-gain angle that best explains the projectors' full-white images (a gain screen,
// with the camera's vignetting measured; ColourOptions::estimate_half_gain_angle): the angle b in [10, 90]
// degrees whose gain toward the camera, divided out, leaves the smallest residual in step 1a's joint fit
// of a radial camera vignetting and a radial fall-off per projector. A wrong b leaves each projector's
// light a lobe about its own mirror point, which neither radial family takes up (docs/calibration.md,
// "Screen gain"). A grid of 5 degrees brackets the minimum, a golden-section search refines it to 0.05.
// Returns b, or the told one (and `estimated` false) where the fit has too few samples.
double estimate_half_gain_angle(const Captured& cap, const ScreenModel& told, const DeviceModel& camera,
                                const std::vector<DeviceModel>& projectors, const ColourOptions& o, double& told_rms,
                                double& rms, bool& estimated) {
    const auto residual = [&](double b) {
        ScreenModel trial = told;
        trial.half_gain_angle_deg = b;
        Captured c = cap;  // shares the images; its gain and vignetting maps are its own
        c.to_camera = gain_toward_camera(cap.screen, trial, camera, projectors);
        const CameraVignetting v = measure_vignetting(c, trial, camera, projectors, o);
        return v.measured ? v.rms : std::numeric_limits<double>::quiet_NaN();
    };
    told_rms = residual(told.half_gain_angle_deg);
    estimated = std::isfinite(told_rms);
    if (!estimated) return told.half_gain_angle_deg;
    double best = 10.0;
    double best_rms = residual(best);
    for (double b = 15.0; b <= 90.0; b += 5.0) {
        const double r = residual(b);
        if (r < best_rms) best = b, best_rms = r;
    }
    double lo = std::max(10.0, best - 5.0);
    double hi = std::min(90.0, best + 5.0);
    const double phi = (std::sqrt(5.0) - 1.0) / 2.0;
    double a = hi - phi * (hi - lo), fa = residual(a);
    double b = lo + phi * (hi - lo), fb = residual(b);
    while (hi - lo > 0.05) {
        if (fa < fb) {
            hi = b, b = a, fb = fa, a = hi - phi * (hi - lo), fa = residual(a);
        } else {
            lo = a, a = b, fa = fb, b = lo + phi * (hi - lo), fb = residual(b);
        }
    }
    const double found = (lo + hi) / 2.0;
    rms = residual(found);
    return found;
}

void keep_screen_measurements(const ColourResult& colour, ScreenModel& screen) {
    screen.half_gain_angle_deg = colour.half_gain_angle_deg;
    screen.interreflection = std::clamp(colour.screen_bounce_reflectance, 0.0, 0.99);
}

ColourResult calibrate_colour(PatternSource& source, const ScreenModel& told, const DeviceModel& camera,
                              std::vector<DeviceModel>& models, ScreenCalibration& calibration,
                              const ColourOptions& options) {
    std::vector<DeviceModel> projectors = models;  // `models` changes only when all has succeeded
    ScreenModel screen = told;                     // its half-gain angle estimated below (a gain screen)
    check_options(options);
    if (projectors.size() != calibration.projectors.size() || projectors.empty()) {
        throw std::invalid_argument("calibrate_colour: " + std::to_string(projectors.size()) + " models for " +
                                    std::to_string(calibration.projectors.size()) + " projectors");
    }
    require_locked_exposure(source);
    const std::size_t n = projectors.size();
    ColourResult res;
    Captured cap;
    res.captures = capture_blacks(source, options, n, cap);
    if (options.lens_falloff) {
        if (camera.resolution.width != cap.black.cols || camera.resolution.height != cap.black.rows) {
            throw std::invalid_argument("calibrate_colour: the camera model is " +
                                        std::to_string(camera.resolution.width) + "x" +
                                        std::to_string(camera.resolution.height) + ", its images " +
                                        std::to_string(cap.black.cols) + "x" + std::to_string(cap.black.rows));
        }
        cap.screen = camera_screen_points(camera, screen);
        cap.to_camera = gain_toward_camera(cap.screen, screen, camera, projectors);
    }
    for (std::size_t k = 0; k < n; ++k) {
        res.projectors.push_back(measure_projector(source, projectors, k, options, cap, res.captures));
    }
    res.half_gain_angle_deg = screen.half_gain_angle_deg;
    if (options.lens_falloff) {
        if (options.screen_bounce) {
            res.captures += capture_bounce_whites(source, projectors, options, cap);
            remove_screen_bounce(cap, screen, res);
        }
        if (options.camera_vignetting && options.estimate_half_gain_angle && screen.gain != 1.0) {
            screen.half_gain_angle_deg =
                estimate_half_gain_angle(cap, told, camera, projectors, options, res.told_half_gain_rms,
                                         res.half_gain_rms, res.half_gain_angle_estimated);
            res.half_gain_angle_deg = screen.half_gain_angle_deg;
            cap.to_camera = gain_toward_camera(cap.screen, screen, camera, projectors);
        }
        if (options.camera_vignetting) res.vignetting = measure_vignetting(cap, screen, camera, projectors, options);
        for (std::size_t k = 0; k < n; ++k) {
            measure_falloff(cap, screen, projectors[k], k, options, res.projectors[k]);
            projectors[k].falloff = res.projectors[k].falloff;
        }
    }
    measure_black(source, options, cap, screen, projectors, res.projectors, res.ambient, res.captures);
    // Step 3: matched white, blacks per channel, black floor over the screen.
    std::vector<std::array<double, 3>> blacks(n);
    for (std::size_t c = 0; c < 3; ++c) {
        res.matched_white[c] = res.projectors[0].channels[c].amplitude;
        for (const ProjectorPhotometry& pp : res.projectors) {
            res.matched_white[c] = std::min(res.matched_white[c], pp.channels[c].amplitude);
        }
    }
    for (std::size_t k = 0; k < n; ++k) {
        ProjectorPhotometry& pp = res.projectors[k];
        // The mono camera sees the mean of the channels: black (mono) = sum_c black_c / 3 in the
        // units A_kc is in (one channel's light / 3), so black_c = beta A_c / sum_c A_c.
        const double sum = pp.channels[0].amplitude + pp.channels[1].amplitude + pp.channels[2].amplitude;
        for (std::size_t c = 0; c < 3; ++c) {
            blacks[k][c] = pp.black * pp.channels[c].amplitude / sum;
            pp.gain[c] = res.matched_white[c] / pp.channels[c].amplitude;
        }
    }
    MeasuredColour colour;
    for (std::size_t k = 0; k < n; ++k) {
        colour.responses.push_back(colour_detail::measured_lut(res.projectors[k], options));
        std::array<double, 3> b{};
        for (std::size_t c = 0; c < 3; ++c) b[c] = blacks[k][c] / res.matched_white[c];
        colour.black.push_back(b);
    }
    res.black_floor = colour_detail::black_floor(projectors, screen, blacks);
    res.alpha_scale = apply_measured_colour(colour, projectors, screen, calibration);
    res.white_floor = colour_detail::white_floor(projectors, screen, calibration);
    models = projectors;
    return res;
}

}  // namespace mogao::autocal
