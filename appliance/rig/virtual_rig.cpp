// SPDX-License-Identifier: Apache-2.0
// The virtual rig: geometry (ground truth) and camera image formation. Formulas in virtual_rig.h.
#include "appliance/rig/virtual_rig.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "appliance/rig/screen_light.h"
#include "common/jpeg_codec.h"

namespace mogao::rig {
namespace {

using detail::check_range;

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kPatchSamples = 4;  // per side: where each screen patch's light leaving it is sampled
constexpr int kPatchBlock = 8;    // projector pixels per side averaged into each such sample

// The far (forward) intersection of o + t d with the cylinder x^2 + z^2 = r^2, o inside.
std::optional<Eigen::Vector3d> hit_cylinder(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r) {
    const double a = d.x() * d.x() + d.z() * d.z();
    if (a < 1e-18) return std::nullopt;
    const double b = 2.0 * (o.x() * d.x() + o.z() * d.z());
    const double c = o.x() * o.x() + o.z() * o.z() - r * r;
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) return std::nullopt;
    const double t = (-b + std::sqrt(disc)) / (2.0 * a);
    if (t <= 0.0) return std::nullopt;
    return o + t * d;
}

// The screen's distance from the axis at (theta, h): the cylinder's radius plus the bulge's
// half-sine bow, zero on the frame (the arc's ends, the bottom and top edges) and bulge_m in the
// middle; the nominal radius outside the screen.
double radius_at(const RigScreen& screen, double theta, double h) {
    const double arc = screen.arc_deg * kDeg;
    if (screen.bulge_m == 0.0 || std::abs(theta) > arc / 2.0 || h < screen.bottom_m || h > screen.top_m) {
        return screen.radius_m;
    }
    return screen.radius_m + screen.bulge_m * std::cos(std::numbers::pi * theta / arc) *
                                 std::sin(std::numbers::pi * (h - screen.bottom_m) / (screen.top_m - screen.bottom_m));
}

// The far intersection of o + t d (o inside) with the screen surface r = radius_at(theta, h): the
// cylinder's intersection, then fixed-point steps through the cylinder of the radius at the last
// hit. Each step shrinks the error by about the bow's slope times the tangent of the ray's incidence;
// validate_rig bounds the slope (0.2), so a few dozen steps reach 1e-12 m but at grazing incidence.
std::optional<Eigen::Vector3d> hit_screen(const RigScreen& screen, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
    auto hit = hit_cylinder(o, d, screen.radius_m);
    if (!hit || screen.bulge_m == 0.0) return hit;
    for (int i = 0; i < 200; ++i) {
        const double r = radius_at(screen, std::atan2(hit->x(), -hit->z()), hit->y());
        const auto next = hit_cylinder(o, d, r);
        if (!next) return std::nullopt;
        const bool converged = (*next - *hit).norm() < 1e-12;
        hit = next;
        if (converged) return hit;
    }
    return std::nullopt;  // not converged: no ground truth rather than a wrong one
}

std::optional<ScreenPoint> on_screen(const RigScreen& screen, const Eigen::Vector3d& p) {
    const ScreenPoint s{std::atan2(p.x(), -p.z()), p.y()};
    const double half = screen.arc_deg * kDeg / 2.0;
    if (std::abs(s.theta_rad) > half || s.h_m < screen.bottom_m || s.h_m > screen.top_m) return std::nullopt;
    return s;
}

// The distortion's centre of projector p in normalised coordinates (RigProjector::distortion_centre_px).
Eigen::Vector2d distortion_centre(const RigProjector& p) {
    return {p.distortion_centre_px.x() / p.intrinsics.fx_px, p.distortion_centre_px.y() / p.intrinsics.fy_px};
}

// Light per projector pixel value before the fall-off, per channel: brightness * (black + (1 - black) * s^gamma),
// mean of channels.
double projector_light(const RigProjector& p, const float* v, int channels) {
    double sum = 0.0;
    for (int c = 0; c < 3; ++c) {
        const double s = std::clamp(static_cast<double>(v[channels == 3 ? c : 0]), 0.0, 1.0);
        const double lin = s <= 0.0 ? 0.0 : (s >= 1.0 ? 1.0 : std::pow(s, p.gamma[static_cast<std::size_t>(c)]));
        sum += p.brightness[static_cast<std::size_t>(c)] * (p.black_level + (1.0 - p.black_level) * lin);
    }
    return sum / 3.0;
}

// The light of projector p's image for `signal` (empty: the projector dark, its black level), defocused
// (RigProjector::blur_px): Gaussian, +-4 sigma, on the image padded by defocus_margin(p) pixels of no light on
// every side, so that the light its border pixels spread past the image's edge lands there.
cv::Mat1f defocused_light(const RigProjector& p, const cv::Mat& signal) {
    const int m = defocus_margin(p);
    cv::Mat1f out(p.resolution.height + 2 * m, p.resolution.width + 2 * m, 0.0F);
    const float zero = 0.0F;
    for (int y = 0; y < p.resolution.height; ++y) {
        for (int x = 0; x < p.resolution.width; ++x) {
            out(y + m, x + m) = static_cast<float>(
                signal.empty() ? projector_light(p, &zero, 1)
                               : projector_light(p, signal.ptr<float>(y) + x * signal.channels(), signal.channels()));
        }
    }
    cv::GaussianBlur(out, out, cv::Size(2 * m + 1, 2 * m + 1), p.blur_px, p.blur_px, cv::BORDER_CONSTANT);
    return out;
}

}  // namespace

