// UniqueFd: sole owner of one file descriptor (after libcamera's UniqueFD). Closes it on
// destruction; move-only. Every fd in drivers/ is opened with O_CLOEXEC so that programs the kiosk
// starts never inherit a DRM master or a camera.
#pragma once

#include <unistd.h>

#include <utility>

namespace mogao {

class UniqueFd {
public:
    UniqueFd() = default;
    explicit UniqueFd(int fd) noexcept : fd_(fd) {}
    UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
    UniqueFd& operator=(UniqueFd&& other) noexcept {
        reset(other.release());
        return *this;
    }
    UniqueFd(const UniqueFd&) = delete;
    UniqueFd& operator=(const UniqueFd&) = delete;
    ~UniqueFd() { reset(); }

    [[nodiscard]] int get() const noexcept { return fd_; }
    [[nodiscard]] bool valid() const noexcept { return fd_ >= 0; }
    // Gives up ownership without closing; returns the fd (or -1).
    [[nodiscard]] int release() noexcept { return std::exchange(fd_, -1); }
    // Closes the owned fd (if any) and takes `fd`. close()'s error is ignored: for the device and
    // event fds owned here it is not actionable, and the fd is released either way on Linux.
    void reset(int fd = -1) noexcept {
        const int old = std::exchange(fd_, fd);
        if (old >= 0 && old != fd) ::close(old);
    }

private:
    int fd_ = -1;
};

}  // namespace mogao
