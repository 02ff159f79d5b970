// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/link_log.h"

#include <spdlog/sinks/stdout_color_sinks.h>

namespace mogao {

spdlog::logger& link_log() {
    // Reuse a logger the program registered under this name (to route it elsewhere); otherwise
    // create it once. The static makes creation thread-safe.
    static const std::shared_ptr<spdlog::logger> logger = [] {
        if (auto existing = spdlog::get("mogao-link")) return existing;
        return spdlog::stderr_color_mt("mogao-link");
    }();
    return *logger;
}

}  // namespace mogao
