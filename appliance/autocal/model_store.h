// SPDX-License-Identifier: Apache-2.0
// The fitted models of a calibration, stored beside its MPCDI file (docs/kiosk.md, "The models
// file"): the screen cylinder, the camera (intrinsics, distortion, pose) and every
// projector (intrinsics, pose) that `mogao-calibrate-sim rig` fitted. The MPCDI holds only what the
// compositor needs (warp maps, blend masks, responses); self-recalibration (appliance/selfcal,
// the kiosk's [selfcal]) needs the models to predict what the screen camera sees and to rebuild
// the warps from re-estimated poses, so they travel with the MPCDI as `<name>.models.json`.
//
// Schema (JSON, version 1; every number finite):
//   {"format": "mogao-calibration-models", "version": 1,
//    "screen": {"radius_m", "arc_deg", "bottom_m", "top_m", "bow_m": [4 numbers, optional: zeros]},
//    "camera": DEVICE, "projectors": [DEVICE, ...]}           // projectors in the MPCDI's order
//   DEVICE = {"id": "proj0", "resolution": [width, height],   // pixels, [1, 16384] per side
//             "fx_px", "fy_px",                                 // focal lengths, pixels, > 0
//             "cx_px", "cy_px",                                 // principal point, image positions
//             "distortion": [k1, k2, p1, p2, k3],               // OpenCV Brown-Conrady; a projector's as
//                                                                // fitted (the distortion trial; zeros for
//                                                                // a pinhole): k1, k2, k3 in [-1, 1], p1, p2
//                                                                // in [-0.1, 0.1], one-to-one out to 1.2x
//                                                                // the image's corners
//             "rotation": [[r00, r01, r02], [..], [..]],         // device -> screen frame, row-major,
//                                                                // orthonormal, det +1 (within 1e-6)
//             "position_m": [x, y, z],                          // device centre, screen frame, metres
//             "falloff": [c0, .., c5]}                          // projectors, optional (absent = flat):
//                                                                // autocal.h's LensFalloff, each in
//                                                                // [-10, 10], F in [0.05, 5] over the image
// Frames and pixel conventions are autocal.h's (the virtual rig's): screen frame in metres, +y up
// the cylinder's axis, -z to the middle of the arc, origin on the axis at floor level; devices in
// OpenCV's camera frame (x right, y down, z forward); image positions with pixel (x, y)'s centre at
// (x + 0.5, y + 0.5).
//
// Errors: ModelStoreError, whose message names the file and the field as a JSON path with the value
// and the limit, e.g. "calibration.models.json: projectors[1].fx_px = -3 is outside (0, 1e6] px".
// The reader returns a whole, valid value or throws. The writer is atomic (common/file_io.h:
// temporary, fsync, rename): a reader sees the old file or the new one.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "appliance/autocal/autocal.h"
#include "common/projector_calibration.h"

namespace mogao::autocal {

struct ModelStoreError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct CalibrationModels {
    ScreenModel screen;
    DeviceModel camera;
    std::vector<DeviceModel> projectors;  // the MPCDI's order
};

// `calibration.mpcdi` -> `calibration.models.json` (the extension replaced).
[[nodiscard]] std::filesystem::path models_path_for(const std::filesystem::path& mpcdi);

// The JSON form (schema above). Throws ModelStoreError (file name `name`) for a model that would
// not read back (non-finite numbers, bad sizes): nothing invalid is written.
[[nodiscard]] nlohmann::json models_json(const CalibrationModels& models, const std::string& name = "models");

// Parses and validates `json` as read from `name`. Throws ModelStoreError.
[[nodiscard]] CalibrationModels models_from_json(const nlohmann::json& json, const std::string& name);

// Writes atomically. Throws ModelStoreError (invalid models) or std::system_error naming the file.
void write_models(const std::filesystem::path& file, const CalibrationModels& models);

// Reads and validates (at most 16 MiB). Throws ModelStoreError naming the file.
[[nodiscard]] CalibrationModels read_models(const std::filesystem::path& file);

// The models belong to `calibration`: as many projectors, the same ids in the same order and the
// same resolutions. Throws ModelStoreError naming `name`, the field and both values.
void check_models_match(const CalibrationModels& models, const ScreenCalibration& calibration, const std::string& name);

}  // namespace mogao::autocal