Eigen::Vector3d screen_position(const RigScreen& screen, ScreenPoint p) {
    const double r = radius_at(screen, p.theta_rad, p.h_m);
    return {r * std::sin(p.theta_rad), p.h_m, -r * std::cos(p.theta_rad)};
}

double projector_falloff(const RigProjector& p, double x, double y) {
    const double half_diagonal = 0.5 * std::hypot(p.resolution.width, p.resolution.height);
    const double rho2 =
        (std::pow(x - p.intrinsics.cx_px, 2) + std::pow(y - p.intrinsics.cy_px, 2)) / (half_diagonal * half_diagonal);
    return 1.0 - p.falloff * std::min(rho2, 2.0);
}

double camera_vignetting(const RigCamera& c, double x, double y) {
    if (c.vignetting == 0.0) return 1.0;
    const double half_diagonal = 0.5 * std::hypot(c.resolution.width, c.resolution.height);
    const double rho2 =
        (std::pow(x - c.intrinsics.cx_px, 2) + std::pow(y - c.intrinsics.cy_px, 2)) / (half_diagonal * half_diagonal);
    return 1.0 - c.vignetting * std::min(rho2, 2.0);
}

std::optional<ScreenPoint> projector_to_screen(const VirtualRig& rig, int k, double x, double y) {
    const RigProjector& p = rig.projectors.at(static_cast<std::size_t>(k));
    const RigIntrinsics& in = p.intrinsics;
    Eigen::Vector3d d_dev((x - in.cx_px) / in.fx_px, (y - in.cy_px) / in.fy_px, 1.0);
    if (in.distortion != std::array<double, 5>{}) {
        const Eigen::Vector2d c = distortion_centre(p);
        const Eigen::Vector2d u = c + undistort(in.distortion, d_dev.x() - c.x(), d_dev.y() - c.y());
        const Eigen::Vector2d back = c + distort(in.distortion, u.x() - c.x(), u.y() - c.y());
        if (!((back - d_dev.head<2>()).norm() < 1e-10)) return std::nullopt;  // not converged: no ground truth
        d_dev.head<2>() = u;
    }
    const auto hit = hit_screen(rig.screen, p.pose.position_m, device_to_screen(p.pose) * d_dev);
    if (!hit) return std::nullopt;
    return on_screen(rig.screen, *hit);
}

