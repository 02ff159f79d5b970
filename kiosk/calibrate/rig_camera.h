// SPDX-License-Identifier: Apache-2.0
// A SIMULATION of the camera on site: the virtual rig's camera (appliance/rig CameraSimulator)
// filming what the outputs show, through the rig's TRUE projectors. What an output shows (RGB8,
// read back: the headless backend's read-back of its last present, or on KMS the kernel's scanout
// buffer, drivers/kms/scanout_reader.h) is projector k's signal, code / 255; the rig forms the camera
// image (its projectors' responses, black levels, lens falloff, ambient light, noise, blur, 8-bit
// quantisation) and the frame carries it as 8-bit codes of the rig's linear camera (use
// CameraTransfer::linear), luma and colour alike.
//
// It lets the whole on-site path -- patterns through the output backend and the renderer (on KMS
// through real page flips), frames through CameraFrame, settling, progress, connector
// identification, refusals -- run where no projector and no camera exist (tests, the appliance
// image's QEMU test, `mogao-calibrate --outputs headless|kms --camera rig:FILE`). The one part it
// cannot stand in for is a real camera looking at a real screen.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "appliance/rig/virtual_rig.h"
#include "common/image.h"
#include "common/result.h"
#include "drivers/headless/headless_output.h"
#include "kiosk/calibrate/calibration_camera.h"

namespace mogao::calibrate {

// What output `i` shows now (RGB8, the output's size); an empty image = nothing shown yet (black).
using ShownImage = std::function<Result<Rgb8Image>(std::size_t output)>;

class RigCamera final : public CalibrationCamera {
public:
    // Rig projector k is lit by output projector_output[k], as `shown` reads it back (whose size must
    // be the projector's resolution: an EINVAL frame error otherwise). `source` names it in
    // description() ("the headless outputs", "the KMS scanout buffers").
    RigCamera(ShownImage shown, std::string source, const rig::VirtualRig& rig,
              std::vector<std::size_t> projector_output);
    // The headless outputs' last presented frames; `outputs` must outlive it.
    RigCamera(const HeadlessOutputBackend& outputs, const rig::VirtualRig& rig,
              std::vector<std::size_t> projector_output);

    [[nodiscard]] Result<CameraFrame> next_frame() override;
    [[nodiscard]] bool exposure_locked() const override { return !sim_.rig().camera.auto_exposure; }
    [[nodiscard]] Status set_relative_exposure(double factor) override;
    [[nodiscard]] std::string description() const override;

    [[nodiscard]] std::uint64_t frames() const { return frame_; }

private:
    ShownImage shown_;
    std::string source_;
    rig::CameraSimulator sim_;
    std::vector<std::size_t> projector_output_;
    double base_exposure_;
    std::uint64_t frame_ = 0;
};

}  // namespace mogao::calibrate
