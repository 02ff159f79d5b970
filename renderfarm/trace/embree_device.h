// SPDX-License-Identifier: Apache-2.0
// RAII owner of an Embree device (RTCDevice) and the error channel of every Embree call made on it.
//
// Errors: Embree reports errors through a per-thread error code and an error callback. The callback
// only records the message (thread-local: it must not throw through Embree's C API); check() reads
// and clears the calling thread's error code and throws std::runtime_error("<what>: <code>: <message>").
// Call check() after Embree calls that can fail (device/scene/geometry creation, commits).
//
// Reference: Embree 3 API, rtcNewDevice / rtcSetDeviceErrorFunction / rtcGetDeviceError
// (https://www.embree.org/api.html).
#pragma once

#include <string>
#include <string_view>

#include <embree3/rtcore.h>

#include "common/unique_handle.h"

namespace mogao {

class EmbreeDevice {
public:
    // config: Embree device configuration, e.g. "threads=1" (BVH builds on one thread); "" = defaults.
    // Throws std::runtime_error if the device cannot be created (bad config, unsupported CPU).
    explicit EmbreeDevice(const std::string& config = "");

    [[nodiscard]] RTCDevice get() const noexcept { return device_.get(); }

    // Throws std::runtime_error naming `what` if an Embree call on this thread failed since the
    // last check(); no-op otherwise.
    void check(std::string_view what) const;

private:
    struct Traits {
        using Value = RTCDevice;
        static constexpr RTCDevice null() noexcept { return nullptr; }
        static void close(RTCDevice device) noexcept { rtcReleaseDevice(device); }
    };
    UniqueHandle<Traits> device_;  // move-only; a moved-from device holds nullptr
};

}  // namespace mogao
