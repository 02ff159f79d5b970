// SPDX-License-Identifier: Apache-2.0
// Rate control (seed paper: the tag's displacement from its rest pose sets a velocity, not a
// position, so a visitor can turn all the way round and walk the whole grotto with small hand
// movements). One axis:
//
//   rate(e) = sign(e) * max_rate * clamp((|e| - dead_zone) / (full_scale - dead_zone), 0, 1) ^ exponent
//
// e is the offset from the rest pose (degrees or metres). Inside the dead zone the rate is 0, so
// tremor and an imprecise rest pose do not creep the view; it then rises continuously from 0 (no
// jump at the dead zone's edge) and saturates at max_rate from full_scale on. exponent > 1 gives
// finer control of slow motion.
#pragma once

namespace mogao {

struct RateAxis {
    double dead_zone = 0.0;   // >= 0, units of e
    double full_scale = 1.0;  // > dead_zone
    double max_rate = 0.0;    // >= 0, units of e per second (0 disables the axis)
    double exponent = 1.0;    // [1, 4]
};

// Throws std::invalid_argument naming `name`, the field and its limit.
void validate(const RateAxis& axis, const char* name);

[[nodiscard]] double rate_from_offset(double offset, const RateAxis& axis);

// Moves `current` toward `target` by at most max_step (>= 0): the acceleration limit that makes
// every velocity change, including the stop when the tag is lost, a ramp instead of a jump.
[[nodiscard]] double slew_toward(double current, double target, double max_step);

}  // namespace mogao
