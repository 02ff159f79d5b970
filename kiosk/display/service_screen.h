// SPDX-License-Identifier: Apache-2.0
// The service card: what the kiosk shows when it cannot start its show -- the configuration (or
// the calibration) neither loads nor has a last good copy, e.g. a missing, unmounted or corrupt
// configuration partition (the image mounts it `nofail`, so the box boots on instead of dropping
// into emergency mode). Instead of exiting into a restart loop behind dark projectors, every
// output shows "SERVICE NEEDED" with the reason (the file and what is wrong with it), the service
// tells systemd it is ready and feeds the watchdog, and the configuration is tried again every
// `retry` seconds: once it loads, the kiosk exits 1 for systemd to start the show
// (Restart=on-failure). SIGTERM/SIGINT end it with 0.
//
// Outputs: the fallback configuration's [outputs] (--service-config FILE; default the built-in
// kiosk.example.toml: KMS on the first card with a connected output). Each output shows the whole
// card: one projector per output size, the card's content stretched over that output alone (no
// calibration is needed to read a message).
#pragma once

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>

#include "common/signal_fd.h"
#include "kiosk/config/kiosk_config.h"

namespace mogao {

struct ServiceScreenOptions {
    std::filesystem::path config;   // the configuration the kiosk could not load (tried again)
    std::string reason;             // what went wrong, shown on the card and logged
    OutputsConfig outputs;          // where to show it
    std::chrono::seconds retry{5};  // how often the configuration is tried again
    double duration_s = 0;          // stop after this long (tests; 0 = never)
};

// Returns the process exit code: 0 on SIGTERM/SIGINT or `duration_s`, 1 once the configuration
// loads again; nullopt when the outputs cannot show the card (logged; the caller keeps its code).
[[nodiscard]] std::optional<int> run_service_screen(const ServiceScreenOptions& options, const SignalFd& signals);

// The [outputs] section the service card uses: that of `file`, or the built-in defaults when
// `file` is empty. Throws KioskConfigError naming the file and field.
[[nodiscard]] OutputsConfig service_outputs(const std::filesystem::path& file);

}  // namespace mogao
