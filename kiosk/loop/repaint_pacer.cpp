// SPDX-License-Identifier: Apache-2.0
#include "kiosk/loop/repaint_pacer.h"

#include <stdexcept>

namespace mogao {

RepaintPacer::RepaintPacer(double max_duty) {
    if (!(max_duty > 0.0 && max_duty <= 1.0)) throw std::invalid_argument("RepaintPacer: max_duty must be in (0, 1]");
    rest_per_busy_ = 1.0 / max_duty - 1.0;
}

void RepaintPacer::drew(Clock::time_point start, Clock::time_point end) {
    last_end_ = end;
    last_round_ = end > start ? end - start : Clock::duration::zero();
}

bool RepaintPacer::may_repaint(Clock::time_point now) const {
    const auto rest = std::chrono::duration_cast<Clock::duration>(last_round_ * rest_per_busy_);
    return now - last_end_ >= rest;
}

}  // namespace mogao
