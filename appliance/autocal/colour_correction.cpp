// SPDX-License-Identifier: Apache-2.0
// The colour step's correction of a calibration: measured responses into LUTs, blacks into betas, the matched white
// and the lens fall-off into the blend (colour_calibration.h, method there; colour_correction.h).
#include "appliance/autocal/colour_correction.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>

#include "appliance/autocal/colour_calibration.h"
#include "appliance/autocal/screen_geometry.h"
#include "appliance/warp/calibration_validation.h"
#include "appliance/warp/response_curve.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao::autocal {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Inverse of the normalised response at target t in [0, 1] by bisection (response_at is monotone).
double invert_measured(const ChannelResponse& r, double t) {
    double lo = 0.0;
    double hi = 1.0;
    for (int it = 0; it < 40; ++it) {
        const double mid = (lo + hi) / 2.0;
        (response_at(r, mid) < t ? lo : hi) = mid;
    }
    return (lo + hi) / 2.0;
}

// How much brighter than a matte screen device d's light at screen point (theta, h) looks from the screen's viewer
// (ScreenModel::gain; 1 on a matte screen).
double toward_viewer(const DeviceModel& d, const ScreenModel& screen, double theta, double h) {
    return screen_gain_at(screen, theta, h, d.position_m, screen.viewer_m);
}

// Black light per channel at screen point (theta, h) as the viewer sees it: sum of the blacks of the projectors
// there, each through its lens's fall-off and the screen's gain; projector `always` lights it with fall-off
// `always_falloff` (the caller knows its pixel; models.size() = none).
std::array<double, 3> black_at(const std::vector<DeviceModel>& models, const ScreenModel& screen,
                               const std::vector<std::array<double, 3>>& blacks, double theta, double h,
                               std::size_t always, double always_falloff) {
    std::array<double, 3> b{};
    for (std::size_t j = 0; j < models.size(); ++j) {
        double f = always_falloff;
        if (j != always) {
            const Eigen::Vector2d p = model_pixel(models[j], screen, theta, h);
            if (!p.allFinite()) continue;
            f = falloff_at(models[j], p.x(), p.y()) * toward_viewer(models[j], screen, theta, h);
        }
        for (std::size_t c = 0; c < 3; ++c) b[c] += f * blacks[j][c];
    }
    return b;
}

// The screen point (theta, h) and blend weight of output pixel (x, y); false where it shows nothing.
bool pixel_on_screen(const ProjectorCalibration& pc, const ScreenModel& screen, int x, int y, double& theta, double& h,
                     float& alpha) {
    const ContentUv uv = sample_warp(pc.warp, pc.output, x, y);
    alpha = sample_blend(pc.blend, pc.output, x, y);
    if (!uv.valid() || alpha <= 0.0F) return false;
    const double arc = screen.arc_deg * kDeg;
    theta = uv.u * arc - arc / 2.0;
    h = screen.top_m - uv.v * (screen.top_m - screen.bottom_m);
    return true;
}

// Projector d's image position of pc's output pixel (x, y) (pixel-index coordinates: x is the
// centre of pixel x); the output may be a scaled copy of the projector's resolution.
Eigen::Vector2d output_position(const DeviceModel& d, const ProjectorCalibration& pc, double x, double y) {
    return {(x + 0.5) * d.resolution.width / pc.output.width, (y + 0.5) * d.resolution.height / pc.output.height};
}

// The relative light of output pixel (x, y) of d as the viewer sees it: its lens's fall-off times the screen's
// gain toward the viewer at the screen point its warp shows there (none where it shows no content).
double falloff_at_output(const DeviceModel& d, const ScreenModel& screen, const ProjectorCalibration& pc, double x,
                         double y) {
    double f = 1.0;
    if (!d.falloff.flat()) {
        const Eigen::Vector2d p = output_position(d, pc, x, y);
        f = falloff_at(d, p.x(), p.y());
    }
    if (screen.gain == 1.0) return f;
    const ContentUv uv = sample_warp_at(pc.warp, pc.output, x, y);
    if (!uv.valid()) return f;
    const double arc = screen.arc_deg * kDeg;
    return f * toward_viewer(d, screen, uv.u * arc - arc / 2.0, screen.top_m - uv.v * (screen.top_m - screen.bottom_m));
}

