// SPDX-License-Identifier: Apache-2.0
#include "kiosk/live_calibration/calibration_inbox.h"

#include <spdlog/spdlog.h>

namespace mogao {

Result<std::unique_ptr<CalibrationInbox>> CalibrationInbox::create() {
    auto wake = EventFd::create();
    if (!wake) return with_context(wake.error(), "calibration inbox");
    return std::unique_ptr<CalibrationInbox>(new CalibrationInbox(std::move(wake).value()));
}

void CalibrationInbox::put(CalibrationUpdate update) {
    {
        const std::lock_guard lock(mutex_);
        slot_ = std::move(update);
        ++updates_;
    }
    if (Status s = wake_.signal(); !s) spdlog::error("calibration inbox: wake-up: {}", s.error().message);
}

std::optional<CalibrationUpdate> CalibrationInbox::take() {
    if (auto drained = wake_.drain(); !drained) spdlog::error("calibration inbox: {}", drained.error().message);
    const std::lock_guard lock(mutex_);
    std::optional<CalibrationUpdate> out = std::move(slot_);
    slot_.reset();
    return out;
}

std::uint64_t CalibrationInbox::updates() const {
    const std::lock_guard lock(mutex_);
    return updates_;
}

}  // namespace mogao
