// SPDX-License-Identifier: Apache-2.0
#include "appliance/decode/last_good_frame.h"

#include <chrono>
#include <exception>

#include <fmt/format.h>

namespace mogao {

std::string LastGoodFrame::accept(const LinkFrame& frame) {
    const auto reject = [&](std::string why) {
        ++rejected_;
        return fmt::format("request {} (link frame {}, {} bytes): {}", frame.request_id, frame.frame_id,
                           frame.jpeg.size(), why);
    };
    if (current_ && frame.request_id <= current_->request_id) {
        return reject(fmt::format("not newer than request {} on screen", current_->request_id));
    }
    ContentFrame next;
    const auto start = std::chrono::steady_clock::now();
    try {
        next.image = decoder_.decode(frame.jpeg);
    } catch (const std::exception& e) {
        return reject(fmt::format("JPEG decode failed: {}", e.what()));
    }
    next.decode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (!(next.image.size == frame.size)) {
        return reject(fmt::format("decoded {}x{} but the farm declared {}x{}", next.image.size.width,
                                  next.image.size.height, frame.size.width, frame.size.height));
    }
    next.request_id = frame.request_id;
    next.link_frame_id = frame.frame_id;
    next.pose = frame.pose;
    next.times = frame.times;
    next.jpeg_bytes = frame.jpeg.size();
    next.spp = frame.spp;
    next.bounces = frame.bounces;
    current_ = std::move(next);
    ++accepted_;
    return {};
}

}  // namespace mogao
