// SPDX-License-Identifier: Apache-2.0
// The calibration from captured images (`mogao-calibrate --site FILE --images DIR --out OUT`,
// docs/on-site-calibration.md, "Calibration from captured images"): the on-site job's calibration
// (on_site_job.h, steps 2 and 5) with the camera images read from DIR (image_folder_source.h)
// instead of filmed live. No outputs are driven and no connector is identified: projector k is the
// one that showed the files of folder p<k>/ (`mogao-calibrate patterns`). Geometry only (the colour
// step needs exposure changes; the MPCDI carries no response): job.colour is ignored.
//
// Files, into job.out (and job.install), as the on-site job writes them: calibration.models.json,
// calibration.mpcdi (the previous ones kept as *.last-good), report.json (per projector the fit, the
// screen, "images": the folder, its captures manifest and pattern set, the captures used) and
// camera-white.png (the capture of every projector white). Any error or refusal happens before the
// first file is written: the last good calibration stays.
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "kiosk/calibrate/on_site_job.h"

namespace mogao::calibrate {

// Runs the job from `images` (holding captures.json); returns the report (also written). Throws
// autocal::CalibrationRefused, rig::RigError, std::runtime_error naming the file or field.
nlohmann::json run_from_images(const OnSiteJob& job, const std::filesystem::path& images);

}  // namespace mogao::calibrate
