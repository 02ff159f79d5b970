// SPDX-License-Identifier: Apache-2.0
// The corrected calibration on the config partition: written atomically as MPCDI (appliance/
// calibration's writer: temporary file, fsync, rename), the previous good one kept beside it.
#pragma once

#include <filesystem>

#include "appliance/autocal/model_store.h"
#include "common/projector_calibration.h"

namespace mogao::selfcal {

// `<path>.last-good`: where save_calibration keeps the calibration it replaced.
[[nodiscard]] std::filesystem::path last_good_path(const std::filesystem::path& path);

// If `path` holds a readable calibration, first copies it (atomically) to last_good_path(path),
// then writes `calibration` to `path` atomically: 16-bit alpha maps, beta maps where a projector
// has one, and each projector's response LUT (mogao's ResponseLUT entry) unless every response is
// the gamma 2.2 the reader assumes without it, so a measured colour survives the file (docs/
// calibration.md, "Self-recalibration"). A write that fails or is interrupted at any
// point leaves `path` holding the previous complete calibration. Throws MpcdiError /
// std::system_error naming the file, std::invalid_argument for an invalid calibration.
void save_calibration(const std::filesystem::path& path, const ScreenCalibration& calibration);

// The models the calibration at `path` was built from (autocal/model_store.h's file, e.g.
// `<name>.models.json`), saved the same way: a readable file at `path` is first copied to
// last_good_path(path), then `models` written atomically. After a correction the models file must
// hold the corrected poses, or a restart would monitor the corrected warps with the old poses.
// Throws autocal::ModelStoreError / std::system_error naming the file.
void save_models(const std::filesystem::path& path, const autocal::CalibrationModels& models);

// Reads a calibration written by save_calibration (MPCDI 2d profile). Throws MpcdiError.
[[nodiscard]] ScreenCalibration load_calibration(const std::filesystem::path& path);

}  // namespace mogao::selfcal
