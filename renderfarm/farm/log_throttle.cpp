// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/log_throttle.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace mogao {

LogThrottle::LogThrottle(double interval_s, std::size_t max_keys) : interval_s_(interval_s), max_keys_(max_keys) {
    if (!std::isfinite(interval_s) || interval_s < 0)
        throw std::invalid_argument("LogThrottle: interval_s must be finite and >= 0");
    if (max_keys == 0) throw std::invalid_argument("LogThrottle: max_keys must be >= 1");
}

LogThrottle::Verdict LogThrottle::allow(const std::string& key, double now_s) {
    auto found = keys_.find(key);
    if (found == keys_.end()) {
        if (keys_.size() >= max_keys_) keys_.clear();  // bounded: sessions come and go
        keys_.emplace(key, Key{now_s, 0});
        return {true, 0};
    }
    Key& k = found->second;
    if (now_s - k.written_s < interval_s_) {
        ++k.held_back;
        return {false, k.held_back};
    }
    const Verdict v{true, k.held_back};
    k = Key{now_s, 0};
    return v;
}

std::string held_back_note(std::uint64_t held_back) {
    if (held_back == 0) return "";
    return " (" + std::to_string(held_back) + " more since the last line)";
}

double log_clock_s() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace mogao