int defocus_margin(const RigProjector& p) { return p.blur_px > 0.0 ? static_cast<int>(std::ceil(4.0 * p.blur_px)) : 0; }

std::optional<Eigen::Vector2d> screen_to_projector(const VirtualRig& rig, int k, ScreenPoint s, double margin_px) {
    const RigProjector& p = rig.projectors.at(static_cast<std::size_t>(k));
    const Eigen::Vector3d d =
        device_to_screen(p.pose).transpose() * (screen_position(rig.screen, s) - p.pose.position_m);
    if (d.z() <= 1e-9) return std::nullopt;
    const RigIntrinsics& in = p.intrinsics;
    Eigen::Vector2d n(d.x() / d.z(), d.y() / d.z());
    if (in.distortion != std::array<double, 5>{}) {
        // Far outside the image the polynomial folds back: only rays within the validated radius count.
        const Eigen::Vector2d c = distortion_centre(p);
        if ((n - c).norm() > 1.2 * corner_radius(p)) return std::nullopt;
        n = c + distort(in.distortion, n.x() - c.x(), n.y() - c.y());
    }
    const Eigen::Vector2d xy(in.fx_px * n.x() + in.cx_px, in.fy_px * n.y() + in.cy_px);
    const double m = margin_px;
    if (!(xy.x() >= -m && xy.x() < p.resolution.width + m && xy.y() >= -m && xy.y() < p.resolution.height + m)) {
        return std::nullopt;
    }
    return xy;
}

Eigen::Vector2d content_of(const RigScreen& screen, ScreenPoint p) {
    const double arc = screen.arc_deg * kDeg;
    return {(p.theta_rad + arc / 2.0) / arc, (screen.top_m - p.h_m) / (screen.top_m - screen.bottom_m)};
}

ScreenPoint screen_of(const RigScreen& screen, Eigen::Vector2d uv) {
    const double arc = screen.arc_deg * kDeg;
    return {uv.x() * arc - arc / 2.0, screen.top_m - uv.y() * (screen.top_m - screen.bottom_m)};
}

CameraSimulator::CameraSimulator(const VirtualRig& rig) : rig_(rig) {
    validate_rig(rig_);
    const RigCamera& cam = rig_.camera;
    const int ss = cam.supersample;
    samples_w_ = cam.resolution.width * ss;
    samples_h_ = cam.resolution.height * ss;
    const std::size_t n = static_cast<std::size_t>(samples_w_) * static_cast<std::size_t>(samples_h_);
    // Normalised distorted coordinates of every sample, undistorted by OpenCV's iterative inverse.
    std::vector<cv::Point2d> distorted(n);
    for (int y = 0; y < samples_h_; ++y) {
        for (int x = 0; x < samples_w_; ++x) {
            const double px = (x + 0.5) / ss;
            const double py = (y + 0.5) / ss;
            distorted[static_cast<std::size_t>(y) * samples_w_ + x] = {
                (px - cam.intrinsics.cx_px) / cam.intrinsics.fx_px, (py - cam.intrinsics.cy_px) / cam.intrinsics.fy_px};
        }
    }
    std::vector<cv::Point2d> ideal(n);
    cv::undistortPoints(distorted, ideal, cv::Matx33d::eye(), cam.intrinsics.distortion, cv::noArray(), cv::noArray(),
                        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-14));
    on_screen_.assign(n, 0);
    hit_.assign(rig_.projectors.size(), std::vector<std::int32_t>(n, -1));
    const Eigen::Matrix3d r = device_to_screen(cam.pose);
    cv::parallel_for_(cv::Range(0, samples_h_), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            for (int x = 0; x < samples_w_; ++x) {
                const std::size_t i = static_cast<std::size_t>(y) * samples_w_ + x;
                const Eigen::Vector3d d = r * Eigen::Vector3d(ideal[i].x, ideal[i].y, 1.0);
                const auto hit = hit_screen(rig_.screen, cam.pose.position_m, d);
                const auto s = hit ? on_screen(rig_.screen, *hit) : std::nullopt;
                if (!s) continue;
                on_screen_[i] = 1;
                for (std::size_t k = 0; k < rig_.projectors.size(); ++k) {
                    const int m = defocus_margin(rig_.projectors[k]);
                    const auto xy = screen_to_projector(rig_, static_cast<int>(k), *s, m);
                    if (!xy) continue;
                    const int w = rig_.projectors[k].resolution.width + 2 * m;
                    hit_[k][i] = (static_cast<std::int32_t>(std::floor(xy->y())) + m) * w +
                                 static_cast<std::int32_t>(std::floor(xy->x())) + m;
                }
            }
        }
    });
    dark_light_.assign(rig_.projectors.size(), cv::Mat1f());
    for (std::size_t k = 0; k < rig_.projectors.size(); ++k) {
        if (rig_.projectors[k].blur_px > 0.0) dark_light_[k] = defocused_light(rig_.projectors[k], cv::Mat());
    }
    if (rig_.screen.gain != 1.0 || rig_.screen.interreflection > 0.0) trace_screen_light();
}

