// SPDX-License-Identifier: Apache-2.0
#include "common/service_notify.h"

#ifdef MOGAO_HAVE_LIBSYSTEMD
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <cstdlib>
#include <exception>
#include <string>
#endif

namespace mogao {

#ifdef MOGAO_HAVE_LIBSYSTEMD
namespace {

// The watchdog period when this process's parent is the process WATCHDOG_PID names: mpirun in
// mogao-farm.service. systemd sets WATCHDOG_PID to the unit's main process (the launcher,
// systemd/mogao-farm-launch, which hands mpirun its own PID in its place), and mpirun passes its
// environment on to the ranks it starts; sd_watchdog_enabled() then tells the admin rank that the
// watchdog is not its business, no WATCHDOG=1 is sent, and systemd kills the farm after WatchdogSec.
// The rank's loop is what the watchdog is for, and NotifyAccess=all lets it ping.
std::uint64_t watchdog_usec_from_parent() {
    const char* pid = std::getenv("WATCHDOG_PID");
    const char* usec = std::getenv("WATCHDOG_USEC");
    if (pid == nullptr || usec == nullptr || std::getenv("NOTIFY_SOCKET") == nullptr) return 0;
    try {
        if (std::stol(pid) != static_cast<long>(getppid())) return 0;
        return std::stoull(usec);
    } catch (const std::exception&) {
        return 0;  // malformed: no watchdog, as sd_watchdog_enabled() would decide
    }
}

}  // namespace
#endif

ServiceNotifier::ServiceNotifier() {
#ifdef MOGAO_HAVE_LIBSYSTEMD
    std::uint64_t usec = 0;
    if (sd_watchdog_enabled(0, &usec) > 0) {
        watchdog_usec_ = usec;
    } else {
        watchdog_usec_ = watchdog_usec_from_parent();
    }
#endif
}

void ServiceNotifier::ready() {
#ifdef MOGAO_HAVE_LIBSYSTEMD
    sd_notify(0, "READY=1");
#endif
}

void ServiceNotifier::stopping() {
#ifdef MOGAO_HAVE_LIBSYSTEMD
    sd_notify(0, "STOPPING=1");
#endif
}

void ServiceNotifier::watchdog() {
    if (watchdog_usec_ == 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::microseconds(watchdog_usec_ / 2)) return;
    last_ = now;
#ifdef MOGAO_HAVE_LIBSYSTEMD
    sd_notify(0, "WATCHDOG=1");
#endif
}

}  // namespace mogao
