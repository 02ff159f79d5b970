// SPDX-License-Identifier: Apache-2.0
// A SIMULATION of the camera on site: the virtual rig's camera (appliance/rig CameraSimulator)
// filming what the headless outputs (drivers/headless) show, through the rig's TRUE projectors.
// What each output last presented (RGB8, read back by the backend) is projector k's signal, code /
// 255; the rig forms the camera image (its projectors' responses, black levels, lens falloff,
// ambient light, noise, blur, 8-bit quantisation) and the frame carries it as 8-bit codes of the
// rig's linear camera (use CameraTransfer::linear), luma and colour alike.
//
// It lets the whole on-site path -- patterns through the output backend and the renderer, frames
// through CameraFrame, settling, progress, connector identification, refusals -- run where no
// projector and no camera exist (tests, `mogao-calibrate --outputs headless --camera rig:FILE`).
// The one part it cannot stand in for is a real camera looking at a real screen.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "appliance/rig/virtual_rig.h"
#include "drivers/headless/headless_output.h"
#include "kiosk/calibrate/calibration_camera.h"

namespace mogao::calibrate {

class RigCamera final : public CalibrationCamera {
public:
    // Rig projector k is lit by output projector_output[k] of `outputs` (whose size must be the
    // projector's resolution: std::invalid_argument otherwise, when filming). `outputs` must outlive it.
    RigCamera(const HeadlessOutputBackend& outputs, const rig::VirtualRig& rig,
              std::vector<std::size_t> projector_output);

    [[nodiscard]] Result<CameraFrame> next_frame() override;
    [[nodiscard]] bool exposure_locked() const override { return !sim_.rig().camera.auto_exposure; }
    [[nodiscard]] Status set_relative_exposure(double factor) override;
    [[nodiscard]] std::string description() const override;

    [[nodiscard]] std::uint64_t frames() const { return frame_; }

private:
    const HeadlessOutputBackend* outputs_;
    rig::CameraSimulator sim_;
    std::vector<std::size_t> projector_output_;
    double base_exposure_;
    std::uint64_t frame_ = 0;
};

}  // namespace mogao::calibrate
