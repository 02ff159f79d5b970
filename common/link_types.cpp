// SPDX-License-Identifier: Apache-2.0
#include "common/link_types.h"

#include <time.h>

namespace mogao {

std::int64_t realtime_ns() {
    timespec ts{};
    clock_gettime(CLOCK_REALTIME, &ts);
    return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace mogao
