// SPDX-License-Identifier: Apache-2.0
// CalibrationInbox: where new projector calibrations reach the kiosk's event loop at run time
// (docs/kiosk.md, "Calibration swap"). Producers on other threads -- the CalibrationWatcher (the
// MPCDI file of [calibration] changed on disk) and, later, self-recalibration -- load and validate a
// calibration off the display thread and put() the result: the calibration, or the error that made
// it unusable. The loop polls fd() and take()s the newest one; Kiosk::on_calibration swaps it onto
// the outputs or, for an error, logs it and keeps the last good calibration on the wall.
//
// Newest wins: an update not yet taken is replaced by the next (a calibration being interpolated
// in only needs its latest step on the wall). Threading: put() from any thread, take() from the
// loop. Errors: create() returns the eventfd's errno error; a failed wake-up is logged.
#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "common/event_fd.h"
#include "common/projector_calibration.h"
#include "common/result.h"

namespace mogao {

struct CalibrationUpdate {
    std::string source;                       // what it came from: the MPCDI path, "selfcal", ...
    std::optional<ScreenCalibration> screen;  // validated (validate_screen); empty: `error` says why
    std::string error;                        // names the file and field (MpcdiError, validation)
    std::vector<std::string> notes;           // the loader's notes (logged)
    std::chrono::system_clock::time_point loaded_at = std::chrono::system_clock::now();
};

class CalibrationInbox {
public:
    // Heap-allocated: producers keep a pointer to it (its mutex cannot move).
    [[nodiscard]] static Result<std::unique_ptr<CalibrationInbox>> create();

    void put(CalibrationUpdate update);                     // any thread; wakes the loop
    [[nodiscard]] std::optional<CalibrationUpdate> take();  // the loop: resets the wake-up
    [[nodiscard]] int fd() const { return wake_.fd(); }
    [[nodiscard]] std::uint64_t updates() const;  // put() calls since construction

private:
    explicit CalibrationInbox(EventFd wake) : wake_(std::move(wake)) {}

    EventFd wake_;
    mutable std::mutex mutex_;
    std::optional<CalibrationUpdate> slot_;
    std::uint64_t updates_ = 0;
};

}  // namespace mogao