// Calls fn(weight, F) for every blend texel of pc (weight writable when pc is), F the relative light at
// the texel's output position (falloff_at_output).
template <typename Calibration, typename Fn>
void for_each_blend_texel(const DeviceModel& d, const ScreenModel& screen, Calibration& pc, Fn&& fn) {
    const ImageSize g = pc.blend.size;
    for (int j = 0; j < g.height; ++j) {
        const double y = grid_to_output(j, pc.output.height, g.height);
        for (int i = 0; i < g.width; ++i) {
            fn(pc.blend.weight[static_cast<std::size_t>(j) * g.width + i],
               falloff_at_output(d, screen, pc, grid_to_output(i, pc.output.width, g.width), y));
        }
    }
}

// Step 4's blend for the fall-off: w_k(p) x s x S / F_k(p) (s the black headroom), so that the
// projectors' light sums to S W_c c wherever they show content c.
void scale_blend(const DeviceModel& d, const ScreenModel& screen, double scale, double white,
                 ProjectorCalibration& pc) {
    for_each_blend_texel(d, screen, pc, [&](float& w, double f) {
        w = static_cast<float>(std::clamp(w * scale * white / f, 0.0, 1.0));
    });
}

// Which other projectors' models light screen point (theta, h): bit j for projector j != k (the first 32; an edge
// of a later one is not told from its neighbours' and keeps the light at the pixel's centre).
std::uint32_t cover_mask(const std::vector<DeviceModel>& models, const ScreenModel& screen, std::size_t k, double theta,
                         double h) {
    std::uint32_t mask = 0;
    for (std::size_t j = 0; j < models.size() && j < 32; ++j) {
        if (j != k && model_pixel(models[j], screen, theta, h).allFinite()) mask |= 1U << j;
    }
    return mask;
}

constexpr std::uint32_t kNotShown = 0xFFFFFFFFU;

// cover_mask at every output pixel of projector k that shows content (kNotShown elsewhere).
std::vector<std::uint32_t> coverage_masks(std::size_t k, const std::vector<DeviceModel>& models,
                                          const ScreenModel& screen, const ProjectorCalibration& pc) {
    std::vector<std::uint32_t> masks(static_cast<std::size_t>(pc.output.pixel_count()), kNotShown);
    for (int y = 0; y < pc.output.height; ++y) {
        for (int x = 0; x < pc.output.width; ++x) {
            double theta = 0.0;
            double h = 0.0;
            float alpha = 0.0F;
            if (!pixel_on_screen(pc, screen, x, y, theta, h, alpha)) continue;
            masks[static_cast<std::size_t>(y) * static_cast<std::size_t>(pc.output.width) + x] =
                cover_mask(models, screen, k, theta, h);
        }
    }
    return masks;
}

// The relative light L_j of every projector j over output pixel (x, y) of projector k: F_j where its model lights
// the pixel, 0 elsewhere; L_k = f, k's fall-off there. On an edge pixel (another projector's image edge crosses
// it) L_j is the mean over kSub x kSub points of the pixel's footprint, placed on the screen through the warp: the
// pixel's light is uniform and the other projector's black covers only part of it, so the deficit at its centre
// alone gave the whole pixel that projector's black or none of it (a line one pixel wide of +-one projector's
// black). Over the pixel the mean is exact, up to the geometry's error at the edge. Into `light` (one entry per
// projector; the caller's buffer, reused from pixel to pixel).
void footprint_light(std::size_t k, const std::vector<DeviceModel>& models, const ScreenModel& screen,
                     const ProjectorCalibration& pc, int x, int y, double f, bool edge, std::vector<double>& light) {
    constexpr int kSub = 8;
    const int side = edge ? kSub : 1;
    const double arc = screen.arc_deg * kDeg;
    light.assign(models.size(), 0.0);
    int n = 0;
    for (int t = 0; t < side * side || n == 0; ++t) {
        // The pixel's centre alone where it is no edge pixel, or where no point of its footprint shows content.
        const bool centre = t >= side * side || !edge;
        const double dx = centre ? 0.0 : ((t % side) + 0.5) / side - 0.5;
        const double dy = centre ? 0.0 : ((t / side) + 0.5) / side - 0.5;
        const ContentUv uv = sample_warp_at(pc.warp, pc.output, x + dx, y + dy);
        if (!uv.valid() && !centre) continue;
        const double theta = uv.u * arc - arc / 2.0;
        const double h = screen.top_m - uv.v * (screen.top_m - screen.bottom_m);
        for (std::size_t j = 0; j < models.size(); ++j) {
            if (j == k) continue;
            const Eigen::Vector2d p = model_pixel(models[j], screen, theta, h);
            if (p.allFinite())
                light[j] += falloff_at(models[j], p.x(), p.y()) * toward_viewer(models[j], screen, theta, h);
        }
        ++n;
    }
    for (double& l : light) l /= n;
    light[k] = f;
}

