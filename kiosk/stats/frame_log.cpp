// SPDX-License-Identifier: Apache-2.0
#include "kiosk/stats/frame_log.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

namespace mogao {

FrameLog::FrameLog(std::filesystem::path path) : path_(std::move(path)) {
    fd_.reset(::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644));
    if (!fd_.valid()) throw std::system_error(errno, std::generic_category(), "frame log " + path_.string());
}

void FrameLog::append(const std::string& line) {
    if (!error_.empty()) return;
    const std::string text = line + "\n";
    std::size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd_.get(), text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            error_ = path_.string() + ": " + (n < 0 ? std::strerror(errno) : "nothing written");
            return;
        }
        done += static_cast<std::size_t>(n);
    }
    ++lines_;
}

}  // namespace mogao
