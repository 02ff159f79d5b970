// SPDX-License-Identifier: Apache-2.0
// The link's spdlog logger "mogao-link", writing to stderr (journald adds timestamps on the
// appliance; the farm sets its own pattern with spdlog::set_pattern before the logger exists).
// Internal to renderfarm/link.
#pragma once

#include <spdlog/spdlog.h>

namespace mogao {

[[nodiscard]] spdlog::logger& link_log();

}  // namespace mogao
