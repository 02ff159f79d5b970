// Conversions between the link's protobuf messages (mogao_link.proto, schema v1) and the farm's
// value types, with the validation every message from the network goes through.
//
// Errors are returned, not thrown: a bad message from one appliance is refused and logged, and its
// session carries on. Error strings name the field, its value and the limit, e.g.
// "quality.spp = 0 is outside [1, 4096]".
//
// Limits (inclusive unless noted; the farm's render limits, with a 16-pixel minimum side):
// width/height 16..16384; quality.spp 1..4096, max_bounces 0..64, ao_samples 0..1024,
// area_light_samples 1..1024, resolution_scale (0, 1], jpeg_quality 1..100; pose and camera
// finite; pinhole vertical_fov_deg (0, 180); cylinder radius_m > 0, arc_deg (0, 360],
// top_m > bottom_m. The request id is ViewRequest::frame_id and must be non-zero.
#pragma once

#include <string>

#include "renderfarm/link/link_types.h"
#include "renderfarm/link/mogao_link.pb.h"
#include "renderfarm/view/view_request.h"

namespace mogao {

inline constexpr int kMinLinkImageSide = 16;
inline constexpr int kMaxLinkImageSide = 16384;

// Checks the limits above; returns "" when the request is valid.
[[nodiscard]] std::string validate_link_request(const ViewRequest& request);

// ViewRequest -> message (request_id = request.frame_id). Does not validate and leaves
// ack_frame_id untouched.
void view_to_msg(const ViewRequest& request, link::v1::ViewRequestMsg& msg);

// Message -> ViewRequest. Returns "" and fills `out` when the message is a valid view request;
// otherwise returns the error and leaves `out` unspecified. Missing pose, camera or quality are
// errors (proto3 would silently read them as zeros).
[[nodiscard]] std::string view_from_msg(const link::v1::ViewRequestMsg& msg, ViewRequest& out);

// Message -> LinkFrame (client side). Returns "" on success; refuses frames whose size is outside
// 1..16384, whose JPEG is empty or above kMaxFrameJpegBytes, or whose pose is not finite.
// The JPEG bytes are copied and then cleared from `msg`. times.receive_ns is left for the caller.
[[nodiscard]] std::string frame_from_msg(link::v1::FrameMsg& msg, LinkFrame& out);

void pose_to_msg(const ViewerPose& pose, link::v1::PoseMsg& msg);

}  // namespace mogao
