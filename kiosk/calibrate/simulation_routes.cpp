// SPDX-License-Identifier: Apache-2.0
// mogao-calibrate-sim's simulation routes (simulation_routes.h): the virtual rig's calibration job, its
// self-recalibration scenarios and its camera.
#include "kiosk/calibrate/simulation_routes.h"

#include <cerrno>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "appliance/autocal/rig_bridge.h"
#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/rig/rig_file.h"
#include "drivers/headless/headless_output.h"
#include "drivers/kms/kms_backend.h"
#include "kiosk/calibrate/rig_camera.h"
#include "kiosk/calibrate/rig_command.h"
#include "kiosk/calibrate/selfcal_command.h"

namespace mogao::calibrate {

bool has_simulation_routes() { return true; }

const char* program_name() { return "mogao-calibrate-sim"; }

struct SimulationCommands {
    RigCommand rig;
    SelfcalCommand selfcal;
};

std::shared_ptr<SimulationCommands> add_simulation_commands(CLI::App& app) {
    auto cmds = std::make_shared<SimulationCommands>();
    add_rig_command(app, cmds->rig);
    add_selfcal_command(app, cmds->selfcal);
    return cmds;
}

std::optional<int> run_simulation_commands(const SimulationCommands& cmds) {
    if (cmds.rig.app->parsed()) return run_rig_command(cmds.rig);
    if (cmds.selfcal.app->parsed()) return run_selfcal_command(cmds.selfcal);
    return std::nullopt;
}

// The rig's projector k is lit by output k (the outputs' order; identification still finds it from
// the images). On KMS the rig films the kernel's scanout buffers, read back after each flip.
std::unique_ptr<CalibrationCamera> open_rig_camera(const std::filesystem::path& rig_file, double scale,
                                                   OutputBackend& outputs) {
    const rig::VirtualRig rig = autocal::scaled_rig(rig::load_rig(rig_file), scale, scale);
    std::vector<std::size_t> order(rig.projectors.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    if (auto* headless = dynamic_cast<HeadlessOutputBackend*>(&outputs)) {
        return std::make_unique<RigCamera>(*headless, rig, order);
    }
    auto* kms = dynamic_cast<KmsOutputBackend*>(&outputs);
    if (kms == nullptr) throw std::invalid_argument("--camera rig:FILE films headless or KMS outputs only");
    // A plane with no framebuffer yet shows black (RigCamera's empty image), not an error.
    return std::make_unique<RigCamera>(
        [kms](std::size_t i) -> Result<Rgb8Image> {
            auto shown = kms->read_scanout(i);
            if (!shown && shown.code() == ENODATA) return Rgb8Image{};
            return shown;
        },
        "the KMS scanout buffers of " + kms->device_path().string(), rig, order);
}

void print_simulation_truth(const std::filesystem::path& rig_file, double scale, const std::filesystem::path& mpcdi) {
    const rig::VirtualRig rig = autocal::scaled_rig(rig::load_rig(rig_file), scale, scale);
    const ScreenCalibration c = to_screen_calibration(read_mpcdi(mpcdi));
    const autocal::GeometryError g = autocal::measure_geometry(rig, c, 4);
    std::printf("SIMULATION ground truth (rig %s): geometry mean %.3f p95 %.3f px\n", rig.name.c_str(), g.mean_px,
                g.p95_px);
}

}  // namespace mogao::calibrate
