// SPDX-License-Identifier: Apache-2.0
// The virtual rig's camera filming what the outputs show (rig_camera.h).
#include "kiosk/calibrate/rig_camera.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace mogao::calibrate {
namespace {

// An output's frame as the rig projector's signal, code / 255: CV_32FC1 when every pixel is grey
// (the Gray code and identification patterns; the rig forms those images for one channel, not three).
cv::Mat signal_of(const Rgb8Image& shown) {
    const std::uint8_t* p = shown.pixels.data();
    bool grey = true;
    for (std::size_t i = 0; i + 2 < shown.pixels.size() && grey; i += 3) grey = p[i] == p[i + 1] && p[i] == p[i + 2];
    if (grey) {
        cv::Mat1f s(shown.size.height, shown.size.width);
        for (int y = 0; y < s.rows; ++y) {
            for (int x = 0; x < s.cols; ++x, p += 3) s(y, x) = p[0] / 255.0f;
        }
        return s;
    }
    cv::Mat3f s(shown.size.height, shown.size.width);
    for (int y = 0; y < s.rows; ++y) {
        for (int x = 0; x < s.cols; ++x, p += 3) s(y, x) = cv::Vec3f(p[0], p[1], p[2]) / 255.0f;
    }
    return s;
}

}  // namespace

RigCamera::RigCamera(ShownImage shown, std::string source, const rig::VirtualRig& rig,
                     std::vector<std::size_t> projector_output)
    : shown_(std::move(shown)),
      source_(std::move(source)),
      sim_(rig),
      projector_output_(std::move(projector_output)),
      base_exposure_(rig.camera.exposure) {
    if (projector_output_.size() != rig.projectors.size()) {
        throw std::invalid_argument("rig camera: " + std::to_string(projector_output_.size()) + " outputs for " +
                                    std::to_string(rig.projectors.size()) + " rig projectors");
    }
}

RigCamera::RigCamera(const HeadlessOutputBackend& outputs, const rig::VirtualRig& rig,
                     std::vector<std::size_t> projector_output)
    : RigCamera([&outputs](std::size_t i) -> Result<Rgb8Image> { return outputs.last_frame(i); },
                "the headless outputs", rig, std::move(projector_output)) {}

Result<CameraFrame> RigCamera::next_frame() {
    std::vector<cv::Mat> signals(projector_output_.size());
    for (std::size_t k = 0; k < signals.size(); ++k) {
        auto shown = shown_(projector_output_[k]);
        if (!shown) {
            const std::string what = "rig camera: reading back what output " + std::to_string(projector_output_[k]);
            return with_context(shown.error(), what + " shows");
        }
        if (shown.value().pixels.empty()) continue;  // nothing presented yet: the projector shows black
        signals[k] = signal_of(shown.value());
    }
    cv::Mat1f image;
    try {
        image = sim_.capture(signals, frame_);
    } catch (const std::invalid_argument& e) {
        return make_error(EINVAL, std::string("rig camera: ") + e.what());
    }
    CameraFrame frame;
    frame.image = GrayImage(image.cols, image.rows);
    Rgb8Image colour;
    colour.size = {image.cols, image.rows};
    colour.pixels.resize(frame.image.pixels.size() * 3);
    for (int y = 0; y < image.rows; ++y) {
        for (int x = 0; x < image.cols; ++x) {
            const auto i =
                static_cast<std::size_t>(y) * static_cast<std::size_t>(image.cols) + static_cast<std::size_t>(x);
            const auto code = static_cast<std::uint8_t>(std::lround(255.0f * std::clamp(image(y, x), 0.0f, 1.0f)));
            frame.image.pixels[i] = code;
            colour.pixels[3 * i] = colour.pixels[3 * i + 1] = colour.pixels[3 * i + 2] = code;
        }
    }
    frame.colour = std::move(colour);
    // A Motion-JPEG camera's frames (the rig camera's mjpeg_quality) were decoded from that codec.
    frame.format = sim_.rig().camera.mjpeg_quality > 0 ? CaptureFormat::mjpeg : CaptureFormat::grey;
    frame.sequence = frame_;
    frame.timestamp_ns = static_cast<std::int64_t>(frame_) * 33'333'333;
    ++frame_;
    return frame;
}

Status RigCamera::set_relative_exposure(double factor) {
    try {
        sim_.set_exposure(base_exposure_ * factor);
    } catch (const std::invalid_argument& e) {
        return make_error(EINVAL, std::string("rig camera: ") + e.what());
    }
    return {};
}

std::string RigCamera::description() const {
    const rig::RigCamera& c = sim_.rig().camera;
    return "rig:" + sim_.rig().name + " (SIMULATION: the virtual rig's camera filming " + source_ + ", " +
           std::to_string(c.resolution.width) + "x" + std::to_string(c.resolution.height) + ")";
}

}  // namespace mogao::calibrate
