// SPDX-License-Identifier: Apache-2.0
// The tracker's result as the navigation's input: TrackedTag (tag_tracker.h) -> TagSample
// (appliance/navigation/navigator.h). Used by `mogao-track navigate` and the kiosk's tracking
// thread; time_ns is the frame's timestamp unless the caller gives another (a replay rebased onto
// the display's clock).
#pragma once

#include <cstdint>

#include "appliance/navigation/navigator.h"
#include "appliance/tracker/tag_tracker.h"

namespace mogao {

[[nodiscard]] inline TagSample tag_sample_of(const TrackedTag& tag) {
    return TagSample{tag.timestamp_ns, tag.visible, tag.pose.rotation, tag.pose.translation_m};
}

[[nodiscard]] inline TagSample tag_sample_of(const TrackedTag& tag, std::int64_t time_ns) {
    TagSample s = tag_sample_of(tag);
    s.time_ns = time_ns;
    return s;
}

}  // namespace mogao
