// SPDX-License-Identifier: Apache-2.0
// mogao-track calibrate-camera: OpenCV chessboard calibration of a folder of photos.
#include <cstdio>

#include "appliance/tools/track_commands.h"
#include "appliance/tracker/chessboard_calibration.h"

namespace mogao::track {

int calibrate_camera(const CalibrateOptions& o) {
    CalibrationResult r;
    try {
        r = calibrate_chessboard(list_images(o.folder), {o.inner_columns, o.inner_rows, o.square_mm / 1000.0});
    } catch (const CalibrationError& e) {
        std::fprintf(stderr, "mogao-track calibrate-camera: %s\n", e.what());
        return 1;
    }
    for (const auto& reason : r.rejected) std::fprintf(stderr, "skipped %s\n", reason.c_str());
    const CameraIntrinsics& c = r.intrinsics;
    std::printf("%zu image(s) used, %zu skipped; RMS reprojection error %.3f px\n", r.used.size(), r.rejected.size(),
                r.rms_px);
    std::printf("%dx%d  fx %.2f  fy %.2f  cx %.2f  cy %.2f  (OpenCV pixel convention)\n", c.width, c.height, c.fx, c.fy,
                c.cx, c.cy);
    std::printf("distortion k1 k2 p1 p2 k3:");
    for (double k : c.distortion) std::printf(" %.5f", k);
    std::printf("\n");
    write_intrinsics(o.out, c, r.rms_px);
    std::printf("wrote %s\n", o.out.string().c_str());
    return 0;
}

}  // namespace mogao::track
