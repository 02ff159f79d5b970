// Owns one file descriptor (file or socket) and closes it once. Open descriptors with O_CLOEXEC /
// SOCK_CLOEXEC so that no child process (mpirun spawns some) inherits keys or sockets.
#pragma once

#include <unistd.h>

#include <utility>

namespace mogao {

class UniqueFd {
public:
    UniqueFd() = default;
    explicit UniqueFd(int fd) : fd_(fd) {}
    ~UniqueFd() { reset(); }
    UniqueFd(UniqueFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
    UniqueFd& operator=(UniqueFd&& other) noexcept {
        if (this != &other) reset(std::exchange(other.fd_, -1));
        return *this;
    }
    UniqueFd(const UniqueFd&) = delete;
    UniqueFd& operator=(const UniqueFd&) = delete;

    [[nodiscard]] int get() const { return fd_; }
    [[nodiscard]] bool valid() const { return fd_ >= 0; }
    void reset(int fd = -1) {
        // close() errors are not actionable here (the descriptor is gone either way); callers that
        // must know whether written data reached the disk call fsync() before.
        if (fd_ >= 0) ::close(fd_);
        fd_ = fd;
    }

private:
    int fd_ = -1;
};

}  // namespace mogao
