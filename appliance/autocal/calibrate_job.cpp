// SPDX-License-Identifier: Apache-2.0
// The calibrate command's job: rig -> patterns -> calibration -> MPCDI, report, preview (calibrate_job.h).
#include "appliance/autocal/calibrate_job.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "appliance/autocal/colour_report.h"
#include "appliance/autocal/colour_truth.h"
#include "appliance/autocal/model_store.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/calibration/mpcdi_writer.h"
#include "appliance/rig/rig_file.h"
#include "appliance/rig/screen_light.h"
#include "appliance/warp/composite.h"
#include "appliance/warp/response_curve.h"
#include "appliance/warp/warp_sampling.h"
#include "common/png_io.h"

namespace mogao::autocal {
namespace {

// An extent in content units ([0, 1] over the frame) across u and across v.
struct ContentExtent {
    double u = 0.0;
    double v = 0.0;
};

// The share of a pixel of extent `pixel` centred at x that a grid line `line` wide covers (lines every 1/16): the
// overlap of the two intervals. Each pixel shows the mean of the content over its extent, as a renderer that filters
// its texture does: a line narrower than a pixel sampled at points breaks into dashes.
double grid_line_coverage(double x, double pixel, double line) {
    const double distance = std::abs(x - std::round(x * 16.0) / 16.0);
    const double overlap = std::min(distance + 0.5 * pixel, 0.5 * line) - std::max(distance - 0.5 * pixel, -0.5 * line);
    return std::clamp(overlap / pixel, 0.0, 1.0);
}

// The preview's content: white with grid lines (at 0.1) every 1/16 of the frame, `line` wide, as a pixel of extent
// `pixel` centred at (u, v) shows it.
double preview_content(double u, double v, ContentExtent pixel, ContentExtent line) {
    const double dark =
        1.0 - (1.0 - grid_line_coverage(u, pixel.u, line.u)) * (1.0 - grid_line_coverage(v, pixel.v, line.v));
    return 1.0 - 0.9 * dark;
}

// The content extent of projector pixel (x, y): the bounding box of its steps to the next pixel across and down
// (`fallback` where the warp has no content there).
ContentExtent pixel_extent(const ProjectorCalibration& pc, int x, int y, ContentUv at, ContentExtent fallback) {
    const ContentUv right = sample_warp(pc.warp, pc.output, std::min(x + 1, pc.output.width - 1), y);
    const ContentUv down = sample_warp(pc.warp, pc.output, x, std::min(y + 1, pc.output.height - 1));
    if (!right.valid() || !down.valid()) return fallback;
    const ContentExtent e{std::abs(right.u - at.u) + std::abs(down.u - at.u),
                          std::abs(right.v - at.v) + std::abs(down.v - at.v)};
    return e.u > 0.0 && e.v > 0.0 ? e : fallback;
}

// The preview grid's line width: two preview pixels, or three pixels of the coarsest projector where those are wider.
// The band of a line that covers whole projector pixels (its width less a pixel's) is then wider than the spacing of
// the preview's samples, so that every row and column of the preview sees the line as dark as the projectors draw
// it, not broken where it falls between its samples. The same for every projector: the content does not change at
// a seam.
ContentExtent grid_line_width(const ScreenCalibration& c, ContentExtent preview_pixel) {
    ContentExtent line{2.0 * preview_pixel.u, 2.0 * preview_pixel.v};
    for (const ProjectorCalibration& pc : c.projectors) {
        const int x = pc.output.width / 2;
        const int y = pc.output.height / 2;
        const ContentUv at = sample_warp(pc.warp, pc.output, x, y);
        if (!at.valid()) continue;
        const ContentExtent e = pixel_extent(pc, x, y, at, {});
        line.u = std::max(line.u, 3.0 * e.u);
        line.v = std::max(line.v, 3.0 * e.v);
    }
    return line;
}

// The light of the preview's content at screen point s, every projector whose (ground-truth) pixel lands
// there: as the rig's viewer sees it (`seen`: through the screen's gain) or as it leaves a matte screen. The content
// is shown less `indirect` (the outputs' field for it, empty: none).
double preview_light(const rig::VirtualRig& rig, const ScreenCalibration& c, const RgbFloatImage& indirect,
                     ContentExtent line, const rig::ScreenPoint& s, bool seen) {
    double l = 0.0;
    for (std::size_t k = 0; k < c.projectors.size(); ++k) {
        const auto p = rig::screen_to_projector(rig, static_cast<int>(k), s);
        if (!p) continue;
        const ProjectorCalibration& pc = c.projectors[k];
        const int px = static_cast<int>(p->x());
        const int py = static_cast<int>(p->y());
        const ContentUv uv = sample_warp(pc.warp, pc.output, px, py);
        if (!uv.valid()) continue;
        const auto grid = static_cast<float>(preview_content(uv.u, uv.v, pixel_extent(pc, px, py, uv, line), line));
        const double content = take_off_indirect_light({grid, grid, grid}, indirect, uv.u, uv.v)[1];
        // The rig's light (mean of the channels, black level included) for the signal
        // render_output gives: content x blend + beta -> response LUT, per channel.
        const float w = sample_blend(pc.blend, pc.output, px, py);
        const std::array<float, 3> beta = sample_beta(pc.beta, pc.output, px, py);
        const rig::RigProjector& rp = rig.projectors[k];
        const double f = rig::projector_falloff(rp, p->x(), p->y()) *
                         (seen ? rig::screen_gain(rig.screen, s, rp.pose.position_m, rig.viewer_m) : 1.0);
        for (std::size_t ch = 0; ch < 3; ++ch) {
            const double signal =
                apply_response(pc.response, static_cast<int>(ch), static_cast<float>(content) * w + beta[ch]);
            l += f * rp.brightness[ch] * (rp.black_level + (1.0 - rp.black_level) * std::pow(signal, rp.gamma[ch])) /
                 3.0;
        }
    }
    return l;
}

// The screen as the viewer sees it: per content pixel of a size x size/aspect image, preview_light as seen, plus one
// bounce of the screen's own light (virtual_rig.h's header comment).
Rgb8Image preview(const rig::VirtualRig& rig, const ScreenCalibration& c, int width,
                  const IndirectLight* compensation) {
    const int height = std::max(1, width * c.content.height / c.content.width);
    const ContentExtent pixel{1.0 / width, 1.0 / height};
    const ContentExtent line = grid_line_width(c, pixel);
    RgbFloatImage indirect;
    if (compensation != nullptr) {
        RgbFloatImage content(ImageSize{width, height});
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                std::fill_n(content.at(x, y), 3,
                            static_cast<float>(preview_content((x + 0.5) / width, (y + 0.5) / height, pixel, line)));
        indirect = compensation->field(compensation->patch_means(content));
    }
    std::optional<rig::ScreenBounce> bounce;
    std::vector<double> bounced;
    if (rig.screen.interreflection > 0.0) {
        bounce.emplace(rig.screen);
        std::vector<double> leaving;
        for (int i = 0; i < bounce->patches(); ++i)
            leaving.push_back(preview_light(rig, c, indirect, line, bounce->centre(i), false));
        bounced = bounce->bounce(leaving);
    }
    cv::Mat1f light(height, width, 0.0f);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const rig::ScreenPoint s = rig::screen_of(rig.screen, {(x + 0.5) / width, (y + 0.5) / height});
            light(y, x) = static_cast<float>(preview_light(rig, c, indirect, line, s, true) +
                                             (bounce ? bounce->at(bounced, s) : 0.0));
        }
    }
    Rgb8Image out(ImageSize{width, height});
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            std::uint8_t* px = out.at(x, y);
            px[0] = px[1] = px[2] =
                cv::saturate_cast<uchar>(255.0 * std::pow(std::clamp(light(y, x) / 1.1, 0.0, 1.0), 1.0 / 2.2));
        }
    }
    return out;
}

