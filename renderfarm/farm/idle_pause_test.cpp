// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/idle_pause.h"

#include <gtest/gtest.h>

namespace mogao {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;
using std::chrono::seconds;

TEST(IdlePause, ShortWaitsPollOftenLongOnesRarely) {
    EXPECT_EQ(idle_pause(microseconds(-5)), microseconds(100));
    EXPECT_EQ(idle_pause(microseconds(0)), microseconds(100));
    EXPECT_EQ(idle_pause(microseconds(4999)), microseconds(100)) << "the tiles right after the view";
    EXPECT_EQ(idle_pause(milliseconds(5)), milliseconds(1));
    EXPECT_EQ(idle_pause(microseconds(999'999)), milliseconds(1));
    EXPECT_EQ(idle_pause(seconds(1)), milliseconds(5));
    EXPECT_EQ(idle_pause(std::chrono::hours(10)), milliseconds(5)) << "a night without a gallery";
}

}  // namespace
}  // namespace mogao
