// SPDX-License-Identifier: Apache-2.0
// The kiosk's start-up steps, in pipeline order (kiosk/main.cpp): configuration -> calibration ->
// outputs -> link -> navigation. Each returns its part, logging what it found, or throws
// KioskSetupError with the exit code and the message mogao-kiosk logs (docs/kiosk.md): 2 for a bad
// configuration, 1 when the appliance cannot run (outputs, calibration, link set-up, files).
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/projector_calibration.h"
#include "drivers/output.h"
#include "kiosk/config/kiosk_config.h"
#include "kiosk/config/last_loaded.h"
#include "kiosk/display/content_dump.h"
#include "kiosk/display/kiosk_display.h"
#include "kiosk/live_calibration/calibration_inbox.h"
#include "kiosk/live_calibration/calibration_watcher.h"
#include "kiosk/loop/frame_inbox.h"
#include "kiosk/navigation/kiosk_navigation.h"
#include "kiosk/navigation/pose_log.h"
#include "kiosk/navigation/view_script.h"
#include "renderfarm/link/link_client.h"
#include "renderfarm/link/tls_material.h"

namespace mogao {

class HeadlessOutputBackend;

struct KioskSetupError : std::runtime_error {
    KioskSetupError(int code, const std::string& message) : std::runtime_error(message), exit_code(code) {}
    int exit_code;
};

// A checked configuration: the file with the command line's overrides, its TLS files, and the
// scripted visitor's path (empty with tracking).
struct KioskSetup {
    KioskConfig config;
    TlsMaterial tls;
    std::optional<ViewScript> script;
    std::vector<StartFallback> fallbacks;  // the configuration came from its last good copy
};

// --path (non-empty: the scripted visitor on that path) and --stats (non-empty) override the file.
// With `fall_back` (not for --check-config): a file that loads is kept as its last good copy
// (kiosk/config/last_loaded.h); a bad file with such a copy runs on the copy, noted in `fallbacks`.
[[nodiscard]] KioskSetup load_setup(const std::filesystem::path& file, const std::string& path,
                                    const std::filesystem::path& stats_file, bool fall_back = false);

// MPCDI or ideal calibration ([calibration]); notes logged. With `fallbacks` (non-null): an MPCDI
// file that loads is kept as its last good copy; a bad one with such a copy loads the copy, noted
// there. Throws KioskSetupError(1) otherwise.
[[nodiscard]] ScreenCalibration load_calibration(const KioskConfig& config,
                                                 std::vector<StartFallback>* fallbacks = nullptr);

// The run-time calibration swap's inbox, and the watcher of [calibration]'s MPCDI file feeding it
// (nullptr: source = "ideal" or watch = false). The watcher must be destroyed before the inbox.
[[nodiscard]] std::unique_ptr<CalibrationInbox> open_calibration_inbox();
[[nodiscard]] std::unique_ptr<CalibrationWatcher> watch_calibration(const KioskConfig& config, CalibrationInbox& inbox);

// The [outputs] backend: headless (sizes from [outputs].sizes, else `screen`'s projectors; its
// backend in *headless for PNG recording) or KMS. Throws KioskSetupError(1) naming the failure.
[[nodiscard]] std::unique_ptr<OutputBackend> open_output_backend(const OutputsConfig& outputs,
                                                                 const ScreenCalibration& screen,
                                                                 HeadlessOutputBackend** headless);

// The [outputs] backend (headless or KMS) showing `screen`, each output logged; headless PNGs when
// png_dir is set. Then the connecting screen on every output.
[[nodiscard]] KioskDisplay open_display(const KioskConfig& config, ScreenCalibration screen);

// --dump-content DIR (empty: none).
[[nodiscard]] std::optional<ContentDump> open_content_dump(const std::filesystem::path& dir, int every);

// The loop's wake-up and frame slot.
[[nodiscard]] std::unique_ptr<FrameInbox> open_inbox();

// The link to [farm], delivering into `inbox`; logs what the kiosk asks the farm for (`script`: the
// scripted visitor, if that is the navigation).
[[nodiscard]] std::unique_ptr<LinkClient> open_link(const KioskConfig& config, TlsMaterial tls, FrameInbox& inbox,
                                                    const std::optional<ViewScript>& script);

// --pose-log FILE (empty: none).
[[nodiscard]] std::optional<PoseLog> open_pose_log(const std::filesystem::path& file);

// The request every view is filled into: [screen] and [quality] (make_view_template).
[[nodiscard]] ViewRequest view_template(const KioskConfig& config);

// The scripted visitor of [navigation] (make_view_script with view_template). Throws PathError.
[[nodiscard]] ViewScript scripted_visitor(const KioskConfig& config);

// The scripted visitor (`script`) or, with tracking, the Navigator and tracking thread.
[[nodiscard]] std::unique_ptr<KioskNavigation> start_navigation(const KioskConfig& config,
                                                                std::optional<ViewScript> script);

}  // namespace mogao