// Seams against the rig's ground truth at black, dark, mid grey and white content, on the default grid or
// (CalibrateJob::dense_seams) a pixel-dense one.
nlohmann::json seam_figures(const rig::VirtualRig& rig, const ScreenCalibration& c, const CalibrateJob& job,
                            const IndirectLight* indirect = nullptr) {
    nlohmann::json out = nlohmann::json::array();
    const SeamGridSize grid = job.dense_seams ? pixel_dense_seam_grid(rig) : SeamGridSize{};
    for (const double level : {0.0, 0.05, 0.5, 1.0}) {
        const SeamColour s = measure_seam_colour(rig, c, level, 0.01, indirect, job.defocused_truth, grid);
        out.push_back({{"level", level},
                       {"reference_luminance", s.reference_luminance},
                       {"seam_luminance_deviation", s.seam_luminance_deviation},
                       {"seam_luminance_pixel_max", s.seam_luminance_pixel_max},
                       {"luminance_max_deviation", s.luminance_max_deviation},
                       {"seam_delta_e76", s.seam_delta_e},
                       {"seam_luminance_p95", s.seam_luminance_p95},
                       {"seam_delta_e76_p95", s.seam_delta_e_p95},
                       {"delta_e76_max", s.delta_e_max},
                       {"seam_samples", s.seam_samples}});
    }
    return out;
}

