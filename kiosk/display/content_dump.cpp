// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/content_dump.h"

#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "common/file_io.h"
#include "common/png_io.h"

namespace mogao {

ContentDump::ContentDump(std::filesystem::path dir, int every) : dir_(std::move(dir)), every_(every) {
    if (every_ < 1) throw std::invalid_argument("ContentDump: every must be >= 1");
    std::filesystem::create_directories(dir_);
}

bool ContentDump::dump(const ContentFrame& frame) {
    ++count_;
    if (count_ % static_cast<std::uint64_t>(every_) != 0) return false;
    const std::string stem = fmt::format("content-req{}", frame.request_id);
    write_ppm(dir_ / (stem + ".ppm"), frame.image);
    const nlohmann::json meta = {
        {"request_id", frame.request_id},  {"link_frame_id", frame.link_frame_id},
        {"width", frame.image.size.width}, {"height", frame.image.size.height},
        {"jpeg_bytes", frame.jpeg_bytes},  {"eye", {frame.pose.eye.x(), frame.pose.eye.y(), frame.pose.eye.z()}},
        {"yaw_deg", frame.pose.yaw_deg},   {"pitch_deg", frame.pose.pitch_deg}};
    const std::string text = meta.dump(1) + "\n";
    write_file_atomically(dir_ / (stem + ".json"), {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
    return true;
}

}  // namespace mogao