// Whether a neighbour of (x, y) (8-connected, among the pixels that show content) sees other projectors than
// (x, y) does: then an image edge crosses the pixel (it lies within 0.71 px of the pixel's centre, and the
// neighbour across it lies 1 px or more from it).
bool crosses_edge(const std::vector<std::uint32_t>& masks, ImageSize out, int x, int y) {
    const std::uint32_t m = masks[static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) + x];
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx;
            const int ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= out.width || ny >= out.height) continue;
            const std::uint32_t n = masks[static_cast<std::size_t>(ny) * static_cast<std::size_t>(out.width) + nx];
            if (n != kNotShown && n != m) return true;
        }
    }
    return false;
}

// Step 4's beta for projector k (blacks and floor in matched-white units, blend not yet scaled);
// returns the largest deficit D / W it met.
double apply_beta(std::size_t k, const std::vector<DeviceModel>& models, const ScreenModel& screen,
                  const std::vector<std::array<double, 3>>& blacks, const std::array<double, 3>& floor,
                  ProjectorCalibration& pc) {
    // Beta per output pixel: black steps are as sharp as the other projectors' image edges, so a
    // coarser grid would smear the compensating step over several pixels.
    const ImageSize out = pc.output;
    pc.beta.size = out;
    pc.beta.rgb.assign(static_cast<std::size_t>(out.pixel_count()) * 3, 0.0F);
    const std::vector<std::uint32_t> masks = coverage_masks(k, models, screen, pc);
    double worst = 0.0;
    std::vector<double> light;
    for (int y = 0; y < out.height; ++y) {
        for (int x = 0; x < out.width; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) + x;
            if (masks[i] == kNotShown) continue;
            const double f = falloff_at_output(models[k], screen, pc, x, y);
            const float alpha = sample_blend(pc.blend, out, x, y);
            footprint_light(k, models, screen, pc, x, y, f, crosses_edge(masks, out, x, y), light);
            for (std::size_t c = 0; c < 3; ++c) {
                double black = 0.0;
                for (std::size_t j = 0; j < models.size(); ++j) black += light[j] * blacks[j][c];
                const double deficit = std::max(0.0, floor[c] - black);
                worst = std::max(worst, deficit);
                pc.beta.rgb[i * 3 + c] = static_cast<float>(std::clamp(alpha * deficit / f, 0.0, 1.0));
            }
        }
    }
    return worst;
}

// measured_colour's least squares: normal equations of beta_kc(p) = a(p) . (t_c, b_0c, ..)
// with a = alpha (1, -L_0, -L_1, ..) (footprint_light), sampled every other pixel.
struct BlackSystem {
    Eigen::MatrixXd ata;
    Eigen::MatrixXd atb;  // (n + 1) x 3
    double bb = 0.0;      // sum of beta^2
    long rows = 0;
};