// Projector k's part of report.json: decoding, fit, coverage, its lens distortion and the distortion trial's outcome
// (with the rig's true distortion beside it).
nlohmann::json projector_json(const AutocalResult& r, std::size_t k, const rig::VirtualRig& rig,
                              const AutocalOptions& options, double coverage) {
    const ProjectorReport& p = r.report.projectors[k];
    const DistortionTrial t = k < r.report.distortion.size() ? r.report.distortion[k] : DistortionTrial{};
    const std::array<double, 5>& d = r.projectors[k].distortion;
    return nlohmann::json{
        {"id", p.id},
        {"resolution", {r.projectors[k].resolution.width, r.projectors[k].resolution.height}},
        {"column_bits", p.column_bits},
        {"row_bits", p.row_bits},
        {"lit_pixels", p.lit_pixels},
        {"phase_refined", p.phase_refined},
        {"noise_sigma", p.noise_sigma},
        {"correspondences", p.cells},
        {"reprojection_rms_px", p.rms_px},
        {"reprojection_rms_sigma", p.rms_sigma},
        {"mean_view_angle_deg", p.mean_view_angle_deg},
        {"camera_coverage", coverage},
        {"distortion", {{"k1", d[0]}, {"k2", d[1]}, {"p1", d[2]}, {"p2", d[3]}, {"k3", d[4]}}},
        {"distortion_trial",
         {{"tried", t.tried},
          {"kept", t.kept},
          {"relative_cost", t.relative_cost},
          {"fit_relative_cost", t.fit_relative_cost},
          {"min_gain", options.distortion_min_gain},
          {"fitted",
           {{"k1", t.distortion[0]}, {"k2", t.distortion[1]}, {"p1", t.distortion[2]}, {"p2", t.distortion[3]}}}}},
        {"true_distortion", rig.projectors[k].intrinsics.distortion}};
}

