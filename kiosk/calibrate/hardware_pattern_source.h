// SPDX-License-Identifier: Apache-2.0
// HardwarePatternSource: autocal's PatternSource (appliance/autocal/autocal.h) on the appliance's
// outputs and a camera: show() puts each projector's pattern on its output (PatternDisplay, every
// output in one round, returning once the flips completed), waits `settle_ms` (the projector's own
// processing and the panel's response), drops `drop_frames` camera frames (their exposure may have
// begun before the flip), takes the next one and returns it as linear camera values
// (camera_image). It counts the images and reports progress after each one: images done of the
// expected total (pattern_budget.h), seconds per image measured so far and the time left.
//
// Errors: show() throws std::runtime_error naming the output or the camera (a failed flip or
// capture, a frame of another size than the calibration's camera: its intrinsics would not hold);
// set_relative_exposure throws autocal::CalibrationRefused when the camera cannot change exposure
// (the colour step needs it; run without it: --no-colour).
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <vector>

#include "appliance/autocal/autocal.h"
#include "kiosk/calibrate/calibration_camera.h"
#include "kiosk/calibrate/pattern_display.h"

namespace mogao::calibrate {

struct CaptureTiming {
    int settle_ms = 150;  // after the flip, before the frames count, [0, 10000]
    int drop_frames = 2;  // camera frames dropped after the settle, [0, 30]
};

struct CaptureProgress {
    int done = 0;                    // images captured so far
    int expected = 0;                // the budget (at least `done`)
    double seconds_per_image = 0.0;  // measured mean
    double seconds_left = 0.0;       // (expected - done) x seconds_per_image
};

using ProgressFn = std::function<void(const CaptureProgress&)>;

class HardwarePatternSource final : public autocal::PatternSource {
public:
    // `display` and `camera` must outlive the source. Projector k of the calibration is shown on
    // output projector_output[k]; the camera must deliver `camera_size` frames.
    HardwarePatternSource(PatternDisplay& display, CalibrationCamera& camera, std::vector<std::size_t> projector_output,
                          ImageSize camera_size, CameraTransfer transfer, CaptureTiming timing, int expected,
                          ProgressFn progress);

    [[nodiscard]] cv::Mat1f show(const std::vector<cv::Mat>& signals) override;
    [[nodiscard]] bool exposure_locked() const override { return camera_->exposure_locked(); }
    void set_relative_exposure(double factor) override;
    // The last frame's wire format was Motion-JPEG.
    [[nodiscard]] bool lossy_frames() const override { return lossy_; }

    // One image of what `per_output[i]` on output i looks like (identification: outputs by index).
    [[nodiscard]] cv::Mat1f show_outputs(const std::vector<cv::Mat>& per_output);
    void set_projector_output(std::vector<std::size_t> projector_output) {
        projector_output_ = std::move(projector_output);
    }
    [[nodiscard]] const std::vector<std::size_t>& projector_output() const { return projector_output_; }
    [[nodiscard]] int images() const { return done_; }
    [[nodiscard]] double seconds() const;

private:
    [[nodiscard]] cv::Mat1f capture();

    PatternDisplay* display_;
    CalibrationCamera* camera_;
    std::vector<std::size_t> projector_output_;
    ImageSize camera_size_;
    CameraTransfer transfer_;
    CaptureTiming timing_;
    int expected_;
    ProgressFn progress_;
    int done_ = 0;
    bool lossy_ = false;
    std::chrono::steady_clock::time_point start_;
};

}  // namespace mogao::calibrate
