// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/log_throttle.h"

#include <cmath>

#include <gtest/gtest.h>

namespace mogao {
namespace {

// An event repeated with every request (60 a second for ten minutes) writes one line a minute, each
// with the count of the events held back since the previous line.
TEST(LogThrottle, AnEventRepeatedEveryFrameWritesOneLineAMinute) {
    LogThrottle throttle(60.0);
    int lines = 0;
    std::uint64_t held_back = 0;
    for (int frame = 0; frame < 60 * 600; ++frame) {
        const LogThrottle::Verdict v = throttle.allow("view:1", frame / 60.0);
        if (!v.write) continue;
        ++lines;
        held_back += v.held_back;
    }
    EXPECT_EQ(lines, 10);
    // Every event up to the last line (minute 9's first) is written or counted in a written line.
    EXPECT_EQ(held_back + lines, 60u * 540u + 1u);
}

TEST(LogThrottle, KeysAreThrottledApartAndForgottenBeyondTheirBound) {
    LogThrottle throttle(60.0, 2);
    EXPECT_TRUE(throttle.allow("view:1", 0.0).write);
    EXPECT_TRUE(throttle.allow("cut:1", 0.0).write) << "another kind of event of the same session";
    EXPECT_FALSE(throttle.allow("view:1", 1.0).write);
    EXPECT_TRUE(throttle.allow("view:2", 1.0).write) << "a third key: the table is emptied, this one written";
    EXPECT_TRUE(throttle.allow("view:1", 2.0).write) << "forgotten: written again at once";
    const LogThrottle::Verdict later = throttle.allow("view:1", 70.0);
    EXPECT_TRUE(later.write);
    EXPECT_EQ(later.held_back, 0u);
    EXPECT_EQ(held_back_note(0), "");
    EXPECT_EQ(held_back_note(3), " (3 more since the last line)");
}

TEST(LogThrottle, BadArgumentsAreRefused) {
    EXPECT_THROW(LogThrottle(-1.0), std::invalid_argument);
    EXPECT_THROW(LogThrottle(std::nan("")), std::invalid_argument);
    EXPECT_THROW(LogThrottle(1.0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
