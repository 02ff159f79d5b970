// SPDX-License-Identifier: Apache-2.0
// Helpers for the fuzz targets (tests/fuzz/README.md): the input as text or as a file that
// path-based readers can open (a memfd, named /proc/self/fd/N, so no file system is touched).
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "common/unique_fd.h"

namespace mogao::fuzz {

inline std::string_view text(const std::uint8_t* data, std::size_t size) {
    return {reinterpret_cast<const char*>(data), size};
}

// The bytes as a file; path() is valid while the object lives.
class MemFile {
public:
    MemFile(const std::uint8_t* data, std::size_t size) : fd_(::memfd_create("mogao-fuzz", MFD_CLOEXEC)) {
        std::size_t done = 0;
        while (fd_.valid() && done < size) {
            const ssize_t n = ::write(fd_.get(), data + done, size - done);
            if (n <= 0) break;
            done += static_cast<std::size_t>(n);
        }
        ::lseek(fd_.get(), 0, SEEK_SET);
    }
    [[nodiscard]] bool valid() const { return fd_.valid(); }
    [[nodiscard]] std::string path() const { return "/proc/self/fd/" + std::to_string(fd_.get()); }

private:
    UniqueFd fd_;
};

}  // namespace mogao::fuzz
