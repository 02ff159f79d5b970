// SPDX-License-Identifier: Apache-2.0
// UniqueFd: sole owner of one file descriptor (after libcamera's UniqueFD). Closes it on
// destruction; move-only. Every fd the project opens is opened with O_CLOEXEC so that programs the
// kiosk starts never inherit a DRM master or a camera. An instance of UniqueHandle
// (common/unique_handle.h): get(), valid(), release(), reset(fd).
#pragma once

#include <unistd.h>

#include "common/unique_handle.h"

namespace mogao {

struct FdTraits {
    using Value = int;
    static constexpr int null() noexcept { return -1; }
    // close()'s error is ignored: for the device and event fds owned here it is not actionable,
    // and the fd is released either way on Linux.
    static void close(int fd) noexcept { ::close(fd); }
};

using UniqueFd = UniqueHandle<FdTraits>;

}  // namespace mogao
