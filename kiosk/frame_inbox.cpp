// SPDX-License-Identifier: Apache-2.0
#include "kiosk/frame_inbox.h"

#include <spdlog/spdlog.h>

namespace mogao {

Result<std::unique_ptr<FrameInbox>> FrameInbox::create() {
    auto wake = EventFd::create();
    if (!wake) return wake.error();
    return std::unique_ptr<FrameInbox>(new FrameInbox(std::move(*wake)));
}

void FrameInbox::put(LinkFrame&& frame) {
    slot_.put(std::move(frame));
    if (Status s = wake_.signal(); !s) spdlog::error("frame wake-up: {}", s.error().message);
}

std::optional<LinkFrame> FrameInbox::take() {
    if (auto n = wake_.drain(); !n) spdlog::error("frame wake-up: {}", n.error().message);
    return slot_.take();
}

}  // namespace mogao