// The camera as the calibration ended with it: edges, intrinsics fitted (or the prior's) beside the
// prior's, and the bundle adjustment's conditioning (standard deviations, condition number).
nlohmann::json camera_report(const AutocalResult& r, const CalibrationPrior& prior, const AutocalOptions& options) {
    const auto intrinsics = [](const DeviceModel& c) {
        return nlohmann::json{{"fx_px", c.fx_px}, {"fy_px", c.fy_px},      {"cx_px", c.cx_px},
                              {"cy_px", c.cy_px}, {"k1", c.distortion[0]}, {"k2", c.distortion[1]}};
    };
    nlohmann::json out = {{"edge_points", r.report.edge_points},
                          {"edge_rms_mm", r.report.edge_rms_m * 1e3},
                          {"intrinsics_refined", r.report.intrinsics.kept},
                          {"intrinsics_trial",
                           {{"tried", r.report.intrinsics.tried},
                            {"kept", r.report.intrinsics.kept},
                            {"relative_cost", r.report.intrinsics.relative_cost},
                            {"min_gain", options.intrinsics_min_gain}}},
                          {"intrinsics", intrinsics(r.camera)},
                          {"prior_intrinsics", intrinsics(prior.camera)},
                          {"bundle_condition_number", r.report.condition_number},
                          {"frame_straddle", r.report.frame_straddle},
                          {"max_frame_straddle", options.max_frame_straddle}};
    const std::vector<double>& s = r.report.camera_intrinsics_sigma;
    if (s.size() == 5) {
        out["intrinsics_sigma"] = {{"fx_px", s[0]}, {"cx_px", s[1]}, {"cy_px", s[2]}, {"k1", s[3]}, {"k2", s[4]}};
    }
    return out;
}

// What the camera saw of the self-check's marks (grey, gamma 2.2), each found mark's centroid (green) and
// where its content belongs as the check's camera sees it (red), 2x the camera's resolution.
Rgb8Image self_check_image(const SelfCheckResult& c) {
    constexpr int kZoom = 2;
    const cv::Mat1f& f = c.filmed;
    Rgb8Image out(ImageSize{f.cols * kZoom, f.rows * kZoom});
    double peak = 1e-6;
    for (int y = 0; y < f.rows; ++y)
        for (int x = 0; x < f.cols; ++x) peak = std::max(peak, static_cast<double>(f(y, x)));
    for (int y = 0; y < out.size.height; ++y) {
        for (int x = 0; x < out.size.width; ++x) {
            const double v = std::clamp(f(y / kZoom, x / kZoom) / peak, 0.0, 1.0);
            std::uint8_t* px = out.at(x, y);
            px[0] = px[1] = px[2] = cv::saturate_cast<uchar>(255.0 * std::pow(v, 1.0 / 2.2));
        }
    }
    const auto dot = [&](const Eigen::Vector2d& p, int channel, int r) {
        const int cx = static_cast<int>(p.x() * kZoom);
        const int cy = static_cast<int>(p.y() * kZoom);
        for (int dy = -r; dy <= r; ++dy) {
            for (int dx = -r; dx <= r; ++dx) {
                const int x = cx + dx;
                const int y = cy + dy;
                if ((dx != 0 && dy != 0) || x < 0 || y < 0 || x >= out.size.width || y >= out.size.height) continue;
                std::uint8_t* px = out.at(x, y);
                px[0] = px[1] = px[2] = 0;
                px[channel] = 255;
            }
        }
    };
    for (const SelfCheckMark& m : c.marks) {
        dot(m.camera_expected, 0, 8);
        dot(m.camera_observed, 1, 3);
    }
    return out;
}

// report.json's "screen": the fitted cylinder (radius, arc, top edge), the bow's trial and the prior's size.
nlohmann::json screen_report(const AutocalResult& r, const CalibrationPrior& prior, const CalibrateJob& job) {
    return {{"fitted", job.options.fit_screen},
            {"bow_m", r.screen.bow_m},
            {"bow_trial",
             {{"tried", r.report.bow.tried},
              {"kept", r.report.bow.kept},
              {"fitted_bow_m", r.report.bow.bow_m},
              {"cylinder_rms_sigma", r.report.bow.cylinder_rms_sigma},
              {"bowed_rms_sigma", r.report.bow.bowed_rms_sigma}}},
            {"radius_m", r.screen.radius_m},
            {"arc_deg", r.screen.arc_deg},
            {"prior_radius_m", prior.screen.radius_m},
            {"prior_arc_deg", prior.screen.arc_deg},
            {"heights_fitted", job.options.fit_heights && !job.options.fit_screen},
            {"bottom_m", r.screen.bottom_m},
            {"top_m", r.screen.top_m},
            {"prior_top_m", prior.screen.top_m},
            {"heights_check", heights_check_report(r.report.heights, job.options.max_heights_shift_px)}};
}

