// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/main_thread_queue.h"

#include <gtest/gtest.h>

namespace mogao {
namespace {

ViewRequest request(std::uint64_t session, std::uint64_t id) {
    ViewRequest v;
    v.session = session;
    v.frame_id = id;
    return v;
}

TEST(MainThreadQueue, ASupersededRequestIsNeverRendered) {
    MainThreadQueue<std::uint64_t> queue;
    std::future<std::uint64_t> old_a = queue.push(request(1, 1));
    std::future<std::uint64_t> b = queue.push(request(2, 1));
    std::future<std::uint64_t> new_a = queue.push(request(1, 2));
    EXPECT_THROW(old_a.get(), SupersededError);  // failed at once, before the main thread looked
    EXPECT_EQ(queue.superseded(), 1u);
    std::vector<std::uint64_t> rendered;
    while (auto job = queue.next(std::chrono::milliseconds(0))) {
        rendered.push_back(job->view.session * 100 + job->view.frame_id);
        job->result.set_value(job->view.frame_id);
    }
    // Session 2 first (it waited longer), then session 1's newest; session 1's request 1 never.
    EXPECT_EQ(rendered, (std::vector<std::uint64_t>{201, 102}));
    EXPECT_EQ(new_a.get(), 2u);
    EXPECT_EQ(b.get(), 1u);
}

TEST(MainThreadQueue, CloseFailsWaitingRequestsAndRefusesNewOnes) {
    MainThreadQueue<int> queue;
    std::future<int> waiting = queue.push(request(1, 1));
    queue.close();
    EXPECT_THROW(waiting.get(), std::runtime_error);
    EXPECT_THROW((void)queue.push(request(1, 2)), std::runtime_error);
    EXPECT_FALSE(queue.next(std::chrono::milliseconds(0)).has_value());
}

}  // namespace
}  // namespace mogao
