// SPDX-License-Identifier: Apache-2.0
// HeadlessRecorder: what the headless kiosk leaves behind for people and tests to look at.
//
// * Every k-th display round (a round = one show or repaint that presented the outputs), each
//   output's pixels as <dir>/<output>-<round, 6 digits>-req<request id>.png (request id 0 = the
//   kiosk's connecting screen), written atomically (common/png_io.h).
// * At exit, <dir>/screen-composite.png: the light on the cylindrical screen computed by the CPU
//   reference composite_on_screen (appliance/warp/composite.h) from the last frame of every
//   output, encoded back to sRGB. It is content-sized and should look like the content frame:
//   visible seams or a wrong brightness in the overlaps mean the calibration or the GL path is off.
//
// Errors: write_round/write_composite throw EncodeError or std::invalid_argument naming the file;
// the kiosk logs them and carries on (a full disk must not stop the show).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "common/projector_calibration.h"
#include "drivers/headless/headless_output.h"

namespace mogao {

class HeadlessRecorder {
public:
    // `dir` is created if missing (std::filesystem_error when it cannot be). every >= 1.
    HeadlessRecorder(const HeadlessOutputBackend& backend, std::filesystem::path dir, int every);

    // After display round `round` (counted from 1) showed request `request_id`: writes the PNGs
    // when round % every == 0. Returns the number of files written.
    std::size_t write_round(std::uint64_t round, std::uint64_t request_id);

    // The composited screen from the outputs' last frames; projector_of[i] is output i's projector
    // in `screen` (ScreenPresenter::projector_of). Outputs without a frame or projector add no light.
    void write_composite(const ScreenCalibration& screen, const std::vector<std::optional<std::size_t>>& projector_of,
                         const std::filesystem::path& file) const;

    [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }

private:
    const HeadlessOutputBackend* backend_;
    std::filesystem::path dir_;
    int every_;
};

}  // namespace mogao
