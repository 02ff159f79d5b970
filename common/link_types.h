// SPDX-License-Identifier: Apache-2.0
// Value types shared by the link's server (farm) and client (appliance), free of gRPC and protobuf.
//
// Times are nanoseconds since the Unix epoch on CLOCK_REALTIME of the host that took them (the
// farm's for the farm stages, the appliance's for request and receipt); 0 means "not recorded".
#pragma once

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "common/pixel_rect.h"
#include "common/view_request.h"

namespace mogao {

// A link could not be set up: bad endpoint, unreadable or mismatched TLS material, port in use.
// Thrown by constructors only; a running server or client logs and carries on instead.
struct LinkError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// What the injected renderer returns for one ViewRequest (see FrameRenderer in link_server.h).
struct RenderedFrame {
    ImageSize size;                  // pixels of the JPEG (normally render_size(request))
    std::vector<std::uint8_t> jpeg;  // baseline JFIF, sRGB
    // When tracing ended and encoding began; 0 lets the server use the time the renderer returned.
    std::int64_t render_end_ns = 0;
    // What the frame holds as served: samples per pixel (all accumulated passes) and indirect
    // bounces; 0 = not reported.
    std::uint32_t spp = 0;
    std::uint32_t bounces = 0;
};

struct FrameTimestamps {
    std::int64_t request_ns = 0;       // appliance: pose sampled (ViewRequest::request_time_ns)
    std::int64_t received_ns = 0;      // farm: request read from the stream
    std::int64_t render_start_ns = 0;  // farm
    std::int64_t render_end_ns = 0;    // farm
    std::int64_t encode_end_ns = 0;    // farm
    std::int64_t send_ns = 0;          // farm: handed to gRPC
    std::int64_t receive_ns = 0;       // appliance: frame read from the stream
};

// A frame as the appliance receives it.
struct LinkFrame {
    std::uint64_t frame_id = 0;    // per session, from 1
    std::uint64_t request_id = 0;  // the request it answers (ViewRequest::frame_id on the farm)
    ViewerPose pose;               // the pose it was rendered for
    ImageSize size;                // JPEG pixels
    std::uint32_t spp = 0;         // samples per pixel as served (RenderedFrame::spp); 0 = not reported
    std::uint32_t bounces = 0;     // indirect bounces as served; 0 = none or not reported
    FrameTimestamps times;
    std::vector<std::uint8_t> jpeg;
};

// CLOCK_REALTIME now, in nanoseconds since the Unix epoch.
[[nodiscard]] std::int64_t realtime_ns();

// Largest JPEG a frame may carry (both sides enforce it). 64 MiB is far above a 16K-wide
// projector canvas at quality 95 and bounds what a broken peer can make the other allocate.
inline constexpr std::size_t kMaxFrameJpegBytes = 64u << 20;

}  // namespace mogao