void CameraSimulator::trace_screen_light() {
    const RigCamera& cam = rig_.camera;
    const ImageSize res = cam.resolution;
    std::vector<cv::Point2d> distorted;
    distorted.reserve(static_cast<std::size_t>(res.width) * res.height);
    for (int y = 0; y < res.height; ++y) {
        for (int x = 0; x < res.width; ++x) {
            distorted.emplace_back((x + 0.5 - cam.intrinsics.cx_px) / cam.intrinsics.fx_px,
                                   (y + 0.5 - cam.intrinsics.cy_px) / cam.intrinsics.fy_px);
        }
    }
    std::vector<cv::Point2d> ideal(distorted.size());
    cv::undistortPoints(distorted, ideal, cv::Matx33d::eye(), cam.intrinsics.distortion, cv::noArray(), cv::noArray(),
                        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-14));
    // Each pixel centre's ray on the cylinder, held to the screen: gain and bounce are smooth, so a pixel
    // at the screen's edge takes its nearest screen point's.
    const Eigen::Matrix3d r = device_to_screen(cam.pose);
    const double half = rig_.screen.arc_deg * kDeg / 2.0;
    pixel_point_.assign(ideal.size(), ScreenPoint{});
    for (std::size_t i = 0; i < ideal.size(); ++i) {
        const auto hit =
            hit_cylinder(cam.pose.position_m, r * Eigen::Vector3d(ideal[i].x, ideal[i].y, 1.0), rig_.screen.radius_m);
        if (!hit) continue;
        pixel_point_[i] = {std::clamp(std::atan2(hit->x(), -hit->z()), -half, half),
                           std::clamp(hit->y(), rig_.screen.bottom_m, rig_.screen.top_m)};
    }
    const std::size_t np = rig_.projectors.size();
    if (rig_.screen.gain != 1.0) {
        gain_.assign(np, std::vector<float>(ideal.size(), 1.0F));
        for (std::size_t k = 0; k < np; ++k) {
            for (std::size_t i = 0; i < ideal.size(); ++i) {
                gain_[k][i] = static_cast<float>(
                    screen_gain(rig_.screen, pixel_point_[i], rig_.projectors[k].pose.position_m, cam.pose.position_m));
            }
        }
    }
    if (rig_.screen.interreflection > 0.0) {
        auto bounce = std::make_shared<ScreenBounce>(rig_.screen);
        patch_pixel_.assign(np, {});
        for (std::size_t k = 0; k < np; ++k) {
            for (int i = 0; i < bounce->patches(); ++i) {
                const ScreenPoint c = bounce->centre(i);
                for (int j = 0; j < kPatchSamples * kPatchSamples; ++j) {
                    const ScreenPoint q{
                        c.theta_rad + ((j % kPatchSamples + 0.5) / kPatchSamples - 0.5) * bounce->patch_theta_rad(),
                        c.h_m + ((j / kPatchSamples + 0.5) / kPatchSamples - 0.5) * bounce->patch_height_m()};
                    const auto xy = screen_to_projector(rig_, static_cast<int>(k), q);
                    patch_pixel_[k].push_back(xy ? Eigen::Vector2f(xy->cast<float>()) : Eigen::Vector2f(-1.0F, -1.0F));
                }
            }
        }
        bounce_ = std::move(bounce);
    }
}

