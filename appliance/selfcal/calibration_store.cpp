// SPDX-License-Identifier: Apache-2.0
// Atomic calibration writes keeping the last good one (calibration_store.h).
#include "appliance/selfcal/calibration_store.h"

#include <system_error>

#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/calibration/mpcdi_writer.h"
#include "appliance/warp/response_curve.h"
#include "common/file_io.h"

namespace mogao::selfcal {

std::filesystem::path last_good_path(const std::filesystem::path& path) {
    return std::filesystem::path(path.string() + ".last-good");
}

ScreenCalibration load_calibration(const std::filesystem::path& path) {
    return to_screen_calibration(read_mpcdi(path));
}

void save_calibration(const std::filesystem::path& path, const ScreenCalibration& calibration) {
    MpcdiExportOptions options;
    options.alpha_bit_depth = 16;
    const ResponseCurve assumed = make_gamma_response();  // what the reader uses without the entry
    for (const ProjectorCalibration& pc : calibration.projectors) {
        options.write_response = options.write_response || pc.response.lut != assumed.lut;
    }
    const MpcdiFile file = to_mpcdi(calibration, options);  // throws before anything is touched
    std::error_code ec;
    if (std::filesystem::is_regular_file(path, ec)) {
        bool readable = true;
        try {
            (void)load_calibration(path);
        } catch (const std::exception&) {
            readable = false;  // never replace the last good one with a broken file
        }
        if (readable) write_file_atomically(last_good_path(path), read_file_bytes(path));
    }
    write_mpcdi(path, file);
}

void save_models(const std::filesystem::path& path, const autocal::CalibrationModels& models) {
    (void)autocal::models_json(models, path.filename().string());  // throws before anything is touched
    std::error_code ec;
    if (std::filesystem::is_regular_file(path, ec)) {
        bool readable = true;
        try {
            (void)autocal::read_models(path);
        } catch (const std::exception&) {
            readable = false;  // never replace the last good one with a broken file
        }
        if (readable) write_file_atomically(last_good_path(path), read_file_bytes(path));
    }
    autocal::write_models(path, models);
}

}  // namespace mogao::selfcal
