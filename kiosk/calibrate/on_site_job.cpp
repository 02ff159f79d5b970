// SPDX-License-Identifier: Apache-2.0
// The on-site calibration job: outputs + camera -> calibration -> files (on_site_job.h).
#include "kiosk/calibrate/on_site_job.h"

#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>

#include "appliance/autocal/colour_report.h"
#include "appliance/autocal/model_store.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/calibration/mpcdi_writer.h"
#include "appliance/rig/rig_file.h"
#include "common/file_io.h"
#include "common/png_io.h"
#include "common/srgb.h"
#include "kiosk/calibrate/connector_identity.h"
#include "kiosk/calibrate/pattern_budget.h"
#include "kiosk/calibrate/procam_command.h"

namespace mogao::calibrate {

namespace fs = std::filesystem;

nlohmann::json fit_json(const autocal::AutocalResult& r, std::size_t k) {
    const autocal::ProjectorReport& p = r.report.projectors[k];
    return {{"id", p.id},
            {"resolution", {r.projectors[k].resolution.width, r.projectors[k].resolution.height}},
            {"column_bits", p.column_bits},
            {"row_bits", p.row_bits},
            {"correspondences", p.cells},
            {"reprojection_rms_px", p.rms_px},
            {"reprojection_rms_sigma", p.rms_sigma},
            {"mean_view_angle_deg", p.mean_view_angle_deg}};
}

nlohmann::json screen_json(const autocal::AutocalResult& r, const autocal::AutocalOptions& options) {
    return {{"radius_m", r.screen.radius_m},
            {"arc_deg", r.screen.arc_deg},
            {"bow_m", r.screen.bow_m},
            {"bow_kept", r.report.bow.kept},
            {"cylinder_rms_sigma", r.report.bow.cylinder_rms_sigma},
            {"bowed_rms_sigma", r.report.bow.bowed_rms_sigma},
            {"fitted", options.fit_screen},
            {"heights_fitted", options.fit_heights && !options.fit_screen},
            {"bottom_m", r.screen.bottom_m},
            {"top_m", r.screen.top_m},
            {"heights_check", autocal::heights_check_report(r.report.heights, options.max_heights_shift_px)}};
}

namespace {

// Makes the renames in the folder of `file` durable. Best effort, as write_mpcdi's: the files are
// complete whether or not this flush succeeds.
void sync_folder(const fs::path& file) {
    const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
    const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    (void)::fsync(fd);
    ::close(fd);
}

}  // namespace

// Copies `file` (when present) to `<file>.last-good` atomically and durably (temporary, fsync,
// rename: a power cut must not leave an empty last good copy).
void keep_last_good(const fs::path& file) {
    if (!fs::exists(file)) return;
    write_file_atomically(file.string() + ".last-good", read_file_bytes(file));
}

// Both files are first written complete and flushed beside their targets (`<file>.staged`), then
// renamed into place one right after the other: no flush between the two renames, so ext4 commits
// them in one journal transaction and a power cut leaves the old pair or the new pair, never new
// models beside the old MPCDI (writing each file atomically on its own left seconds between the
// two: the MPCDI's encoding and flush). Models first: a running kiosk's calibration watcher reacts
// to the MPCDI and then finds its models.
void write_calibration(const fs::path& mpcdi, const autocal::CalibrationModels& models, const ScreenCalibration& c,
                       const OnSiteJob& job) {
    fs::create_directories(mpcdi.parent_path().empty() ? fs::path(".") : mpcdi.parent_path());
    const fs::path models_file = autocal::models_path_for(mpcdi);
    keep_last_good(models_file);
    keep_last_good(mpcdi);
    MpcdiExportOptions mo;
    mo.alpha_bit_depth = job.alpha_bits;
    mo.write_response = job.colour;
    const fs::path staged_models = models_file.string() + ".staged";
    const fs::path staged_mpcdi = mpcdi.string() + ".staged";
    autocal::write_models(staged_models, models);
    write_mpcdi(staged_mpcdi, to_mpcdi(c, mo));
    fs::rename(staged_models, models_file);
    fs::rename(staged_mpcdi, mpcdi);
    sync_folder(mpcdi);
}

// 8-bit sRGB PNG with libpng (common/png_io.h; OpenCV's imgcodecs would bring GDAL, HDF5, Poppler ...
// into the appliance image, docs/image.md).
void write_camera_png(const fs::path& png, const cv::Mat1f& linear) {
    Rgb8Image out(ImageSize{linear.cols, linear.rows});
    for (int y = 0; y < linear.rows; ++y) {
        for (int x = 0; x < linear.cols; ++x) {
            std::uint8_t* px = out.at(x, y);
            px[0] = px[1] = px[2] = srgb8_encode(linear(y, x));
        }
    }
    write_png(png, out);
}

namespace {

struct Identified {
    std::vector<std::size_t> projector_output;
    std::vector<LitOutput> lit;
    cv::Mat1f white;  // every output white
};

// Step 1 (connector_identity.h): black, all white, each output white alone.
Identified identify(HardwarePatternSource& source, const PatternDisplay& display,
                    const autocal::CalibrationPrior& prior, double min_contrast, double min_lit_fraction) {
    const std::size_t outputs = display.output_count();
    std::vector<cv::Mat> per_output(outputs);
    const cv::Mat1f black = source.show_outputs(per_output);
    std::vector<cv::Mat> all(outputs);
    for (std::size_t i = 0; i < outputs; ++i) {
        all[i] = cv::Mat1f(display.output(i).size.height, display.output(i).size.width, 1.0f);
    }
    Identified id;
    id.white = source.show_outputs(all);
    std::vector<cv::Mat1f> alone;
    for (std::size_t i = 0; i < outputs; ++i) {
        per_output.assign(outputs, cv::Mat());
        per_output[i] = all[i];
        alone.push_back(source.show_outputs(per_output));
    }
    id.lit = lit_outputs(black, alone, min_contrast);
    std::vector<std::string> names;
    std::vector<std::string> ids;
    for (std::size_t i = 0; i < outputs; ++i) names.push_back(display.output(i).name);
    for (const autocal::DeviceModel& p : prior.projectors) ids.push_back(p.id);
    id.projector_output = assign_projectors(id.lit, names, ids, min_lit_fraction);
    for (std::size_t k = 0; k < ids.size(); ++k) {
        const OutputInfo& o = display.output(id.projector_output[k]);
        const ImageSize want = prior.projectors[k].resolution;
        if (o.size.width != want.width || o.size.height != want.height) {
            throw std::runtime_error("projector " + std::to_string(k) + " '" + ids[k] + "' is on connector " + o.name +
                                     " whose mode is " + std::to_string(o.size.width) + "x" +
                                     std::to_string(o.size.height) + "; the site file says " +
                                     std::to_string(want.width) + "x" + std::to_string(want.height));
        }
    }
    return id;
}

nlohmann::json connectors_json(const Identified& id, const PatternDisplay& display,
                               const autocal::CalibrationPrior& prior) {
    nlohmann::json out = nlohmann::json::array();
    for (std::size_t k = 0; k < id.projector_output.size(); ++k) {
        const std::size_t i = id.projector_output[k];
        const LitOutput& l = id.lit[i];
        nlohmann::json c = {{"projector", prior.projectors[k].id},
                            {"connector", display.output(i).name},
                            {"refresh_hz", display.output(i).refresh_hz},
                            {"lit_fraction", l.lit_fraction},
                            {"centroid_x_px", l.centroid_x}};
        if (const auto edid = read_connector_edid(display.output(i).name)) {
            c["edid"] = {{"manufacturer", edid->manufacturer},
                         {"product", edid->product},
                         {"serial", edid->serial},
                         {"serial_text", edid->serial_text},
                         {"name", edid->name}};
        }
        out.push_back(c);
    }
    return out;
}

nlohmann::json previous_connectors(const fs::path& report) {
    std::ifstream f(report);
    if (!f) return nullptr;
    try {
        const nlohmann::json j = nlohmann::json::parse(f);
        return j.contains("connectors") ? j["connectors"] : nlohmann::json(nullptr);
    } catch (const nlohmann::json::exception&) {
        return nullptr;  // an unreadable old report only means no comparison
    }
}

// Steps 4-5: the report and the files (on_site_job.h).
nlohmann::json finish(const OnSiteJob& job, const Identified& id, const autocal::AutocalResult& r,
                      const std::optional<autocal::ColourResult>& colour, const autocal::SelfCheckResult& check,
                      const PatternDisplay& display, const autocal::CalibrationPrior& prior,
                      const CalibrationCamera& camera, const PatternBudget& budget, double seconds, int images) {
    nlohmann::json report = {{"site_file", job.site.string()},
                             {"scale", job.scale},
                             {"content", {job.content.width, job.content.height}},
                             {"camera",
                              {{"source", camera.description()},
                               {"edge_points", r.report.edge_points},
                               {"edge_rms_mm", r.report.edge_rms_m * 1e3},
                               {"frame_straddle", r.report.frame_straddle}}},
                             {"captures", images},
                             {"budget",
                              {{"identification", budget.identification},
                               {"geometry_at_most", budget.geometry},
                               {"colour", budget.colour},
                               {"self_check", budget.self_check},
                               {"total", budget.total()}}},
                             {"capture_seconds", seconds},
                             {"seconds_per_image", seconds / std::max(1, images)},
                             {"settle_ms", job.timing.settle_ms},
                             {"drop_frames", job.timing.drop_frames}};
    report["connectors"] = connectors_json(id, display, prior);
    report["cabling_changes"] = cabling_changes(previous_connectors(job.out / "report.json"), report["connectors"]);
    const auto lenses = bench_lenses_of(rig::load_rig(job.site), job.site.string());
    for (std::size_t k = 0; k < r.projectors.size(); ++k) {
        report["projectors"].push_back(fit_json(r, k));
        report["projectors"].back()["prior_lens"] = k < lenses.size() && lenses[k] ? lenses[k]->source : "data sheet";
    }
    if (colour) {
        report["colour"] = autocal::colour_report(*colour);
        // What the kiosk will take off each frame of the screen's own light, from the models written below.
        const autocal::IndirectLight indirect(r.screen, r.projectors, r.calibration);
        report["colour"]["indirect_light"] = autocal::indirect_light_report(indirect.active() ? &indirect : nullptr);
    }
    report["self_check"] = autocal::self_check_report(check, job.self_check);
    // The screen the calibration used: the site file's cylinder, with the bow where it paid (autocal.h).
    report["screen"] = screen_json(r, job.options);
    const autocal::CalibrationModels models{r.screen, r.camera, r.projectors};
    write_calibration(job.out / "calibration.mpcdi", models, r.calibration, job);
    if (!job.install.empty()) write_calibration(job.install, models, r.calibration, job);
    write_camera_png(job.out / "camera-white.png", id.white);
    const fs::path json = job.out / "report.json";
    std::ofstream f(json);
    f << report.dump(2) << "\n";
    if (!f) throw std::runtime_error("calibrate: cannot write '" + json.string() + "'");
    return report;
}

}  // namespace

autocal::CalibrationPrior site_prior(const OnSiteJob& job) {
    const rig::VirtualRig site = rig::load_rig(job.site);
    return autocal::with_bench_lenses(autocal::prior_from_rig(autocal::scaled_rig(site, job.scale, job.scale)),
                                      bench_lenses_of(site, job.site.string()));
}

nlohmann::json run_on_site(const OnSiteJob& job, OutputBackend& outputs, CalibrationCamera& camera,
                           const ProgressFn& progress) {
    const autocal::CalibrationPrior prior = site_prior(job);
    if (outputs.outputs().size() < prior.projectors.size()) {
        throw std::runtime_error("the site file has " + std::to_string(prior.projectors.size()) +
                                 " projectors, the outputs only " + std::to_string(outputs.outputs().size()));
    }
    auto display = PatternDisplay::create(outputs, job.flip_timeout_ms);
    if (!display) throw std::runtime_error(display.error().message);
    const PatternBudget budget = pattern_budget(prior, job.colour, job.colour_options, job.options, job.self_check);
    std::vector<std::size_t> order(prior.projectors.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    HardwarePatternSource source(display.value(), camera, order, prior.camera.resolution, job.transfer, job.timing,
                                 budget.total(), progress);
    autocal::require_locked_exposure(source);  // step 0: before any pattern is shown
    const std::vector<cv::Mat> dark(display.value().output_count());
    std::optional<Identified> id;
    std::optional<autocal::AutocalResult> r;
    std::optional<autocal::ColourResult> colour;
    std::optional<autocal::SelfCheckResult> check;
    try {
        id = identify(source, display.value(), prior, job.options.min_contrast, job.min_lit_fraction);
        source.set_projector_output(id->projector_output);
        r = autocal::calibrate(source, prior, job.content, job.options);
        if (job.colour) {
            colour = autocal::calibrate_colour(source, r->screen, r->camera, r->projectors, r->calibration,
                                               job.colour_options);
            autocal::keep_screen_measurements(*colour, r->screen);
        }
        check = autocal::run_self_check(source, prior, *r, job.self_check);  // step 3b
        autocal::check_self_check_gate(*check, job.self_check);
    } catch (...) {
        (void)display.value().show_outputs(dark);  // refused or failed: the wall goes dark, not a stripe pattern
        throw;
    }
    const double seconds = source.seconds();
    const int images = source.images();
    if (auto s = display.value().show_outputs(dark); !s) throw std::runtime_error(s.error().message);
    return finish(job, *id, *r, colour, *check, display.value(), prior, camera, budget, seconds, images);
}

}  // namespace mogao::calibrate
