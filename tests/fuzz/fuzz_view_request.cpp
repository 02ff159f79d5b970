// SPDX-License-Identifier: Apache-2.0
// Fuzz target: a wire ViewRequestMsg (protobuf bytes from an appliance) converted and
// validated by view_from_msg, as the farm does for every request. Documented errors are caught; anything
// else (a crash, a sanitizer report, an exception of another type) is a finding.
#include <cstddef>
#include <cstdint>

#include <limits>

#include "renderfarm/link/mogao_link.pb.h"
#include "renderfarm/link/wire_convert.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    mogao::link::v1::ViewRequestMsg msg;
    if (size > static_cast<std::size_t>(std::numeric_limits<int>::max())) return 0;
    if (!msg.ParseFromArray(data, static_cast<int>(size))) return 0;
    mogao::ViewRequest request;
    static_cast<void>(mogao::view_from_msg(msg, request));
    return 0;
}
