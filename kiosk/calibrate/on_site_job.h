// SPDX-License-Identifier: Apache-2.0
// The on-site calibration job (`mogao-calibrate --outputs kms|headless --camera NAME`,
// docs/on-site-calibration.md): the camera-based calibration of appliance/autocal run on the
// appliance's outputs and a camera, from the site file to the files the kiosk loads.
//
// Site file: a rig file (rigs/*.toml, appliance/rig/rig_file.h) describing the installation as
// measured: [screen], the camera's intrinsics (chessboard, `mogao-calibrate camera-intrinsics`) and
// roughly measured pose, and per projector (listed left to right as the viewer sees them) its id,
// resolution (= its output's mode), throw ratio and lens shift from the data sheet; [prior] errors
// 0. Responses, gamma, noise and the projectors' poses are not used (they are what is measured).
//
// Steps: (0) the camera's exposure must be locked: refused before any pattern is shown; (1) which
// output drives which projector, from the camera (connector_identity.h), with each connector's
// EDID; (2) autocal::calibrate (Gray code, camera pose, projector fits, bundle adjustment, warp,
// blend) and (3) autocal::calibrate_colour unless `colour` is off, both through
// HardwarePatternSource; (3b) the self-check (appliance/autocal/self_check.h): marks through the new warp
// and blend, filmed, against where their content belongs, with no ground truth; above its gate
// (self_check.max_mean_px, --max-self-check-px) the calibration is refused; (4) all outputs black again; (5) the files,
// into `out`:
//   calibration.models.json, calibration.mpcdi  as mogao-calibrate-sim rig writes them (atomic, the models
//                      first); a calibration.mpcdi already there is kept as calibration.mpcdi.last-good
//                      (and its models as calibration.models.json.last-good) before it is replaced,
//   report.json        per projector the fit (bits, correspondences, reprojection rms, view angle),
//                      "connectors" (projector id, connector name, EDID, lit fraction, centroid),
//                      "cabling_changes" against the previous report.json in `out`, the captured image
//                      count, capture seconds and seconds per image, the budget, the camera, the colour
//                      step's figures, "self_check" (the on-site accuracy figure: the marks' error in projector
//                      pixels, mean / p95 / max, in mm, marks found); no ground truth (there is none on site),
//   camera-white.png   what the camera saw with every projector white (8-bit, the camera's codes
//                      re-encoded sRGB): where the screen and the projectors are, for the technician.
// and, when `install` is set, the MPCDI and its models also to `install` (the kiosk's
// [calibration].source on the config partition, e.g. /var/lib/mogao/etc/screen.mpcdi), the previous
// ones kept as <file>.last-good; the kiosk's calibration watcher swaps it in if the kiosk runs.
// A refusal (autocal::CalibrationRefused) or any error writes nothing: the last good calibration
// stays where it was.
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/calibration_settings.h"
#include "appliance/autocal/colour_calibration.h"
#include "appliance/autocal/model_store.h"
#include "appliance/autocal/self_check.h"
#include "drivers/output.h"
#include "kiosk/calibrate/calibration_camera.h"
#include "kiosk/calibrate/hardware_pattern_source.h"

namespace mogao::calibrate {

// The settings (appliance/autocal/calibration_settings.h: scale, content, alpha bits, options, colour, self-check,
// step 3b and its gate) and the site's own.
struct OnSiteJob : autocal::CalibrationSettings {
    std::filesystem::path site;     // rig-format site file (above)
    std::filesystem::path out;      // folder, created if missing
    std::filesystem::path install;  // empty: none
    CaptureTiming timing;
    CameraTransfer transfer = CameraTransfer::srgb;
    double min_lit_fraction = 0.01;  // identification: an output must light this much of the camera image
    int flip_timeout_ms = 2000;
};

// The calibration prior the site file gives (scaled by job.scale), with the bench lenses its projectors name
// (projectors[k].procam: procam_command.h, bench_lenses_of). Throws rig::RigError, or std::runtime_error naming
// the procam file.
[[nodiscard]] autocal::CalibrationPrior site_prior(const OnSiteJob& job);

// Runs the job on `outputs` (the backend's GL context current on this thread) and `camera`; returns
// the report (also written). Throws autocal::CalibrationRefused (nothing written), rig::RigError,
// std::runtime_error naming the output, camera or file.
nlohmann::json run_on_site(const OnSiteJob& job, OutputBackend& outputs, CalibrationCamera& camera,
                           const ProgressFn& progress);

// Shared with the captured-images route (images_job.h):
// report.json's per-projector fit and screen entries (above);
[[nodiscard]] nlohmann::json fit_json(const autocal::AutocalResult& r, std::size_t k);
[[nodiscard]] nlohmann::json screen_json(const autocal::AutocalResult& r, const autocal::AutocalOptions& options);
// the MPCDI and its models at `mpcdi`, the previous ones kept as <file>.last-good (above);
void write_calibration(const std::filesystem::path& mpcdi, const autocal::CalibrationModels& models,
                       const ScreenCalibration& c, const OnSiteJob& job);
// a linear camera image as an 8-bit sRGB PNG (camera-white.png).
void write_camera_png(const std::filesystem::path& png, const cv::Mat1f& linear);

}  // namespace mogao::calibrate