std::vector<double> CameraSimulator::patch_light(const std::vector<cv::Mat>& signals,
                                                 const std::vector<cv::Mat1f>& blurred) const {
    const int n = bounce_->patches();
    std::vector<double> leaving(static_cast<std::size_t>(n), 0.0);
    for (std::size_t k = 0; k < rig_.projectors.size(); ++k) {
        const RigProjector& p = rig_.projectors[k];
        // The projector's light image, averaged over blocks of kPatchBlock pixels: the patches' samples then
        // see each block's mean, not one pixel of a fine stripe.
        cv::Mat1f light = blurred[k];
        if (!light.empty()) {  // the image itself, without its defocus margin
            const int m = defocus_margin(p);
            light = light(cv::Rect(m, m, p.resolution.width, p.resolution.height));
        } else {
            light.create(p.resolution.height, p.resolution.width);
            const float zero = 0.0F;
            const cv::Mat& s = signals[k];
            cv::parallel_for_(cv::Range(0, light.rows), [&](const cv::Range& rows) {
                for (int y = rows.start; y < rows.end; ++y) {
                    for (int x = 0; x < light.cols; ++x) {
                        light(y, x) = static_cast<float>(
                            s.empty() ? projector_light(p, &zero, 1)
                                      : projector_light(p, s.ptr<float>(y) + x * s.channels(), s.channels()));
                    }
                }
            });
        }
        cv::Mat1f coarse;
        cv::resize(light, coarse,
                   cv::Size((light.cols + kPatchBlock - 1) / kPatchBlock, (light.rows + kPatchBlock - 1) / kPatchBlock),
                   0, 0, cv::INTER_AREA);
        const std::vector<Eigen::Vector2f>& px = patch_pixel_[k];
        for (int i = 0; i < n; ++i) {
            double sum = 0.0;
            for (int j = 0; j < kPatchSamples * kPatchSamples; ++j) {
                const Eigen::Vector2f xy = px[static_cast<std::size_t>(i * kPatchSamples * kPatchSamples + j)];
                if (xy.x() < 0.0F) continue;
                const int cx = std::min(static_cast<int>(xy.x()) * coarse.cols / light.cols, coarse.cols - 1);
                const int cy = std::min(static_cast<int>(xy.y()) * coarse.rows / light.rows, coarse.rows - 1);
                sum += projector_falloff(p, xy.x(), xy.y()) * coarse(cy, cx);
            }
            leaving[static_cast<std::size_t>(i)] += sum / (kPatchSamples * kPatchSamples);
        }
    }
    return leaving;
}

