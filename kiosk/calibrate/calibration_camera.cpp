// SPDX-License-Identifier: Apache-2.0
// The calibration camera: locked controls, relative exposure, linear camera images (calibration_camera.h).
#include "kiosk/calibrate/calibration_camera.h"

#include <array>
#include <cmath>

#include "drivers/camera/v4l2_capture.h"

namespace mogao::calibrate {
namespace {

class LiveCamera final : public CalibrationCamera {
public:
    LiveCamera(std::unique_ptr<FrameSource> source, bool recording, std::optional<double> base_exposure_us,
               CameraControls controls)
        : source_(std::move(source)),
          recording_(recording),
          base_exposure_us_(base_exposure_us),
          controls_(std::move(controls)) {}
    Result<CameraFrame> next_frame() override { return source_->next_frame(); }
    bool exposure_locked() const override { return true; }  // opened with it required (or a recording)
    Status set_relative_exposure(double factor) override {
        auto* v4l2 = dynamic_cast<V4l2Capture*>(source_.get());
        if (recording_ || v4l2 == nullptr || !base_exposure_us_) {
            return make_error(ENOTSUP, source_->description() + ": cannot change the exposure while capturing");
        }
        CameraControls c;
        c.exposure = {ControlSetting::Mode::manual, *base_exposure_us_ * factor, true, controls_.exposure.name};
        return v4l2->apply_controls(c);
    }
    std::string description() const override { return source_->description(); }

private:
    std::unique_ptr<FrameSource> source_;
    bool recording_;
    std::optional<double> base_exposure_us_;
    CameraControls controls_;
};

ControlSetting locked(ControlSetting s, bool required_always) {
    if (s.mode != ControlSetting::Mode::manual) s.mode = ControlSetting::Mode::lock;
    s.required = required_always || s.mode == ControlSetting::Mode::manual;
    return s;
}

std::array<float, 256> decode_table(CameraTransfer transfer) {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
        const double v = i / 255.0;
        const double l = transfer == CameraTransfer::linear ? v
                         : v <= 0.04045                     ? v / 12.92
                                                            : std::pow((v + 0.055) / 1.055, 2.4);
        t[static_cast<std::size_t>(i)] = static_cast<float>(l);
    }
    return t;
}

}  // namespace

CameraControls locked_controls(const CameraControls& requested) {
    CameraControls c;
    c.exposure = locked(requested.exposure, true);
    c.gain = locked(requested.gain, false);
    c.white_balance = locked(requested.white_balance, false);
    return c;
}

Result<std::unique_ptr<CalibrationCamera>> open_calibration_camera(CameraSourceSpec spec) {
    const bool recording = spec.kind == CameraSourceSpec::Kind::replay;
    if (!recording) spec.controls = locked_controls(spec.controls);
    auto source = open_camera_source(spec);
    if (!source) return with_context(source.error(), "calibration camera (exposure, gain, white balance locked)");
    std::optional<double> base;
    if (auto* v4l2 = dynamic_cast<V4l2Capture*>(source.value().get())) base = v4l2->control_values().exposure_us;
    return std::unique_ptr<CalibrationCamera>(
        std::make_unique<LiveCamera>(std::move(source.value()), recording, base, spec.controls));
}

cv::Mat1f camera_image(const CameraFrame& frame, CameraTransfer transfer) {
    static const std::array<float, 256> srgb = decode_table(CameraTransfer::srgb);
    static const std::array<float, 256> linear = decode_table(CameraTransfer::linear);
    const std::array<float, 256>& t = transfer == CameraTransfer::srgb ? srgb : linear;
    const GrayImage& g = frame.image;
    cv::Mat1f out(g.height, g.width);
    if (frame.colour && frame.colour->size.width == g.width && frame.colour->size.height == g.height) {
        const std::uint8_t* p = frame.colour->pixels.data();
        for (int y = 0; y < g.height; ++y) {
            for (int x = 0; x < g.width; ++x, p += 3) out(y, x) = (t[p[0]] + t[p[1]] + t[p[2]]) / 3.0f;
        }
        return out;
    }
    for (int y = 0; y < g.height; ++y) {
        for (int x = 0; x < g.width; ++x) out(y, x) = t[g.at(x, y)];
    }
    return out;
}

}  // namespace mogao::calibrate
