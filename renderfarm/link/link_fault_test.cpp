// SPDX-License-Identifier: Apache-2.0
// The farm going away and coming back: the appliance reconnects by itself and never shows a frame
// older than one it already showed.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "renderfarm/link/link_client.h"
#include "renderfarm/link/link_server.h"
#include "renderfarm/link/link_test_support.h"

namespace mogao {
namespace {

using namespace testing;

#define REQUIRE_IPV6_LOOPBACK() \
    if (!ipv6_loopback_available()) GTEST_SKIP() << "IPv6 loopback [::1] is not available on this host"

TEST(LinkFault, ClientReconnectsToARestartedFarmAndIdsKeepIncreasing) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    auto farm = std::make_unique<LinkServer>(test_server_options(), renderer.function());
    const std::uint16_t port = farm->endpoint().port;

    std::mutex mutex;
    std::vector<std::uint64_t> ids;
    std::vector<std::string> problems;
    LinkClient client(test_client_options(port, TestPki::get().museum1), [&](LinkFrame&& f) {
        const auto mark = read_mark(f.jpeg);
        const std::lock_guard lock(mutex);
        if (!mark || mark->request_id != f.request_id)
            problems.push_back("wrong pixels for " + std::to_string(f.request_id));
        ids.push_back(f.request_id);
    });
    // The tracker keeps sending poses whatever the link's state.
    std::atomic<bool> feeding{true};
    std::jthread feeder([&] {
        for (int i = 0; feeding; ++i) {
            client.submit(test_request(0.01 * i));
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
    });
    const auto frames = [&] {
        const std::lock_guard lock(mutex);
        return ids.size();
    };
    ASSERT_TRUE(wait_until([&] { return frames() >= 10; }));

    farm->stop();  // mid-stream
    farm.reset();
    ASSERT_TRUE(wait_until([&] { return !client.stats().connected && client.stats().attempts_failed >= 2; }))
        << "the client should notice and retry with backoff";
    const std::size_t before_restart = frames();
    const std::uint64_t last_before = client.stats().last_request_id;

    farm = std::make_unique<LinkServer>(test_server_options("[::1]:" + std::to_string(port)), renderer.function());
    ASSERT_TRUE(wait_until([&] { return farm->stats().frames_sent >= 10; })) << "no reconnect";
    feeding = false;
    feeder.join();

    const LinkClientStats stats = client.stats();
    EXPECT_EQ(stats.sessions_opened, 2u);
    EXPECT_TRUE(stats.connected);
    const std::lock_guard lock(mutex);
    for (const auto& p : problems) ADD_FAILURE() << p;
    ASSERT_GT(ids.size(), before_restart);
    EXPECT_GT(ids[before_restart], last_before);
    for (std::size_t i = 1; i < ids.size(); ++i) EXPECT_LT(ids[i - 1], ids[i]) << "frame " << i << " out of order";
}

TEST(LinkFault, UnansweredRequestIsResentAfterReconnect) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    auto farm = std::make_unique<LinkServer>(test_server_options(), renderer.function());
    const std::uint16_t port = farm->endpoint().port;
    LinkClient client(test_client_options(port, TestPki::get().museum1), [](LinkFrame&&) {});
    ASSERT_TRUE(wait_until([&] { return client.stats().connected; }));
    farm.reset();  // destructor stops
    ASSERT_TRUE(wait_until([&] { return client.stats().attempts_failed >= 1; }));
    // Submitted while the farm is down; nobody calls submit again.
    const auto id = client.submit(test_request(5.0));
    farm = std::make_unique<LinkServer>(test_server_options("[::1]:" + std::to_string(port)), renderer.function());
    ASSERT_TRUE(wait_until([&] { return client.stats().last_request_id == id; }));
}

TEST(LinkFault, ClientStopsWhileNoFarmIsThere) {
    REQUIRE_IPV6_LOOPBACK();
    std::uint16_t port = 0;
    {
        SyntheticRenderer renderer;
        LinkServer probe(test_server_options(), renderer.function());
        port = probe.endpoint().port;  // free again once probe is gone
    }
    LinkClient client(test_client_options(port, TestPki::get().museum1), [](LinkFrame&&) {});
    ASSERT_TRUE(wait_until([&] { return client.stats().attempts_failed >= 2; }));
    client.stop();  // returns: nothing blocks on the absent farm
    EXPECT_FALSE(client.stats().connected);
}

TEST(LinkFault, FarmStopsWhileTheRendererIsBusy) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer farm(test_server_options(), renderer.function());
    LinkClient client(test_client_options(farm.endpoint().port, TestPki::get().museum1), [](LinkFrame&&) {});
    const auto hold = renderer.hold();
    client.submit(test_request());
    ASSERT_TRUE(wait_until([&] { return renderer.blocked() == 1; }));
    std::jthread releaser([&] {
        // stop() waits for the renderer call in progress; let it finish once stop has begun.
        wait_until([&] { return !client.stats().connected; });
        renderer.release();
    });
    farm.stop();
    EXPECT_EQ(farm.stats().sessions_active, 0u);
    EXPECT_EQ(farm.stats().frames_sent, 0u);
}

}  // namespace
}  // namespace mogao