namespace {

// capture()'s input check: one continuous CV_32FC1 or CV_32FC3 image (or an empty one: that projector dark) at
// each projector's resolution.
void check_signals(const VirtualRig& rig, const std::vector<cv::Mat>& signals) {
    const std::size_t np = rig.projectors.size();
    for (std::size_t k = 0; k < np; ++k) {
        const ImageSize r = rig.projectors[k].resolution;
        const cv::Mat& s = signals[k];
        if (s.empty()) continue;
        if ((s.type() != CV_32FC1 && s.type() != CV_32FC3) || s.cols != r.width || s.rows != r.height ||
            !s.isContinuous()) {
            throw std::invalid_argument("capture: signals[" + std::to_string(k) +
                                        "] must be a continuous CV_32FC1 or CV_32FC3 of " + std::to_string(r.width) +
                                        "x" + std::to_string(r.height));
        }
    }
}

// The camera's sensor on the light image (camera pixels, light units): lens blur, exposure and gain, auto-exposure,
// read and shot noise (seeded by the camera's seed and the frame number) and quantisation to cam.bits.
void expose(const RigCamera& cam, cv::Mat1f& img, std::uint64_t frame) {
    if (cam.blur_sigma_px > 0.0)
        cv::GaussianBlur(img, img, cv::Size(0, 0), cam.blur_sigma_px, cam.blur_sigma_px, cv::BORDER_REPLICATE);
    img *= cam.exposure * cam.gain;
    if (cam.auto_exposure) {
        const double mean = cv::mean(img)[0];
        if (mean > 0.0) img *= kAutoExposureTarget / mean;
    }
    cv::Mat1f noise(img.size());
    cv::RNG rng(cam.seed * 0x9E3779B97F4A7C15ULL + frame * 0xD1B54A32D192ED03ULL + 1);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
    const double levels = std::ldexp(1.0, cam.bits) - 1.0;
    for (int y = 0; y < img.rows; ++y) {
        for (int x = 0; x < img.cols; ++x) {
            const double v = img(y, x);
            const double sigma =
                std::sqrt(cam.read_noise * cam.read_noise + cam.shot_noise * cam.shot_noise * std::max(v, 0.0));
            const double q = std::round(std::clamp(v + sigma * noise(y, x), 0.0, 1.0) * levels) / levels;
            img(y, x) = static_cast<float>(q);
        }
    }
}

// A Motion-JPEG camera's frame (RigCamera::mjpeg_quality): the quantised 8-bit image, grey on R, G and B,
// compressed by libjpeg-turbo at `quality` (4:2:0, as a webcam's MJPEG) and decoded back; grey in, grey out
// (the colour conversion of R = G = B is exact in libjpeg-turbo's fixed point, so the decoded channels agree).
void mjpeg_round_trip(cv::Mat1f& img, int quality) {
    Rgb8Image rgb(ImageSize{img.cols, img.rows});
    for (int y = 0; y < img.rows; ++y) {
        for (int x = 0; x < img.cols; ++x) {
            const auto v = static_cast<std::uint8_t>(std::lround(std::clamp(img(y, x), 0.0f, 1.0f) * 255.0f));
            std::uint8_t* p = rgb.at(x, y);
            p[0] = p[1] = p[2] = v;
        }
    }
    JpegEncoder encoder;
    const std::vector<std::uint8_t> jpeg = encoder.encode(rgb, quality, Subsampling::yuv420);
    JpegDecoder decoder;
    const Rgb8Image back = decoder.decode(jpeg);
    for (int y = 0; y < img.rows; ++y) {
        for (int x = 0; x < img.cols; ++x) img(y, x) = static_cast<float>(back.at(x, y)[1] / 255.0);
    }
}

}  // namespace

