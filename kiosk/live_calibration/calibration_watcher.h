// SPDX-License-Identifier: Apache-2.0
// CalibrationWatcher: the run-time calibration swap's trigger (docs/kiosk.md, "Calibration swap").
// It watches the MPCDI file of [calibration] with inotify(7) -- on its folder, for IN_CLOSE_WRITE
// (written in place) and IN_MOVED_TO (renamed over it, as write_mpcdi and the calibration store do:
// an atomic replace gives a new inode, which a watch on the file itself would miss) -- and on every
// change loads and validates the file on its own thread, off the display path, and puts the
// calibration or the error (naming the file and field) into a CalibrationInbox. The kiosk swaps a
// good one onto its outputs and keeps the last good one for a bad one.
//
// The inotify fd (IN_CLOEXEC | IN_NONBLOCK) and the stop eventfd are UniqueFds; the thread polls
// both and is joined by the destructor. Errors: create() returns the errno of inotify_init1 /
// inotify_add_watch naming the folder (ENOENT, ENOSPC for the watch limit). A load error is no error
// of the watcher: it goes into the inbox.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "common/event_fd.h"
#include "common/projector_calibration.h"
#include "common/result.h"
#include "common/unique_fd.h"
#include "kiosk/live_calibration/calibration_inbox.h"

namespace mogao {

class CalibrationWatcher {
public:
    // Loads and validates the file (e.g. load_screen_calibration); throws with a message naming the
    // file and field. Runs on the watcher's thread.
    using Loader = std::function<ScreenCalibration(std::vector<std::string>* notes)>;

    // Heap-allocated: its thread keeps `this`. `inbox` must outlive the watcher.
    [[nodiscard]] static Result<std::unique_ptr<CalibrationWatcher>> create(std::filesystem::path file, Loader loader,
                                                                            CalibrationInbox& inbox);
    ~CalibrationWatcher();
    CalibrationWatcher(const CalibrationWatcher&) = delete;
    CalibrationWatcher& operator=(const CalibrationWatcher&) = delete;

    [[nodiscard]] const std::filesystem::path& file() const { return file_; }

private:
    CalibrationWatcher(std::filesystem::path file, Loader loader, CalibrationInbox& inbox, UniqueFd inotify,
                       EventFd stop);
    void run();                         // the thread: poll, read events, load
    [[nodiscard]] bool file_changed();  // drains the inotify fd; true when an event names the file
    void load();

    std::filesystem::path file_;
    Loader loader_;
    CalibrationInbox& inbox_;
    UniqueFd inotify_;
    EventFd stop_;
    std::thread thread_;  // last: started once everything it reads exists
};

}  // namespace mogao
