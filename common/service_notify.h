// SPDX-License-Identifier: Apache-2.0
// systemd service notification (sd_notify: READY=1, WATCHDOG=1, STOPPING=1) for Type=notify units
// with WatchdogSec=. Without libsystemd at build time, or outside systemd ($NOTIFY_SOCKET unset),
// every call does nothing. A process started by the service's main process (a rank under mpirun in
// mogao-farm.service, NotifyAccess=all) pets the watchdog too.
#pragma once

#include <chrono>
#include <cstdint>

namespace mogao {

class ServiceNotifier {
public:
    ServiceNotifier();
    void ready();
    void stopping();
    // Pets the watchdog at half its period; cheap to call often.
    void watchdog();

private:
    std::uint64_t watchdog_usec_ = 0;
    std::chrono::steady_clock::time_point last_{};
};

}  // namespace mogao
