// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/render_threads.h"

#include <sched.h>

#include <gtest/gtest.h>

namespace mogao {
namespace {

TEST(RenderThreads, AHostsCpusAreSharedAmongItsRenderRanks) {
    EXPECT_EQ(threads_per_render_rank(2, 1), 2);   // this machine: admin + one render rank
    EXPECT_EQ(threads_per_render_rank(2, 2), 1);   // admin + two render ranks, as before
    EXPECT_EQ(threads_per_render_rank(16, 3), 5);  // the remainder stays free (the admin's share)
    EXPECT_EQ(threads_per_render_rank(64, 1), 64);
}

TEST(RenderThreads, NeverFewerThanOneThread) {
    EXPECT_EQ(threads_per_render_rank(2, 4), 1);  // more ranks than CPUs (oversubscribed)
    EXPECT_EQ(threads_per_render_rank(0, 0), 1);
    EXPECT_EQ(threads_per_render_rank(-3, 2), 1);
}

TEST(RenderThreads, UsableCpusFollowTheAffinityMask) {
    cpu_set_t all;
    ASSERT_EQ(sched_getaffinity(0, sizeof(all), &all), 0);
    EXPECT_EQ(usable_cpus(), CPU_COUNT(&all));
    // Pinned to one CPU (as taskset or a cpuset would), the count follows.
    int first = 0;
    while (!CPU_ISSET(first, &all)) ++first;
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(first, &one);
    ASSERT_EQ(sched_setaffinity(0, sizeof(one), &one), 0);
    EXPECT_EQ(usable_cpus(), 1);
    ASSERT_EQ(sched_setaffinity(0, sizeof(all), &all), 0);
}

}  // namespace
}  // namespace mogao
