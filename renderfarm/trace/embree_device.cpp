// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/embree_device.h"

#include <stdexcept>

namespace mogao {
namespace {

// Embree calls the error function on the thread whose API call failed, so a thread-local message
// pairs correctly with that thread's rtcGetDeviceError() code without locking.
thread_local std::string last_embree_message;

void record_error(void* /*user*/, RTCError /*code*/, const char* message) {
    last_embree_message = message != nullptr ? message : "";
}

const char* error_name(RTCError code) {
    switch (code) {
        case RTC_ERROR_NONE:
            return "RTC_ERROR_NONE";
        case RTC_ERROR_UNKNOWN:
            return "RTC_ERROR_UNKNOWN";
        case RTC_ERROR_INVALID_ARGUMENT:
            return "RTC_ERROR_INVALID_ARGUMENT";
        case RTC_ERROR_INVALID_OPERATION:
            return "RTC_ERROR_INVALID_OPERATION";
        case RTC_ERROR_OUT_OF_MEMORY:
            return "RTC_ERROR_OUT_OF_MEMORY";
        case RTC_ERROR_UNSUPPORTED_CPU:
            return "RTC_ERROR_UNSUPPORTED_CPU";
        case RTC_ERROR_CANCELLED:
            return "RTC_ERROR_CANCELLED";
    }
    return "RTC_ERROR_?";
}

[[noreturn]] void throw_error(std::string_view what, RTCError code) {
    std::string message = std::string(what) + ": " + error_name(code);
    if (!last_embree_message.empty()) message += ": " + last_embree_message;
    last_embree_message.clear();
    throw std::runtime_error(message);
}

// Embree reports every allocation (bytes > 0) and release (bytes < 0); true lets it proceed.
bool count_memory(void* user, ssize_t bytes, bool /*post*/) {
    static_cast<std::atomic<std::int64_t>*>(user)->fetch_add(bytes, std::memory_order_relaxed);
    return true;
}

}  // namespace

std::string EmbreeDevice::effective_config(const std::string& config) {
    if (config.find("isa=") != std::string::npos) return config;  // "isa=" or "max_isa=": the caller's choice
    return config.empty() ? std::string("max_isa=avx2") : config + ",max_isa=avx2";
}

EmbreeDevice::EmbreeDevice(const std::string& config) : device_(rtcNewDevice(effective_config(config).c_str())) {
    if (!device_) {
        // Creation errors are only reported through the null device's error code.
        throw_error("rtcNewDevice(\"" + effective_config(config) + "\")", rtcGetDeviceError(nullptr));
    }
    rtcSetDeviceErrorFunction(device_.get(), record_error, nullptr);
    rtcSetDeviceMemoryMonitorFunction(device_.get(), count_memory, allocated_.get());
}

void EmbreeDevice::check(std::string_view what) const {
    const RTCError code = rtcGetDeviceError(device_.get());
    if (code != RTC_ERROR_NONE) throw_error(what, code);
}

}  // namespace mogao