void accumulate_blacks(const ProjectorCalibration& pc, std::size_t k, const std::vector<DeviceModel>& models,
                       const ScreenModel& screen, double scale, double white, BlackSystem& sys) {
    const auto n = static_cast<long>(models.size());
    const std::vector<std::uint32_t> masks = coverage_masks(k, models, screen, pc);
    Eigen::VectorXd a(n + 1);
    std::vector<double> light;
    for (int y = 0; y < pc.output.height; y += 2) {
        for (int x = 0; x < pc.output.width; x += 2) {
            if (masks[static_cast<std::size_t>(y) * static_cast<std::size_t>(pc.output.width) + x] == kNotShown) {
                continue;
            }
            // beta_k = alpha_k (t - sum_j b_j L_j) / F_k with w = alpha_k s S / F_k (L_j as apply_beta's).
            const double alpha = sample_blend(pc.blend, pc.output, x, y) / (scale * white);
            footprint_light(k, models, screen, pc, x, y, falloff_at_output(models[k], screen, pc, x, y),
                            crosses_edge(masks, pc.output, x, y), light);
            a[0] = alpha;
            for (long j = 0; j < n; ++j) a[j + 1] = -alpha * light[static_cast<std::size_t>(j)];
            const std::array<float, 3> beta =
                pc.beta.rgb.empty() ? std::array<float, 3>{} : sample_beta(pc.beta, pc.output, x, y);
            sys.ata += a * a.transpose();
            for (long c = 0; c < 3; ++c) {
                sys.atb.col(c) += a * static_cast<double>(beta[static_cast<std::size_t>(c)]);
                sys.bb += static_cast<double>(beta[static_cast<std::size_t>(c)]) * beta[static_cast<std::size_t>(c)];
            }
            ++sys.rows;
        }
    }
}

void check_colour_layout(const std::vector<DeviceModel>& models, const ScreenCalibration& calibration,
                         std::size_t responses, const char* who) {
    if (models.empty() || models.size() != calibration.projectors.size() || responses != models.size()) {
        throw std::invalid_argument(std::string(who) + ": " + std::to_string(models.size()) + " models, " +
                                    std::to_string(calibration.projectors.size()) + " projectors and " +
                                    std::to_string(responses) + " colours (must be the same, > 0)");
    }
}

}  // namespace

namespace colour_detail {

// Step 3's black floor: the brightest black over a 801 x 101 grid of screen points (blacks' units).
std::array<double, 3> black_floor(const std::vector<DeviceModel>& models, const ScreenModel& screen,
                                  const std::vector<std::array<double, 3>>& blacks) {
    const double arc = screen.arc_deg * kDeg;
    std::array<double, 3> floor{};
    for (int j = 0; j <= 100; ++j) {
        for (int i = 0; i <= 800; ++i) {
            const double theta = (i / 800.0 - 0.5) * arc;
            const double h = screen.bottom_m + (screen.top_m - screen.bottom_m) * j / 100.0;
            const std::array<double, 3> b = black_at(models, screen, blacks, theta, h, models.size(), 1.0);
            for (std::size_t c = 0; c < 3; ++c) floor[c] = std::max(floor[c], b[c]);
        }
    }
    return floor;
}

// Step 4's LUT for one projector.
ResponseCurve measured_lut(const ProjectorPhotometry& pp, const ColourOptions& o) {
    ResponseCurve out;
    for (std::size_t c = 0; c < 3; ++c) {
        std::vector<float>& lut = out.lut[c];
        lut.assign(static_cast<std::size_t>(o.lut_entries), 0.0F);
        for (int j = 0; j < o.lut_entries; ++j) {
            const double x = static_cast<double>(j) / (o.lut_entries - 1);
            lut[static_cast<std::size_t>(j)] = static_cast<float>(invert_measured(pp.channels[c], x * pp.gain[c]));
        }
        for (std::size_t j = 1; j < lut.size(); ++j) lut[j] = std::max(lut[j], lut[j - 1]);
    }
    return out;
}

// Step 4's white floor S: the least relative light F any projector gives where it shows content
// (blend > 0); 1 when every projector is flat. The wall's white is S W_c everywhere.
double white_floor(const std::vector<DeviceModel>& models, const ScreenModel& screen,
                   const ScreenCalibration& calibration) {
    double floor = 1.0;
    for (std::size_t k = 0; k < models.size(); ++k) {
        if (models[k].falloff.flat() && screen.gain == 1.0) continue;
        for_each_blend_texel(models[k], screen, calibration.projectors[k], [&](float w, double f) {
            if (w > 0.0F) floor = std::min(floor, f);
        });
    }
    return floor;
}

}  // namespace colour_detail

