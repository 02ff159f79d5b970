// SPDX-License-Identifier: Apache-2.0
// Conversions between the link's protobuf messages (mogao_link.proto, schema v1) and the farm's
// value types, with the validation every message from the network goes through.
//
// Errors are returned, not thrown: a bad message from one appliance is refused and logged, and its
// session carries on. Error strings name the field, its value and the limit, e.g.
// "quality.spp = 0 is outside [1, 4096]".
//
// Limits: the table in common/request_limits.h (frame sides in kLinkImageSide); pose and camera
// finite; pinhole vertical_fov_deg (0, 180); cylinder radius_m > 0, arc_deg (0, 360],
// top_m > bottom_m. The request id is ViewRequest::frame_id and must be non-zero.
#pragma once

#include <string>

#include "common/link_types.h"
#include "common/request_limits.h"
#include "common/view_request.h"
#include "renderfarm/link/mogao_link.pb.h"

namespace mogao {

inline constexpr int kMinLinkImageSide = request_limits::kLinkImageSide.min;
inline constexpr int kMaxLinkImageSide = request_limits::kLinkImageSide.max;

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
