// SPDX-License-Identifier: Apache-2.0
// The bench calibration as one job (what `mogao-calibrate procam` runs): capture folders in, the
// procam file out (procam_calibration.h), with leave-one-capture-out errors when there are three or
// more captures.
#pragma once

#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "appliance/procam/gray_decode.h"
#include "appliance/procam/local_homography.h"
#include "appliance/procam/procam_calibration.h"

namespace mogao::procam {

struct ProcamJob {
    std::vector<std::filesystem::path> captures;  // folders (capture_folder.h)
    ImageSize projector;
    BoardSpec board;
    DecodeOptions decode;
    HomographyOptions homography;
    CalibrationOptions calibration;
};

// Loads, decodes and observes one folder (its name is the folder's name); `camera` receives the
// camera's size. Throws ProcamError naming the folder or file (capture_folder.h, observe_board).
[[nodiscard]] BoardObservation observe_folder(const std::filesystem::path& folder, const GrayLayout& layout,
                                              const ProcamJob& job, ImageSize& camera);

struct ProcamJobResult {
    std::vector<BoardObservation> views;
    ProcamCalibration calibration;
    std::vector<HeldOutError> held_out;  // empty with fewer than 3 captures
    nlohmann::json file;                 // procam_json of the above, plus lit/decoded fractions per capture
};

// Throws ProcamError (a folder, file or capture), std::invalid_argument (a size, board or option out
// of range, fewer than 2 captures), or ProcamError if the captures' camera sizes differ.
[[nodiscard]] ProcamJobResult run_procam_job(const ProcamJob& job);

}  // namespace mogao::procam