double apply_measured_colour(const MeasuredColour& colour, const std::vector<DeviceModel>& models,
                             const ScreenModel& screen, ScreenCalibration& calibration) {
    check_colour_layout(models, calibration, colour.responses.size(), "apply_measured_colour");
    if (colour.black.size() != models.size())
        throw std::invalid_argument("apply_measured_colour: blacks per projector");
    bool any_black = false;
    for (std::size_t k = 0; k < models.size(); ++k) {
        validate_response(colour.responses[k], "apply_measured_colour: response of " + models[k].id);
        for (const double b : colour.black[k]) {
            if (!(b >= 0.0 && b < 1.0)) throw std::invalid_argument("apply_measured_colour: black outside [0, 1)");
            any_black = any_black || b > 0.0;
        }
        calibration.projectors[k].response = colour.responses[k];
        calibration.projectors[k].beta = {};
    }
    double worst = 0.0;
    if (any_black) {
        const std::array<double, 3> floor = colour_detail::black_floor(models, screen, colour.black);
        for (std::size_t k = 0; k < models.size(); ++k) {
            worst = std::max(worst, apply_beta(k, models, screen, colour.black, floor, calibration.projectors[k]));
        }
    }
    // alpha s S / F + beta <= 1 with beta <= D / F and F >= S where alpha > 0: s = 1 - max D / S.
    const double white = colour_detail::white_floor(models, screen, calibration);
    const double scale = 1.0 - worst / white;
    for (std::size_t k = 0; k < models.size(); ++k)
        scale_blend(models[k], screen, scale, white, calibration.projectors[k]);
    validate_screen(calibration);
    return scale;
}

MeasuredColour measured_colour(const ScreenCalibration& calibration, const std::vector<DeviceModel>& models,
                               const ScreenModel& screen) {
    check_colour_layout(models, calibration, models.size(), "measured_colour");
    const std::size_t n = models.size();
    MeasuredColour out;
    out.black.assign(n, std::array<double, 3>{});
    float beta_max = 0.0F;
    for (const ProjectorCalibration& pc : calibration.projectors) {
        out.responses.push_back(pc.response);
        for (const float b : pc.beta.rgb) beta_max = std::max(beta_max, b);
    }
    // w = alpha s S / F: s is the largest w F / S (alpha = 1 where one projector alone shows content).
    const double white = colour_detail::white_floor(models, screen, calibration);
    double scale = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
        for_each_blend_texel(models[k], screen, calibration.projectors[k],
                             [&](float w, double f) { scale = std::max(scale, w * f / white); });
    }
    if (!(beta_max > 0.0F) || !(scale > 0.0)) return out;  // no black-level compensation
    BlackSystem sys{Eigen::MatrixXd::Zero(static_cast<long>(n) + 1, static_cast<long>(n) + 1),
                    Eigen::MatrixXd::Zero(static_cast<long>(n) + 1, 3)};
    for (std::size_t k = 0; k < n; ++k) {
        accumulate_blacks(calibration.projectors[k], k, models, screen, scale, white, sys);
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(sys.ata);
    const Eigen::VectorXd ev = eig.eigenvalues();
    if (sys.rows == 0 || !(ev.minCoeff() > 1e-10 * ev.maxCoeff())) {
        throw std::invalid_argument(
            "measured_colour: the beta maps' blacks are not separable (no overlap of the "
            "models' projectors): the black-level compensation cannot be re-derived");
    }
    const Eigen::MatrixXd sol = sys.ata.ldlt().solve(sys.atb);
    const double rss =
        std::max(0.0, sys.bb - 2.0 * (sol.transpose() * sys.atb).trace() + (sol.transpose() * sys.ata * sol).trace());
    const double rms = std::sqrt(rss / (3.0 * static_cast<double>(sys.rows)));
    const double beta_rms = std::sqrt(sys.bb / (3.0 * static_cast<double>(sys.rows)));
    if (rms > 0.1 * beta_rms) {
        throw std::invalid_argument(
            "measured_colour: the beta maps are not the black-level compensation of the "
            "models' overlaps (rms residual " +
            std::to_string(rms) + " > 10 % of their rms " + std::to_string(beta_rms) + "): they cannot be re-derived");
    }
    for (std::size_t k = 0; k < n; ++k) {
        for (std::size_t c = 0; c < 3; ++c) {
            out.black[k][c] = std::max(0.0, sol(static_cast<long>(k) + 1, static_cast<long>(c)));
        }
    }
    return out;
}

}  // namespace mogao::autocal
