// SPDX-License-Identifier: Apache-2.0
// ioctl on a V4L2 device that retries when a signal interrupts it (the V4L2 uAPI examples'
// "xioctl"). Internal to drivers/camera: capture, controls and the device listing share it.
#pragma once

#include <sys/ioctl.h>

#include <cerrno>

namespace mogao {

inline int xioctl(int fd, unsigned long request, void* arg) {
    int r = 0;
    do {
        r = ::ioctl(fd, request, arg);
    } while (r == -1 && errno == EINTR);
    return r;
}

}  // namespace mogao