// report.json's "predicted": the blend's worst weight-sum deviation as the fitted models predict it.
nlohmann::json predicted_report(const AutocalResult& r) {
    const PredictedSeam& p = r.report.predicted_seam;
    return {{"seam_weight_sum_max_deviation", p.deviation},
            {"seam_at",
             {{"projector", p.projector},
              {"pixel", {p.x, p.y}},
              {"theta_deg", p.theta_rad * 180.0 / std::numbers::pi},
              {"h_m", p.h_m}}}};
}

// report.json's "ground_truth": the calibration measured against the rig's truth (none of it is the fit's own).
nlohmann::json ground_truth_report(const GeometryError& g, const LuminanceError& l, const AutocalResult& r,
                                   const rig::VirtualRig& rig) {
    return {{"geometry_mean_px", g.mean_px},
            {"geometry_p95_px", g.p95_px},
            {"geometry_max_px", g.max_px},
            {"geometry_samples", g.samples},
            {"missing", g.missing},
            {"outside", g.outside},
            {"luminance_max_deviation", l.max_deviation},
            {"seam_luminance_max_deviation", l.seam_max_deviation},
            {"seam_luminance_max_at",
             {{"theta_deg", l.seam_max_at.theta_rad * 180.0 / std::numbers::pi}, {"h_m", l.seam_max_at.h_m}}},
            {"camera_position_error_mm", (r.camera.position_m - rig.camera.pose.position_m).norm() * 1e3}};
}

// The job's files: the models first, so that whoever sees the new MPCDI (the kiosk's watcher) finds its models;
// then the MPCDI, the previews and report.json.
void write_job_outputs(const CalibrateJob& job, const AutocalResult& r, const rig::VirtualRig& rig,
                       const SelfCheckResult& check, const IndirectLight* indirect, const nlohmann::json& report) {
    std::filesystem::create_directories(job.out);
    MpcdiExportOptions mo;
    mo.alpha_bit_depth = job.alpha_bits;
    mo.write_response = job.colour;
    write_models(models_path_for(job.out / "calibration.mpcdi"), CalibrationModels{r.screen, r.camera, r.projectors});
    write_mpcdi(job.out / "calibration.mpcdi", to_mpcdi(r.calibration, mo));
    write_png(job.out / "preview.png",
              preview(rig, r.calibration, 960, indirect));  // libpng: no imgcodecs in the image
    if (!check.filmed.empty()) write_png(job.out / "self-check.png", self_check_image(check));
    const std::filesystem::path json = job.out / "report.json";
    std::ofstream f(json);
    f << report.dump(2) << "\n";
    if (!f) throw std::runtime_error("calibrate: cannot write '" + json.string() + "'");
}

}  // namespace

