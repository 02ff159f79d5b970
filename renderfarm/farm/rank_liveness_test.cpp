// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/rank_liveness.h"

#include <limits>

#include <gtest/gtest.h>

namespace mogao {
namespace {

// A rank that keeps reporting is never lost, however long its frame takes (a slow frame).
TEST(RankLiveness, ARankThatReportsIsNeverLostHoweverLongItsFrameTakes) {
    RankLiveness live(2, 2.0, 0.0);
    for (double t = 0.1; t < 600.0; t += 0.1) {
        live.heard(1, t);
        live.heard(2, t);
        ASSERT_TRUE(live.silent(t).empty()) << "at " << t << " s";
    }
}

// A rank that stops reporting is named silence_s after its last report, whenever that was.
TEST(RankLiveness, ASilentRankIsNamedAfterTheSilenceLimit) {
    RankLiveness live(3, 2.0, 0.0);
    for (double t = 0.1; t <= 30.0; t += 0.1) {
        live.heard(1, t);
        live.heard(3, t);
        if (t < 20.0) live.heard(2, t);  // rank 2 stops (SIGSTOP, cut link) 20 s into a long frame
    }
    EXPECT_TRUE(live.silent(21.9).empty());
    EXPECT_EQ(live.silent(22.1), std::vector<int>{2});
    EXPECT_NEAR(live.silent_for(2, 22.1), 2.2, 0.11);
    // Reports arriving out of order do not move a rank's last report back.
    live.heard(1, 5.0);
    EXPECT_TRUE(live.silent(30.0).empty() || live.silent(30.0) == std::vector<int>{2});
}

// Every rank that owes falling silent within a few beats of each other is the shared machine's
// stall: each is allowed kAllRanksSilentFactor times the limit, and all are named together past it.
TEST(RankLiveness, RanksSilentAllAtOnceAreAllowedTheLongerLimit) {
    RankLiveness live(3, 2.0, 0.0);
    for (double t = 0.1; t <= 10.0; t += 0.1) {
        live.heard(1, t);
        live.heard(2, t + 0.07);  // beats in another phase: the last ones differ by most of a beat
        live.heard(3, t + 0.03);
    }
    const double stalled_until = 10.0 + 2.0 * kAllRanksSilentFactor;
    EXPECT_TRUE(live.silent(12.05).empty()) << "rank 1 past the limit, the others a beat short of it";
    EXPECT_TRUE(live.silent(12.5).empty()) << "all silent 2.5 s: the machine's stall, not three lost hosts";
    EXPECT_TRUE(live.silent(stalled_until - 0.1).empty());
    EXPECT_EQ(live.silent(stalled_until + 0.05), (std::vector<int>{1, 2, 3}));
    EXPECT_DOUBLE_EQ(live.limit_s({1, 2, 3}), 2.0 * kAllRanksSilentFactor);
    EXPECT_DOUBLE_EQ(live.limit_s({2}), 2.0);
}

// When a stall ends the ranks resume one by one: the first heard ends it, and the others, silent past
// the ordinary limit, are judged from its end (allowed its length), not named at once.
TEST(RankLiveness, AfterAStallTheRanksStillSilentAreJudgedFromItsEnd) {
    RankLiveness live(3, 2.0, 0.0);
    for (double t = 0.1; t <= 10.0; t += 0.1) {
        live.heard(1, t);
        live.heard(2, t + 0.07);
        live.heard(3, t + 0.03);
    }
    EXPECT_TRUE(live.silent(13.0).empty());
    live.heard(1, 13.0);  // the stall ends for rank 1 first
    EXPECT_TRUE(live.silent(13.05).empty()) << "ranks 2 and 3 resume a moment later";
    for (double t = 13.05; t < 14.95; t += 0.1) {
        live.heard(1, t);
        live.heard(2, t);
        ASSERT_TRUE(live.silent(t).empty()) << "at " << t << " s";
    }
    EXPECT_EQ(live.silent(15.1), std::vector<int>{3}) << "rank 3 never resumed: named the limit after the stall";
    EXPECT_DOUBLE_EQ(live.limit_s({3}), 2.0);
}

// A lost host's rank beside ranks that keep reporting is named at the ordinary limit.
TEST(RankLiveness, ALostRankBesideReportingRanksGetsTheOrdinaryLimit) {
    RankLiveness live(3, 2.0, 0.0);
    for (double t = 0.1; t <= 3.0; t += 0.1) {
        live.heard(1, t);
        if (t < 1.0) live.heard(2, t);
        live.heard(3, t);
    }
    EXPECT_EQ(live.silent(3.05), std::vector<int>{2});
}

// One rank that owes (the other replied, or a farm of one render rank) gets the ordinary limit: a
// single silence says nothing of the machine.
TEST(RankLiveness, ALoneOwingRankGetsTheOrdinaryLimit) {
    RankLiveness one(1, 2.0, 0.0);
    EXPECT_EQ(one.silent(2.1), std::vector<int>{1});
    RankLiveness two(2, 2.0, 0.0);
    two.replied(1);
    EXPECT_EQ(two.silent(2.1), std::vector<int>{2});
    EXPECT_DOUBLE_EQ(two.limit_s({2}), 2.0);
}

TEST(RankLiveness, RanksThatRepliedOweNothingAndAllowancesExtendTheLimit) {
    RankLiveness live(2, 1.0, 0.0);
    live.replied(1);
    EXPECT_FALSE(live.owes(1));
    EXPECT_TRUE(live.owes(2));
    live.allow(2, 3.0);  // its pixels are on the way
    EXPECT_TRUE(live.silent(3.9).empty());
    EXPECT_EQ(live.silent(4.1), std::vector<int>{2});
    live.replied(2);
    EXPECT_TRUE(live.silent(100.0).empty());
}

TEST(RankLiveness, NoLimitNeverLosesARankAndBadArgumentsAreRefused) {
    RankLiveness never(2, 0.0, 0.0);
    EXPECT_TRUE(never.silent(1e9).empty());
    EXPECT_THROW(RankLiveness(-1, 1.0, 0.0), std::invalid_argument);
    EXPECT_THROW(RankLiveness(1, std::numeric_limits<double>::infinity(), 0.0), std::invalid_argument);
    RankLiveness live(2, 1.0, 0.0);
    EXPECT_THROW(live.heard(0, 1.0), std::invalid_argument);
    EXPECT_THROW(live.heard(3, 1.0), std::invalid_argument);
}

TEST(FullPassSeconds, ExtrapolatesACutPassFromTheTilesDoneAtTheCut) {
    EXPECT_DOUBLE_EQ(full_pass_seconds(0.7, 0.0, 10, 10), 0.7);  // not cut
    EXPECT_DOUBLE_EQ(full_pass_seconds(1.2, 1.0, 25, 100), 4.0);
    EXPECT_DOUBLE_EQ(full_pass_seconds(1.2, 1.0, 0, 100), 100.0);  // not one tile in the budget
    EXPECT_DOUBLE_EQ(full_pass_seconds(0.0, 0.0, 0, 0), 0.0);      // nothing assigned
}

}  // namespace
}  // namespace mogao
