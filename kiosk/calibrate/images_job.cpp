// SPDX-License-Identifier: Apache-2.0
// The calibration from a folder of captured images (images_job.h).
#include "kiosk/calibrate/images_job.h"

#include <fstream>
#include <stdexcept>

#include "appliance/calibration/mpcdi_screen.h"
#include "kiosk/calibrate/image_folder_source.h"
#include "kiosk/calibrate/pattern_catalogue.h"

namespace mogao::calibrate {

namespace fs = std::filesystem;

nlohmann::json run_from_images(const OnSiteJob& job, const fs::path& images) {
    const autocal::CalibrationPrior prior = site_prior(job);
    CapturesManifest manifest = read_captures_manifest(images);
    const PatternCatalogue catalogue(prior.projectors, job.options, manifest.phase_periods_px);
    check_captures(manifest, catalogue, prior.camera.resolution);
    ImageFolderSource source(catalogue, manifest, prior.camera.resolution, job.transfer);
    const autocal::AutocalResult r = autocal::calibrate(source, prior, job.content, job.options);
    OnSiteJob geometry = job;
    geometry.colour = false;
    nlohmann::json report = {{"site_file", job.site.string()},
                             {"scale", job.scale},
                             {"content", {job.content.width, job.content.height}},
                             {"images",
                              {{"folder", images.string()},
                               {"manifest", manifest.file.string()},
                               {"pattern_set", manifest.pattern_set},
                               {"patterns", catalogue.patterns().size()}}},
                             {"camera",
                              {{"source", "captured images in " + images.string()},
                               {"edge_points", r.report.edge_points},
                               {"edge_rms_mm", r.report.edge_rms_m * 1e3}}},
                             {"captures", source.images()}};
    for (std::size_t k = 0; k < r.projectors.size(); ++k) report["projectors"].push_back(fit_json(r, k));
    report["screen"] = screen_json(r, job.options);
    const autocal::CalibrationModels models{r.screen, r.camera, r.projectors};
    write_calibration(job.out / "calibration.mpcdi", models, r.calibration, geometry);
    if (!job.install.empty()) write_calibration(job.install, models, r.calibration, geometry);
    if (!source.white().empty()) write_camera_png(job.out / "camera-white.png", source.white());
    const fs::path json = job.out / "report.json";
    std::ofstream f(json);
    f << report.dump(2) << "\n";
    if (!f) throw std::runtime_error("calibrate: cannot write '" + json.string() + "'");
    return report;
}

}  // namespace mogao::calibrate