cv::Mat1f CameraSimulator::capture(const std::vector<cv::Mat>& signals, std::uint64_t frame) const {
    const std::size_t np = rig_.projectors.size();
    if (signals.size() != np) {
        throw std::invalid_argument("capture: " + std::to_string(signals.size()) + " signal images for " +
                                    std::to_string(np) + " projectors");
    }
    check_signals(rig_, signals);
    const auto light = [&](std::size_t k, const float* v, int channels) {
        return projector_light(rig_.projectors[k], v, channels);
    };
    // Defocus (RigProjector::blur_px): each projector's light image, blurred and padded by its margin (hit_ indexes
    // the padded image); looked up in place of `light`. A dark projector's is the same every time.
    std::vector<cv::Mat1f> blurred(np);
    for (std::size_t k = 0; k < np; ++k) {
        if (rig_.projectors[k].blur_px <= 0.0) continue;
        blurred[k] = signals[k].empty() ? dark_light_[k] : defocused_light(rig_.projectors[k], signals[k]);
    }
    // Interreflection: the light the screen throws onto itself, one bounce (header comment).
    std::optional<std::vector<double>> bounced;
    if (bounce_) bounced = bounce_->bounce(patch_light(signals, blurred));
    const int ss = rig_.camera.supersample;
    const ImageSize res = rig_.camera.resolution;
    cv::Mat1f img(res.height, res.width, 0.0f);
    cv::parallel_for_(cv::Range(0, res.height), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            for (int x = 0; x < res.width; ++x) {
                double acc = 0.0;
                const double on_screen_light =
                    rig_.ambient +
                    (bounced ? bounce_->at(*bounced, pixel_point_[static_cast<std::size_t>(y) * res.width + x]) : 0.0);
                for (int sy = 0; sy < ss; ++sy) {
                    for (int sx = 0; sx < ss; ++sx) {
                        const std::size_t i = static_cast<std::size_t>(y * ss + sy) * samples_w_ + (x * ss + sx);
                        double l = on_screen_[i] ? on_screen_light : 0.3 * rig_.ambient;
                        for (std::size_t k = 0; k < np; ++k) {
                            const std::int32_t h = hit_[k][i];
                            if (h < 0) continue;
                            const float zero = 0.0f;
                            const cv::Mat& s = signals[k];
                            const RigProjector& p = rig_.projectors[k];
                            const int wp = blurred[k].empty() ? p.resolution.width : blurred[k].cols;
                            const int m = blurred[k].empty() ? 0 : defocus_margin(p);
                            const double f =
                                p.falloff == 0.0 ? 1.0 : projector_falloff(p, h % wp - m + 0.5, h / wp - m + 0.5);
                            const double g =
                                gain_.empty() ? 1.0 : gain_[k][static_cast<std::size_t>(y) * res.width + x];
                            if (!blurred[k].empty()) {
                                l += g * f * blurred[k](h / wp, h % wp);
                                continue;
                            }
                            l += g * f *
                                 (s.empty() ? light(k, &zero, 1)
                                            : light(k, s.ptr<float>() + static_cast<std::size_t>(h) * s.channels(),
                                                    s.channels()));
                        }
                        acc += l;
                    }
                }
                const double v = camera_vignetting(rig_.camera, x + 0.5, y + 0.5);
                img(y, x) = static_cast<float>(v == 1.0 ? acc / (ss * ss) : v * acc / (ss * ss));
            }
        }
    });
    expose(rig_.camera, img, frame);
    if (rig_.camera.mjpeg_quality > 0) mjpeg_round_trip(img, rig_.camera.mjpeg_quality);
    return img;
}

void CameraSimulator::set_exposure(double exposure) {
    check_range(exposure, 1e-3, 100.0, "camera.exposure");
    rig_.camera.exposure = exposure;
}

double CameraSimulator::camera_coverage(int k) const {
    const std::vector<std::int32_t>& hits = hit_.at(static_cast<std::size_t>(k));
    const ImageSize r = rig_.projectors[static_cast<std::size_t>(k)].resolution;
    const int m = defocus_margin(rig_.projectors[static_cast<std::size_t>(k)]);
    // Projector pixels in 8x8 blocks that some camera sample sees, over all blocks.
    const int bw = (r.width + 7) / 8;
    const int bh = (r.height + 7) / 8;
    std::vector<std::uint8_t> seen(static_cast<std::size_t>(bw) * bh, 0);
    for (std::int32_t h : hits) {
        if (h < 0) continue;
        const int x = h % (r.width + 2 * m) - m;
        const int y = h / (r.width + 2 * m) - m;
        if (x < 0 || y < 0 || x >= r.width || y >= r.height) continue;  // light spread past the image's edge
        seen[static_cast<std::size_t>(y / 8) * bw + x / 8] = 1;
    }
    return static_cast<double>(std::count(seen.begin(), seen.end(), 1)) / static_cast<double>(seen.size());
}

}  // namespace mogao::rig
