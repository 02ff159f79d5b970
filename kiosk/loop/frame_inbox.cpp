// SPDX-License-Identifier: Apache-2.0
#include "kiosk/loop/frame_inbox.h"

#include <spdlog/spdlog.h>

namespace mogao {

Result<std::unique_ptr<FrameInbox>> FrameInbox::create() {
    auto wake = EventFd::create();
    if (!wake) return wake.error();
    return std::unique_ptr<FrameInbox>(new FrameInbox(std::move(*wake)));
}

FrameInbox::FrameInbox(EventFd wake)
    : wake_(std::move(wake)), worker_([this] {
          if (Status s = wake_.signal(); !s) spdlog::error("frame wake-up: {}", s.error().message);
      }) {}

void FrameInbox::put(LinkFrame&& frame) { worker_.put(std::move(frame)); }

DecodeWorker::Taken FrameInbox::take() {
    if (auto n = wake_.drain(); !n) spdlog::error("frame wake-up: {}", n.error().message);
    return worker_.take();
}

}  // namespace mogao