nlohmann::json run_calibrate_job(const CalibrateJob& job) {
    if (job.drop_frames < 0 || job.drop_frames > 30)
        throw std::invalid_argument("calibrate: drop_frames: 0..30, got " + std::to_string(job.drop_frames));
    const rig::VirtualRig rig = scaled_rig(rig::load_rig(job.rig), job.scale, job.scale);
    RigPatternSource source(rig, job.drop_frames);
    const CalibrationPrior prior = with_bench_lenses(prior_from_rig(rig), job.bench_lenses);
    const auto t0 = std::chrono::steady_clock::now();
    AutocalResult r = calibrate(source, prior, job.content, job.options);  // throws before any write
    double calibrate_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    nlohmann::json seams_before;
    std::optional<ColourResult> colour;
    if (job.colour) {
        seams_before = seam_figures(rig, r.calibration, job);
        const auto t1 = std::chrono::steady_clock::now();
        colour =
            calibrate_colour(source, r.screen, r.camera, r.projectors, r.calibration, job.colour_options);  // throws
        keep_screen_measurements(*colour, r.screen);
        calibrate_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    }
    // The self-check sees only the camera images and the calibration (no ground truth); its gate refuses
    // before anything is written. After the colour step, which it does not change.
    const auto t2 = std::chrono::steady_clock::now();
    const SelfCheckResult check = run_self_check(source, prior, r, job.self_check);
    calibrate_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t2).count();
    check_self_check_gate(check, job.self_check);
    const GeometryError g = measure_geometry(rig, r.calibration, 4);
    // The outputs take the screen's own light out of each frame when the colour step measured it.
    std::optional<IndirectLight> indirect;
    if (colour && job.indirect_light) indirect.emplace(r.screen, r.projectors, r.calibration);
    const IndirectLight* shown_less = indirect && indirect->active() ? &*indirect : nullptr;
    // One grid point per projector pixel: a seam's maximum must see a line one pixel wide.
    const LuminanceError l =
        measure_luminance(rig, r.calibration, 0.01, pixel_dense_seam_grid(rig), shown_less, job.defocused_truth);
    nlohmann::json report = {{"rig", rig.name},
                             {"rig_file", job.rig.string()},
                             {"scale", job.scale},
                             {"content", {job.content.width, job.content.height}},
                             {"captures", r.report.captures + check.captures},
                             {"geometry_captures", r.report.captures},
                             {"knobs",
                              {{"max_gray_bits", job.options.max_gray_bits},
                               {"frames_per_pattern", job.options.frames_per_pattern},
                               {"phase_shifts", job.options.phase_shifts},
                               {"warp_step_px", job.options.warp_step_px}}},
                             // Wall seconds: the calibration's own compute (calibrate and the colour step, without the
                             // rig's camera simulation, which a real camera replaces) and the simulation apart.
                             {"timing",
                              {{"compute_s", calibrate_s - source.simulate_s()},
                               {"simulate_s", source.simulate_s()},
                               {"calibrate_wall_s", calibrate_s}}},
                             {"camera", camera_report(r, prior, job.options)},
                             {"self_check", self_check_report(check, job.self_check)},
                             {"screen", screen_report(r, prior, job)},
                             {"predicted", predicted_report(r)},
                             {"ground_truth", ground_truth_report(g, l, r, rig)}};
    if (colour) {
        report["colour"] = colour_report(*colour);
        report["colour"]["indirect_light"] = indirect_light_report(shown_less);
        report["captures"] = r.report.captures + check.captures + colour->captures;
        report["ground_truth"]["seams_before_colour"] = seams_before;
    }
    report["ground_truth"]["seams"] = seam_figures(rig, r.calibration, job, shown_less);
    const SeamGridSize standard;
    report["ground_truth"]["seams_grid"] = job.dense_seams
                                               ? std::string("pixel-dense")
                                               : std::to_string(standard.columns) + "x" + std::to_string(standard.rows);
    report["ground_truth"]["defocused"] = job.defocused_truth;
    for (std::size_t k = 0; k < r.report.projectors.size(); ++k) {
        report["projectors"].push_back(
            projector_json(r, k, rig, job.options, source.simulator().camera_coverage(static_cast<int>(k))));
        const bool bench = k < job.bench_lenses.size() && job.bench_lenses[k];
        report["projectors"].back()["prior_lens"] = bench ? job.bench_lenses[k]->source : "data sheet";
    }
    write_job_outputs(job, r, rig, check, shown_less, report);
    return report;
}

}  // namespace mogao::autocal
