#include "renderfarm/farm/service_notify.h"

#ifdef MOGAO_HAVE_LIBSYSTEMD
#include <systemd/sd-daemon.h>
#endif

namespace mogao {

ServiceNotifier::ServiceNotifier() {
#ifdef MOGAO_HAVE_LIBSYSTEMD
    std::uint64_t usec = 0;
    if (sd_watchdog_enabled(0, &usec) > 0) watchdog_usec_ = usec;
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
