// SPDX-License-Identifier: Apache-2.0
// mogao-camera: what the cameras on this machine support, to choose the kiosk's camera keys.
//   mogao-camera list                          every V4L2 capture node (device, driver, card)
//   mogao-camera info v4l2:/dev/videoN|/dev/videoN   formats, sizes, frame rates, controls with ranges
//   mogao-camera info libcamera:[<id>]         the same through libcamera (every camera without an id)
// Exit codes (docs/architecture.md): 0 success, 1 the device could not be queried, 2 bad command line.
#include <CLI/CLI.hpp>

#include <iostream>
#include <string>

#include "common/program_cli.h"
#include "drivers/camera/camera_source.h"
#include "drivers/camera/libcamera_capture.h"
#include "drivers/camera/v4l2_info.h"

namespace {

int run_info(const std::string& camera) {
    std::string device = camera;
    if (!camera.starts_with("/")) {
        mogao::CameraSourceSpec spec;
        std::string why;
        if (!mogao::parse_camera_source(camera, spec, &why)) {
            std::cerr << "mogao-camera info: " << why << "\n";
            return 2;
        }
        if (spec.kind == mogao::CameraSourceSpec::Kind::libcamera) {
            auto text = mogao::describe_libcamera_cameras(spec.camera_id);
            if (!text) {
                std::cerr << "mogao-camera info: " << text.error().message << "\n";
                return 1;
            }
            std::cout << *text;
            return 0;
        }
        if (spec.kind != mogao::CameraSourceSpec::Kind::v4l2) {
            std::cerr << "mogao-camera info: '" << camera
                      << "': a replay folder has no formats or controls; give v4l2:/dev/videoN or libcamera:[<id>]\n";
            return 2;
        }
        device = spec.device;
    }
    auto info = mogao::query_v4l2_device(device);
    if (!info) {
        std::cerr << "mogao-camera info: " << info.error().message << "\n";
        return 1;
    }
    std::cout << mogao::format_v4l2_info(*info);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"mogao-camera: the cameras this machine has and what they support (formats, sizes, rates, controls)"};
    mogao::cli::prepare(app, "mogao-camera");
    app.require_subcommand(1);
    CLI::App* list = app.add_subcommand("list", "every V4L2 capture node: device, driver, card, bus");
    CLI::App* info =
        app.add_subcommand("info", "formats, sizes, frame rates and controls (ranges, values) of one camera");
    std::string camera;
    info->add_option("camera", camera, "v4l2:/dev/videoN, /dev/videoN or libcamera:[<id>]")->required();
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return mogao::cli::exit_status(app, e);  // --help is 0
    }
    if (list->parsed()) {
        const auto devices = mogao::list_v4l2_devices();
        if (devices.empty()) std::cout << "no V4L2 capture devices in /dev/video*\n";
        for (const auto& d : devices) {
            std::cout << "v4l2:" << d.device << "  " << d.driver << "  \"" << d.card << "\"  " << d.bus
                      << (d.multiplanar ? "  multi-planar" : "") << "\n";
        }
        return 0;
    }
    return run_info(camera);
}
