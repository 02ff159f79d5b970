// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate camera-intrinsics` (camera_intrinsics_command.h).
#include "kiosk/calibrate/camera_intrinsics_command.h"

#include <cstdio>

#include "appliance/tracker/camera_intrinsics.h"
#include "appliance/tracker/chessboard_calibration.h"
#include "common/size_text.h"

namespace mogao::calibrate {

void add_camera_intrinsics_command(CLI::App& parent, CameraIntrinsicsCommand& cmd) {
    cmd.app = parent.add_subcommand("camera-intrinsics", "Camera intrinsics from chessboard photos in a folder");
    cmd.app->add_option("FOLDER", cmd.folder, "folder of chessboard images")->required()->check(CLI::ExistingDirectory);
    // The same texts as `procam`'s (one text per name, docs/cli.md).
    cmd.app->add_option("--board", cmd.board, "Chessboard inner corners, COLUMNSxROWS");
    cmd.app->add_option("--square-mm", cmd.square_mm, "Chessboard square side, mm")->check(CLI::Range(0.1, 1000.0));
    cmd.app->add_option("--out", cmd.out, "calibration file to write (.json)");
    cmd.app->parse_complete_callback([&cmd] {
        ImageSize board;
        if (!parse_size(cmd.board, board)) {
            throw CLI::ValidationError("--board", "'" + cmd.board + "' is not COLUMNSxROWS (e.g. 9x6)");
        }
    });
}

int run_camera_intrinsics_command(const CameraIntrinsicsCommand& cmd) {
    ImageSize board;
    (void)parse_size(cmd.board, board);  // checked during the parse
    CalibrationResult r;
    try {
        r = calibrate_chessboard(list_images(cmd.folder), {board.width, board.height, cmd.square_mm / 1000.0});
        for (const auto& reason : r.rejected) std::fprintf(stderr, "skipped %s\n", reason.c_str());
        const CameraIntrinsics& c = r.intrinsics;
        std::printf("%zu image(s) used, %zu skipped; RMS reprojection error %.3f px\n", r.used.size(),
                    r.rejected.size(), r.rms_px);
        std::printf("%dx%d  fx %.2f  fy %.2f  cx %.2f  cy %.2f  (OpenCV pixel convention)\n", c.width, c.height, c.fx,
                    c.fy, c.cx, c.cy);
        std::printf("distortion k1 k2 p1 p2 k3:");
        for (double k : c.distortion) std::printf(" %.5f", k);
        std::printf("\n");
        write_intrinsics(cmd.out, c, r.rms_px);
        std::printf("wrote %s\n", cmd.out.string().c_str());
        return 0;
    } catch (const std::exception& e) {  // CalibrationError, an unwritable --out
        std::fprintf(stderr, "mogao-calibrate camera-intrinsics: %s\n", e.what());
        return 1;
    }
}

}  // namespace mogao::calibrate
