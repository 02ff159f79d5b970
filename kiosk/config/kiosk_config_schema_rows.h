// SPDX-License-Identifier: Apache-2.0
// What the schema's row files share (internal to kiosk/config/): how a row names its member, its
// limits, and the [navigation] rows, which have a file of their own (kiosk_config_schema_navigation.cpp).
#pragma once

#include <span>

#include "common/request_limits.h"
#include "kiosk/config/kiosk_config_schema.h"

namespace mogao::schema_rows {

// The member a row fills, as a function returning a reference to it.
#define MOGAO_AT(T, member) +[](KioskConfig& c) -> T& { return c.member; }
#define MOGAO_CHOICE(E, member)                                                   \
    ChoiceMember {                                                                \
        +[](const KioskConfig& c) { return static_cast<std::size_t>(c.member); }, \
            +[](KioskConfig& c, std::size_t i) { c.member = static_cast<E>(i); }  \
    }

constexpr NumberLimit closed(double lo, double hi) { return {lo, hi, false, false, false}; }
constexpr NumberLimit open_low(double lo, double hi) { return {lo, hi, true, false, false}; }
constexpr NumberLimit ints(IntRange r) { return closed(r.min, r.max); }

// [navigation], [navigation.detector], [navigation.roi], [navigation.control], in the file's order.
[[nodiscard]] std::span<const ConfigKey> navigation_rows();

}  // namespace mogao::schema_rows
