// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate camera-intrinsics`: the camera's intrinsics from chessboard photos in a folder (OpenCV's
// chessboard calibration, appliance/tracker/chessboard_calibration.h; docs/tracking.md), written as the JSON file
// the site file's [camera] and the kiosk's [tracking] camera take.
//
//   mogao-calibrate camera-intrinsics FOLDER [--board 9x6] [--square-mm 25] [--out camera.json]
#pragma once

#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

namespace mogao::calibrate {

struct CameraIntrinsicsCommand {
    CLI::App* app = nullptr;
    std::filesystem::path folder;
    std::string board = "9x6";  // inner corners, COLUMNSxROWS
    double square_mm = 25.0;
    std::filesystem::path out = "camera.json";
};

// Adds the subcommand and its options to `parent`; a malformed --board is a usage error (CLI::ValidationError
// during the parse).
void add_camera_intrinsics_command(CLI::App& parent, CameraIntrinsicsCommand& cmd);

// Runs a parsed subcommand: 0 written, 1 the job failed (no board found, an unreadable image: the message names it).
[[nodiscard]] int run_camera_intrinsics_command(const CameraIntrinsicsCommand& cmd);

}  // namespace mogao::calibrate
