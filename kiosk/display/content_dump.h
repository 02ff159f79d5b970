// SPDX-License-Identifier: Apache-2.0
// ContentDump (--dump-content DIR): keeps every k-th decoded content frame as the kiosk got it, for
// end-to-end checks against the farm's lossless render of the same pose.
//   <dir>/content-req<id>.ppm   the decoded frame (binary PPM, lossless, what the outputs sampled)
//   <dir>/content-req<id>.json  {"request_id", "link_frame_id", "width", "height", "jpeg_bytes",
//                                "eye": [x, y, z], "yaw_deg", "pitch_deg"} (world metres, degrees;
//                                numbers printed so that they read back exactly)
// Errors: dump() throws EncodeError / std::system_error naming the file.
#pragma once

#include <filesystem>

#include "appliance/decode/last_good_frame.h"

namespace mogao {

class ContentDump {
public:
    // Creates `dir` if missing. every >= 1 (std::invalid_argument).
    ContentDump(std::filesystem::path dir, int every);

    // Counts the frame and writes it when its count is a multiple of `every` (the first frame is
    // count 1). Returns true when written.
    bool dump(const ContentFrame& frame);

private:
    std::filesystem::path dir_;
    int every_;
    std::uint64_t count_ = 0;
};

}  // namespace mogao
