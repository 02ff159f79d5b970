// SPDX-License-Identifier: Apache-2.0
// The kiosk's simulated screen camera for self-recalibration ([selfcal].camera = "rig:<rig.toml>"):
// the virtual rig's camera (appliance/rig CameraSimulator) filming what the wall's calibration makes
// the rig file's TRUE (possibly bumped) projectors show, at the models' resolutions (scaled_rig).
// Tests and demos only: it measures nothing on a real wall, and the appliance's mogao-kiosk does not
// link it (mogao-kiosk-sim does). Errors: KioskSetupError(1, "selfcal: [selfcal].camera: ...")
// naming the rig file (unreadable, another projector count than the models, a camera that does not
// scale to the models').
#include "kiosk/live_calibration/selfcal_setup.h"

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "appliance/autocal/rig_bridge.h"
#include "appliance/rig/rig_file.h"
#include "appliance/selfcal/rig_simulation.h"
#include "kiosk/loop/kiosk_setup.h"

namespace mogao {
namespace {

[[noreturn]] void refuse(const std::string& message) { throw KioskSetupError(1, "selfcal: " + message); }

// A SIMULATED screen camera: the rig file's camera seeing what the wall's calibration makes the rig
// file's (true, possibly bumped) projectors show, at the models' resolutions.
SelfcalWorker::Camera rig_camera(const SelfcalConfig& sc, const selfcal::SystemModel& model) {
    rig::VirtualRig rig;
    try {
        rig = rig::load_rig(sc.rig);
    } catch (const std::exception& e) {
        refuse(fmt::format("[selfcal].camera: {}", e.what()));
    }
    if (rig.projectors.size() != model.projectors.size()) {
        refuse(fmt::format("[selfcal].camera: rig '{}' has {} projectors, the models {}", sc.rig.string(),
                           rig.projectors.size(), model.projectors.size()));
    }
    const double projector_scale =
        static_cast<double>(model.projectors[0].resolution.width) / rig.projectors[0].resolution.width;
    const double camera_scale = static_cast<double>(model.camera.resolution.width) / rig.camera.resolution.width;
    rig = autocal::scaled_rig(rig, std::min(projector_scale, 1.0), std::min(camera_scale, 1.0));
    if (rig.camera.resolution.width != model.camera.resolution.width ||
        rig.camera.resolution.height != model.camera.resolution.height) {
        refuse(fmt::format("[selfcal].camera: rig '{}' camera {}x{} does not scale to the models' {}x{}",
                           sc.rig.string(), rig.camera.resolution.width, rig.camera.resolution.height,
                           model.camera.resolution.width, model.camera.resolution.height));
    }
    spdlog::warn("selfcal: the screen camera is SIMULATED from the virtual rig {} (tests and demos only)",
                 sc.rig.string());
    auto sim = std::make_shared<rig::CameraSimulator>(rig);
    return [sim](const cv::Mat1f& content, const ScreenCalibration& wall, std::uint64_t frame) {
        std::vector<cv::Mat> signals;
        for (const ProjectorCalibration& pc : wall.projectors) {
            signals.emplace_back(selfcal::projector_signal(pc, content));
        }
        return sim->capture(signals, frame + 1);
    };
}

}  // namespace

SimulatedScreenCamera built_in_simulated_camera() { return rig_camera; }

}  // namespace mogao
