// SPDX-License-Identifier: Apache-2.0
#include "appliance/decode/latest_frame_slot.h"

#include <utility>

namespace mogao {

bool LatestFrameSlot::put(LinkFrame frame) {
    std::optional<LinkFrame> old;  // freed outside the lock
    bool replaced = false;
    {
        const std::lock_guard lock(mutex_);
        replaced = frame_.has_value();
        if (replaced) ++replaced_;
        ++stored_;
        old = std::exchange(frame_, std::move(frame));
    }
    return replaced;
}

std::optional<LinkFrame> LatestFrameSlot::take() {
    const std::lock_guard lock(mutex_);
    return std::exchange(frame_, std::nullopt);
}

std::uint64_t LatestFrameSlot::replaced() const {
    const std::lock_guard lock(mutex_);
    return replaced_;
}

std::uint64_t LatestFrameSlot::stored() const {
    const std::lock_guard lock(mutex_);
    return stored_;
}

}  // namespace mogao
