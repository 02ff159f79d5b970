// SPDX-License-Identifier: Apache-2.0
// autocal's PatternSource on the appliance's outputs and a camera (hardware_pattern_source.h).
#include "kiosk/calibrate/hardware_pattern_source.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <thread>

namespace mogao::calibrate {

HardwarePatternSource::HardwarePatternSource(PatternDisplay& display, CalibrationCamera& camera,
                                             std::vector<std::size_t> projector_output, ImageSize camera_size,
                                             CameraTransfer transfer, CaptureTiming timing, int expected,
                                             ProgressFn progress)
    : display_(&display),
      camera_(&camera),
      projector_output_(std::move(projector_output)),
      camera_size_(camera_size),
      transfer_(transfer),
      timing_(timing),
      expected_(expected),
      progress_(std::move(progress)),
      start_(std::chrono::steady_clock::now()) {}

cv::Mat1f HardwarePatternSource::show(const std::vector<cv::Mat>& signals) {
    if (signals.size() != projector_output_.size()) {
        throw std::invalid_argument("pattern source: " + std::to_string(signals.size()) + " patterns for " +
                                    std::to_string(projector_output_.size()) + " projectors");
    }
    std::vector<cv::Mat> per_output(display_->output_count());
    for (std::size_t k = 0; k < signals.size(); ++k) per_output.at(projector_output_[k]) = signals[k];
    return show_outputs(per_output);
}

cv::Mat1f HardwarePatternSource::show_outputs(const std::vector<cv::Mat>& per_output) {
    if (auto s = display_->show_outputs(per_output); !s) throw std::runtime_error(s.error().message);
    return capture();
}

cv::Mat1f HardwarePatternSource::capture() {
    if (timing_.settle_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(timing_.settle_ms));
    Result<CameraFrame> frame = make_error(EIO, "no frame");
    for (int i = 0; i <= timing_.drop_frames; ++i) {
        frame = camera_->next_frame();
        if (!frame) throw std::runtime_error("camera " + camera_->description() + ": " + frame.error().message);
    }
    const GrayImage& g = frame.value().image;
    if (g.width != camera_size_.width || g.height != camera_size_.height) {
        throw std::runtime_error("camera " + camera_->description() + ": delivers " + std::to_string(g.width) + "x" +
                                 std::to_string(g.height) + " frames, the calibration's camera is " +
                                 std::to_string(camera_size_.width) + "x" + std::to_string(camera_size_.height));
    }
    cv::Mat1f image = camera_image(frame.value(), transfer_);
    lossy_ = frame.value().format == CaptureFormat::mjpeg;
    ++done_;
    if (progress_) {
        CaptureProgress p;
        p.done = done_;
        p.expected = std::max(expected_, done_);
        p.seconds_per_image = seconds() / done_;
        p.seconds_left = (p.expected - done_) * p.seconds_per_image;
        progress_(p);
    }
    return image;
}

void HardwarePatternSource::set_relative_exposure(double factor) {
    if (auto s = camera_->set_relative_exposure(factor); !s) {
        throw autocal::CalibrationRefused("camera " + camera_->description() + ": the colour step needs exposure x" +
                                          std::to_string(factor) + " (black levels, the ramps' low end): " +
                                          s.error().message + " (calibrate the geometry alone with --no-colour)");
    }
}

double HardwarePatternSource::seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

}  // namespace mogao::calibrate
