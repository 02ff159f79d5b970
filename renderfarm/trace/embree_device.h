// SPDX-License-Identifier: Apache-2.0
// RAII owner of an Embree device (RTCDevice) and the error channel of every Embree call made on it.
//
// Errors: Embree reports errors through a per-thread error code and an error callback. The callback
// only records the message (thread-local: it must not throw through Embree's C API); check() reads
// and clears the calling thread's error code and throws std::runtime_error("<what>: <code>: <message>").
// Call check() after Embree calls that can fail (device/scene/geometry creation, commits).
//
// ISA: every device is created with "max_isa=avx2" unless the configuration names an ISA itself
// ("isa=" or "max_isa="). Debian 12's Embree 3.13.5 never returned from rtcOccluded16 in its
// AVX-512 kernels on an AMD EPYC with AVX-512 (seen 2026-11-23: every render, from a 160x90 test
// room up, spun in libembree3 forever, so the farm's ranks missed their frame deadline); with the
// AVX2 kernels the same renders pass. On a CPU without AVX2, max_isa lets Embree pick a lower one.
//
// Reference: Embree 3 API, rtcNewDevice / rtcSetDeviceErrorFunction / rtcGetDeviceError, and the
// device configuration keys isa / max_isa (https://www.embree.org/api.html).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include <embree3/rtcore.h>

#include "common/unique_handle.h"

namespace mogao {

class EmbreeDevice {
public:
    // config: Embree device configuration, e.g. "threads=1" (BVH builds on one thread); "" = defaults
    // (either way with max_isa=avx2 added unless it names an ISA, see above). Throws std::runtime_error if the device
    // cannot be created (bad config, unsupported CPU).
    explicit EmbreeDevice(const std::string& config = "");

    [[nodiscard]] RTCDevice get() const noexcept { return device_.get(); }

    // Throws std::runtime_error naming `what` if an Embree call on this thread failed since the
    // last check(); no-op otherwise.
    void check(std::string_view what) const;

    // Bytes Embree holds on this device now (BVHs, buffers it allocated), from its memory monitor
    // (rtcSetDeviceMemoryMonitorFunction); what benchmarks compare across BVH choices.
    [[nodiscard]] std::int64_t allocated_bytes() const noexcept { return allocated_ ? allocated_->load() : 0; }

    // The configuration rtcNewDevice gets for `config` (the ISA cap added where it names none).
    [[nodiscard]] static std::string effective_config(const std::string& config);

private:
    struct Traits {
        using Value = RTCDevice;
        static constexpr RTCDevice null() noexcept { return nullptr; }
        static void close(RTCDevice device) noexcept { rtcReleaseDevice(device); }
    };
    // Heap-held so the monitor's user pointer survives a move of the device; declared before
    // device_ so it outlives the device's last callback.
    std::unique_ptr<std::atomic<std::int64_t>> allocated_ = std::make_unique<std::atomic<std::int64_t>>(0);
    UniqueHandle<Traits> device_;  // move-only; a moved-from device holds nullptr
};

}  // namespace mogao
