// SPDX-License-Identifier: Apache-2.0
// The camera mogao-calibrate films the screen with: a live camera (drivers/camera: "v4l2:/dev/videoN",
// "libcamera:[id]"), a recording ("replay:<folder>") or, in tests and demos, the virtual rig filming
// the headless outputs (rig_camera.h).
//
// Locked controls: the Gray-code decoding compares images value by value and the colour step
// measures light, so a live camera is opened with exposure, gain and white balance fixed
// (drivers/camera/camera_controls.h): each setting the caller leaves at keep/auto becomes `lock`
// (the automatic loop stops at the value it reached), a manual value stays manual. Exposure is
// required (a camera without an exposure control is refused: it cannot be locked); gain and white
// balance are required only when given a manual value (many cameras lack them, and then have no
// automatic loop for them either). A recording's exposure cannot change: it counts as locked.
//
// Camera values: CameraFrame's 8-bit codes are the camera's encoded values. camera_image() turns
// them into the calibration's linear camera units: `srgb` decodes IEC 61966-2-1 (what webcams and
// most V4L2 cameras deliver; an assumption, as in kiosk/live_calibration/selfcal_setup.h), `linear` takes code / 255
// (raw sensors, the virtual rig). Colour frames (CameraFrame::colour) are averaged over R, G and B
// after decoding (autocal's camera is monochrome with a flat spectral response,
// appliance/autocal/colour_calibration.h); without colour the luma image is used.
#pragma once

#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "common/result.h"
#include "drivers/camera/camera_frame.h"
#include "drivers/camera/camera_source.h"

namespace mogao::calibrate {

enum class CameraTransfer { srgb, linear };

class CalibrationCamera {
public:
    virtual ~CalibrationCamera() = default;
    // The newest frame (a live camera drops older queued frames); errors as FrameSource.
    [[nodiscard]] virtual Result<CameraFrame> next_frame() = 0;
    // False while the camera meters every image itself.
    [[nodiscard]] virtual bool exposure_locked() const = 0;
    // Manual exposure `factor` x the one it was opened with (1 = back to it); ENOTSUP where the
    // camera cannot (a recording, libcamera 0.0.3 here), EINVAL outside the device's range.
    [[nodiscard]] virtual Status set_relative_exposure(double factor) = 0;
    [[nodiscard]] virtual std::string description() const = 0;
};

// The controls a live calibration camera is opened with (above), from what the caller asked for.
[[nodiscard]] CameraControls locked_controls(const CameraControls& requested);

// Opens `spec` (colour frames as spec.colour says) with locked_controls(spec.controls). Errors of
// open_camera_source; ENOTSUP/EINVAL naming the control when it cannot be locked or set.
[[nodiscard]] Result<std::unique_ptr<CalibrationCamera>> open_calibration_camera(CameraSourceSpec spec);

// The frame as linear camera values in [0, 1] (CV_32FC1), as described above.
[[nodiscard]] cv::Mat1f camera_image(const CameraFrame& frame, CameraTransfer transfer);

}  // namespace mogao::calibrate
