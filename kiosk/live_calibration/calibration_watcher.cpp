// SPDX-License-Identifier: Apache-2.0
#include "kiosk/live_calibration/calibration_watcher.h"

#include <poll.h>
#include <sys/inotify.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

#include <spdlog/spdlog.h>

namespace mogao {

namespace fs = std::filesystem;

Result<std::unique_ptr<CalibrationWatcher>> CalibrationWatcher::create(fs::path file, Loader loader,
                                                                       CalibrationInbox& inbox) {
    UniqueFd inotify(::inotify_init1(IN_CLOEXEC | IN_NONBLOCK));
    if (!inotify.valid()) return errno_error("inotify_init1");
    const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
    if (::inotify_add_watch(inotify.get(), dir.c_str(), IN_CLOSE_WRITE | IN_MOVED_TO) < 0) {
        return errno_error("inotify_add_watch '" + dir.string() + "'");
    }
    auto stop = EventFd::create();
    if (!stop) return with_context(stop.error(), "calibration watcher");
    return std::unique_ptr<CalibrationWatcher>(
        new CalibrationWatcher(std::move(file), std::move(loader), inbox, std::move(inotify), std::move(stop).value()));
}

CalibrationWatcher::CalibrationWatcher(fs::path file, Loader loader, CalibrationInbox& inbox, UniqueFd inotify,
                                       EventFd stop)
    : file_(std::move(file)),
      loader_(std::move(loader)),
      inbox_(inbox),
      inotify_(std::move(inotify)),
      stop_(std::move(stop)),
      thread_([this] { run(); }) {}

CalibrationWatcher::~CalibrationWatcher() {
    if (Status s = stop_.signal(); !s) spdlog::error("calibration watcher: stop: {}", s.error().message);
    if (thread_.joinable()) thread_.join();
}

void CalibrationWatcher::run() {
    for (;;) {
        std::array<pollfd, 2> fds{pollfd{inotify_.get(), POLLIN, 0}, pollfd{stop_.fd(), POLLIN, 0}};
        if (::poll(fds.data(), fds.size(), -1) < 0) {
            if (errno == EINTR) continue;
            spdlog::error("calibration watcher: poll: {}; run-time calibration swaps stop", std::strerror(errno));
            return;
        }
        if (fds[1].revents != 0) return;
        if (fds[0].revents != 0 && file_changed()) load();
    }
}

bool CalibrationWatcher::file_changed() {
    // inotify events are variable-length records; the buffer is aligned for the first one.
    alignas(inotify_event) std::array<char, 4096> buffer{};
    const std::string name = file_.filename().string();
    bool changed = false;
    for (;;) {
        const ssize_t n = ::read(inotify_.get(), buffer.data(), buffer.size());
        if (n <= 0) return changed;  // EAGAIN: drained
        for (ssize_t at = 0; at < n;) {
            inotify_event event{};
            std::memcpy(&event, buffer.data() + at, sizeof event);
            const char* event_name = buffer.data() + at + sizeof(inotify_event);
            if (event.len > 0 && name == event_name) changed = true;
            at += static_cast<ssize_t>(sizeof(inotify_event) + event.len);
        }
    }
}

void CalibrationWatcher::load() {
    CalibrationUpdate update;
    update.source = file_.string();
    try {
        update.screen = loader_(&update.notes);
    } catch (const std::exception& e) {
        // MpcdiError names the file already; a validation error names only the field.
        const std::string what = e.what();
        update.error = what.find(file_.string()) == std::string::npos ? file_.string() + ": " + what : what;
    }
    inbox_.put(std::move(update));
}

}  // namespace mogao
