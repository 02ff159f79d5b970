// SPDX-License-Identifier: Apache-2.0
#include "kiosk/loop/repaint_pacer.h"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

namespace mogao {
namespace {

using namespace std::chrono_literals;
using Clock = RepaintPacer::Clock;

TEST(RepaintPacer, AtHalfDutyTheRasteriserRestsAsLongAsItDrew) {
    RepaintPacer pacer(0.5);
    const Clock::time_point t0{};
    EXPECT_TRUE(pacer.may_repaint(t0 + 1s)) << "nothing drawn yet";
    pacer.drew(t0, t0 + 60ms);  // a slow round: 60 ms
    EXPECT_FALSE(pacer.may_repaint(t0 + 90ms)) << "30 ms of rest after 60 ms of drawing";
    EXPECT_TRUE(pacer.may_repaint(t0 + 120ms));
    pacer.drew(t0 + 120ms, t0 + 122ms);  // a GPU's round: 2 ms
    EXPECT_TRUE(pacer.may_repaint(t0 + 124ms));
    EXPECT_FALSE(pacer.may_repaint(t0 + 123ms));
}

TEST(RepaintPacer, FullDutyNeverHoldsARepaintBack) {
    RepaintPacer pacer(1.0);
    const Clock::time_point t0{};
    pacer.drew(t0, t0 + 200ms);
    EXPECT_TRUE(pacer.may_repaint(t0 + 200ms));
}

TEST(RepaintPacer, ADutyOutsideItsRangeIsRefused) {
    EXPECT_THROW(RepaintPacer(0.0), std::invalid_argument);
    EXPECT_THROW(RepaintPacer(1.5), std::invalid_argument);
    EXPECT_THROW(RepaintPacer(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
