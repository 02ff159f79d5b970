// SPDX-License-Identifier: Apache-2.0
// Frames over real gRPC + mutual TLS on [::1]: delivery, newest-request-wins, flow control,
// concurrent sessions, bad requests and renderer failures.
#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>

#include "renderfarm/link/link_client.h"
#include "renderfarm/link/link_server.h"
#include "renderfarm/link/link_test_support.h"
#include "renderfarm/link/wire_convert.h"

namespace mogao {
namespace {

using namespace testing;
namespace v1 = link::v1;

#define REQUIRE_IPV6_LOOPBACK() \
    if (!ipv6_loopback_available()) GTEST_SKIP() << "IPv6 loopback [::1] is not available on this host"

// Collects what the client delivers, checking each frame's pixels against its request id.
struct Received {
    std::mutex mutex;
    std::vector<LinkFrame> frames;
    std::vector<std::string> problems;

    FrameCallback callback() {
        return [this](LinkFrame&& f) {
            const auto mark = read_mark(f.jpeg);
            const std::lock_guard lock(mutex);
            if (!mark) problems.push_back("frame " + std::to_string(f.frame_id) + " does not decode");
            else if (mark->request_id != f.request_id)
                problems.push_back("frame for request " + std::to_string(f.request_id) + " shows request " +
                                   std::to_string(mark->request_id));
            else if (mark->yaw_centideg != static_cast<std::int32_t>(std::lround(f.pose.yaw_deg * 100.0)))
                problems.push_back("frame for request " + std::to_string(f.request_id) + " shows another pose");
            f.jpeg.clear();
            frames.push_back(std::move(f));
        };
    }
    std::vector<std::uint64_t> request_ids() {
        const std::lock_guard lock(mutex);
        std::vector<std::uint64_t> ids;
        for (const auto& f : frames) ids.push_back(f.request_id);
        return ids;
    }
    void expect_clean_and_increasing() {
        const auto ids = request_ids();
        for (std::size_t i = 1; i < ids.size(); ++i) EXPECT_LT(ids[i - 1], ids[i]) << "at frame " << i;
        const std::lock_guard lock(mutex);
        for (const auto& p : problems) ADD_FAILURE() << p;
    }
};

TEST(LinkStream, DeliversOneFrameForEachOf100Requests) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(test_server_options(), renderer.function());
    Received received;
    LinkClient client(test_client_options(server.endpoint().port, TestPki::get().museum1), received.callback());
    constexpr int kFrames = 100;
    for (int i = 0; i < kFrames; ++i) {
        // Lock-step: each request waits for its frame, so none is dropped and every id is answered.
        const std::uint64_t id = client.submit(test_request(0.25 * i, 640, 360));
        ASSERT_EQ(id, static_cast<std::uint64_t>(i + 1));
        ASSERT_TRUE(wait_until([&] { return client.stats().last_request_id == id; })) << "no frame for request " << id;
    }
    received.expect_clean_and_increasing();
    const auto ids = received.request_ids();
    ASSERT_EQ(ids.size(), static_cast<std::size_t>(kFrames));
    const LinkClientStats cs = client.stats();
    EXPECT_EQ(cs.frames_received, static_cast<std::uint64_t>(kFrames));
    EXPECT_EQ(cs.frames_discarded, 0u);
    EXPECT_TRUE(cs.connected);
    EXPECT_EQ(cs.sessions_opened, 1u);
    EXPECT_GT(cs.fps, 0.0);
    EXPECT_GT(cs.bandwidth_bytes_per_s, 0.0);
    EXPECT_GT(cs.mean_latency_ms, 0.0);
    // The farm counts a frame once its write completes, which can be just after the appliance has
    // read it: wait for the count rather than race it.
    EXPECT_TRUE(wait_until([&] { return server.stats().frames_sent == static_cast<std::uint64_t>(kFrames); }))
        << "frames_sent = " << server.stats().frames_sent;
    const LinkServerStats ss = server.stats();
    EXPECT_EQ(ss.requests_dropped, 0u);
    {
        const std::lock_guard lock(received.mutex);
        for (const auto& f : received.frames) {
            EXPECT_EQ(f.size, (ImageSize{640, 360}));
            // Stages in order on the farm's clock; request and receipt on the appliance's.
            EXPECT_LE(f.times.received_ns, f.times.render_start_ns);
            EXPECT_LE(f.times.render_start_ns, f.times.render_end_ns);
            EXPECT_LE(f.times.render_end_ns, f.times.encode_end_ns);
            EXPECT_LE(f.times.encode_end_ns, f.times.send_ns);
            EXPECT_LE(f.times.request_ns, f.times.receive_ns);
        }
    }
    // Figures for docs/link.md (loopback, lock-step, 640x360 JPEG q90).
    std::printf("loopback lock-step 640x360: %.1f fps, latency mean %.2f ms max %.2f ms, %.0f bytes/frame, %.2f MB/s\n",
                cs.fps, cs.mean_latency_ms, cs.max_latency_ms, cs.mean_frame_bytes, cs.bandwidth_bytes_per_s / 1e6);
}

TEST(LinkStream, StreamsAt720pFromAFastTracker) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(test_server_options(), renderer.function());
    std::atomic<std::uint64_t> last{0};
    std::atomic<bool> ordered{true};
    LinkClient client(test_client_options(server.endpoint().port, TestPki::get().museum1), [&](LinkFrame&& f) {
        if (f.request_id <= last) ordered = false;
        last = f.request_id;
    });
    // A tracker at ~500 Hz, faster than the farm: the link must keep latency bounded by dropping.
    std::atomic<bool> feeding{true};
    std::jthread feeder([&] {
        for (int i = 0; feeding; ++i) {
            client.submit(test_request(0.05 * i, 1280, 720));
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
    });
    ASSERT_TRUE(wait_until([&] { return client.stats().frames_received >= 60; }));
    feeding = false;
    feeder.join();
    EXPECT_TRUE(ordered);
    const auto cs = client.stats();
    const auto ss = server.stats();
    EXPECT_EQ(cs.frames_discarded, 0u);
    EXPECT_GT(ss.requests_dropped + cs.requests_coalesced, 0u);
    std::printf(
        "loopback streaming 1280x720 (tracker 500 Hz): %.1f fps, latency mean %.2f ms max %.2f ms, "
        "%.0f bytes/frame, %.2f MB/s; %llu requests dropped on the farm, %llu coalesced in the client\n",
        cs.fps, cs.mean_latency_ms, cs.max_latency_ms, cs.mean_frame_bytes, cs.bandwidth_bytes_per_s / 1e6,
        static_cast<unsigned long long>(ss.requests_dropped), static_cast<unsigned long long>(cs.requests_coalesced));
}

TEST(LinkStream, NewestRequestWinsWhileTheRendererIsBusy) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(test_server_options(), renderer.function());
    Received received;
    LinkClient client(test_client_options(server.endpoint().port, TestPki::get().museum1), received.callback());
    const auto hold = renderer.hold();
    ASSERT_EQ(client.submit(test_request(1.0)), 1u);
    ASSERT_TRUE(wait_until([&] { return renderer.blocked() == 1; }));  // request 1 is being rendered
    // Each request reaches the farm before the next is submitted, so the farm (not the client's
    // own coalescing) has to drop requests 2..9.
    for (std::uint64_t i = 2; i <= 10; ++i) {
        ASSERT_EQ(client.submit(test_request(static_cast<double>(i))), i);
        ASSERT_TRUE(wait_until([&] { return server.stats().requests_received == i; })) << "request " << i;
    }
    renderer.release();
    ASSERT_TRUE(wait_until([&] { return client.stats().last_request_id == 10; }));
    EXPECT_EQ(received.request_ids(), (std::vector<std::uint64_t>{1, 10}));
    EXPECT_EQ(renderer.rendered_ids(), (std::vector<std::uint64_t>{1, 10}));
    EXPECT_EQ(server.stats().requests_dropped, 8u);
    EXPECT_EQ(client.stats().requests_coalesced, 0u);
    received.expect_clean_and_increasing();
}

// A renderer that queues its calls (the farm: one main thread serves every session's call in turn) takes the
// session's newest request when it starts on a call: the frame shows that view and answers that request, the
// one the call was made for counts as dropped. Without the take-over the frame would answer request 1, as old
// as the wait in the queue.
TEST(LinkStream, ARendererThatQueuesItsCallsAnswersTheNewestRequestTakenOver) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer synthetic;
    std::atomic<LinkServer*> link{nullptr};
    std::mutex mutex;
    std::condition_variable cv;
    bool go = false;
    int waiting = 0;
    const FrameRenderer queued = [&](const ViewRequest& r) {
        {
            std::unique_lock lock(mutex);
            ++waiting;
            cv.wait(lock, [&] { return go; });  // the call waits its turn
        }
        const std::optional<ViewRequest> newer = link.load()->take_newer_request(r.session);
        return synthetic(newer ? *newer : r);
    };
    LinkServer server(test_server_options(), queued);
    link = &server;
    Received received;
    LinkClient client(test_client_options(server.endpoint().port, TestPki::get().museum1), received.callback());
    ASSERT_EQ(client.submit(test_request(1.0)), 1u);
    ASSERT_TRUE(wait_until([&] {
        const std::lock_guard lock(mutex);
        return waiting == 1;
    }));
    for (std::uint64_t i = 2; i <= 5; ++i) {
        ASSERT_EQ(client.submit(test_request(static_cast<double>(i))), i);
        ASSERT_TRUE(wait_until([&] { return server.stats().requests_received == i; })) << "request " << i;
    }
    {
        const std::lock_guard lock(mutex);
        go = true;
    }
    cv.notify_all();
    ASSERT_TRUE(wait_until([&] { return received.request_ids().size() == 1; }));
    EXPECT_EQ(received.request_ids(), (std::vector<std::uint64_t>{5}));
    EXPECT_EQ(synthetic.rendered_ids(), (std::vector<std::uint64_t>{5}));
    EXPECT_EQ(server.stats().requests_dropped, 4u);  // 2, 3 replaced while pending; 1 taken over by 5
    {
        const std::lock_guard lock(received.mutex);
        EXPECT_DOUBLE_EQ(received.frames.at(0).pose.yaw_deg, 5.0);
    }
    // Nothing newer: the call renders the request it was made for.
    ASSERT_EQ(client.submit(test_request(6.0)), 6u);
    ASSERT_TRUE(wait_until([&] { return received.request_ids().size() == 2; }));
    EXPECT_EQ(received.request_ids(), (std::vector<std::uint64_t>{5, 6}));
    EXPECT_EQ(server.stats().requests_dropped, 4u);
    EXPECT_FALSE(server.take_newer_request(12345).has_value());  // no such session
    received.expect_clean_and_increasing();
}

TEST(LinkStream, SlowFarmAnswersIncreasingRequestsAndTheLastOne) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    renderer.set_delay(std::chrono::milliseconds(3));
    LinkServer server(test_server_options(), renderer.function());
    Received received;
    LinkClient client(test_client_options(server.endpoint().port, TestPki::get().museum1), received.callback());
    std::uint64_t last = 0;
    for (int i = 0; i < 300; ++i) {
        last = client.submit(test_request(0.1 * i));
        if (i % 10 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));  // a tracker's pace, roughly
    }
    ASSERT_TRUE(wait_until([&] { return client.stats().last_request_id == last; }));
    received.expect_clean_and_increasing();
    const auto ids = received.request_ids();
    EXPECT_EQ(ids.back(), last);
    const auto ss = server.stats();
    const auto cs = client.stats();
    // Each request was either rendered, dropped on the farm, or coalesced in the client.
    EXPECT_EQ(ss.render_calls + ss.requests_dropped + cs.requests_coalesced, 300u);
    std::printf("slow farm (3 ms/frame): 300 requests -> %zu frames, %llu dropped on the farm, %llu coalesced\n",
                ids.size(), static_cast<unsigned long long>(ss.requests_dropped),
                static_cast<unsigned long long>(cs.requests_coalesced));
}

TEST(LinkStream, AtMostTwoFramesInFlightUntilAcknowledged) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(test_server_options(), renderer.function());
    // A raw stream that acknowledges only when told to.
    auto stub = v1::Tour::NewStub(
        tls_channel(server.endpoint().grpc_target(), TestPki::get().appliance_tls(TestPki::get().museum1)));
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    auto stream = stub->Session(&ctx);
    const auto send = [&](std::uint64_t id, std::uint64_t ack) {
        ViewRequest r = test_request(static_cast<double>(id));
        r.frame_id = id;
        v1::ViewRequestMsg msg;
        if (id != 0) view_to_msg(r, msg);
        msg.set_ack_frame_id(ack);
        ASSERT_TRUE(stream->Write(msg));
    };
    v1::FrameMsg frame;
    send(1, 0);
    ASSERT_TRUE(stream->Read(&frame));
    EXPECT_EQ(frame.request_id(), 1u);
    send(2, 0);
    ASSERT_TRUE(stream->Read(&frame));
    EXPECT_EQ(frame.request_id(), 2u);
    // Two unacknowledged frames: request 3 must wait, and request 4 replaces it.
    send(3, 0);
    send(4, 0);
    ASSERT_TRUE(wait_until([&] { return server.stats().requests_received == 4; }));
    EXPECT_EQ(server.stats().requests_dropped, 1u);
    EXPECT_EQ(server.stats().render_calls, 2u);
    send(0, 1);  // acknowledge frame 1: one slot frees
    ASSERT_TRUE(stream->Read(&frame));
    EXPECT_EQ(frame.request_id(), 4u);
    EXPECT_EQ(frame.frame_id(), 3u);
    EXPECT_EQ(renderer.rendered_ids(), (std::vector<std::uint64_t>{1, 2, 4}));
    // Stale and replayed ids are dropped, never rendered.
    send(4, 3);
    send(2, 0);
    ASSERT_TRUE(wait_until([&] { return server.stats().requests_dropped == 3; }));
    send(5, 0);
    ASSERT_TRUE(stream->Read(&frame));
    EXPECT_EQ(frame.request_id(), 5u);
    ctx.TryCancel();
    static_cast<void>(stream->Finish());
}

TEST(LinkStream, TwoConcurrentSessionsEachGetTheirOwnFrames) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(test_server_options(), renderer.function());
    Received a, b;
    LinkClient one(test_client_options(server.endpoint().port, TestPki::get().museum1), a.callback());
    LinkClient two(test_client_options(server.endpoint().port, TestPki::get().museum2), b.callback());
    ASSERT_TRUE(wait_until([&] { return server.stats().sessions_active == 2; }));
    const auto drive = [](LinkClient& client, double yaw_base, std::atomic<bool>& ok) {
        for (int i = 0; i < 30; ++i) {
            const auto id = client.submit(test_request(yaw_base + i));
            if (!wait_until([&] { return client.stats().last_request_id == id; })) return;
        }
        ok = true;
    };
    std::atomic<bool> ok_one{false}, ok_two{false};
    {
        std::jthread t1([&] { drive(one, 0.0, ok_one); });
        std::jthread t2([&] { drive(two, 100.0, ok_two); });
    }
    EXPECT_TRUE(ok_one);
    EXPECT_TRUE(ok_two);
    a.expect_clean_and_increasing();
    b.expect_clean_and_increasing();
    EXPECT_EQ(a.request_ids().size(), 30u);
    EXPECT_EQ(b.request_ids().size(), 30u);
    {
        // Each session got its own poses: yaw base 0 vs 100.
        const std::lock_guard la(a.mutex), lb(b.mutex);
        for (const auto& f : a.frames) EXPECT_LT(f.pose.yaw_deg, 50.0);
        for (const auto& f : b.frames) EXPECT_GE(f.pose.yaw_deg, 100.0);
    }
    EXPECT_EQ(server.stats().sessions_opened, 2u);
    EXPECT_TRUE(wait_until([&] { return server.stats().frames_sent == 60u; }))  // counted after the write completes
        << "frames_sent = " << server.stats().frames_sent;
}

TEST(LinkStream, InvalidRequestIsRefusedAndTheSessionContinues) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(test_server_options(), renderer.function());
    auto stub = v1::Tour::NewStub(
        tls_channel(server.endpoint().grpc_target(), TestPki::get().appliance_tls(TestPki::get().museum1)));
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    auto stream = stub->Session(&ctx);
    ViewRequest bad = test_request();
    bad.frame_id = 1;
    bad.quality.spp = 0;
    v1::ViewRequestMsg msg;
    view_to_msg(bad, msg);
    ASSERT_TRUE(stream->Write(msg));
    ASSERT_TRUE(stream->Write(v1::ViewRequestMsg{}));  // empty: an ack of nothing, harmless
    msg.Clear();
    msg.set_request_id(2);  // a view with no pose, camera or quality
    ASSERT_TRUE(stream->Write(msg));
    ViewRequest good = test_request(7.0);
    good.frame_id = 3;
    view_to_msg(good, msg);
    ASSERT_TRUE(stream->Write(msg));
    v1::FrameMsg frame;
    ASSERT_TRUE(stream->Read(&frame));
    EXPECT_EQ(frame.request_id(), 3u);
    EXPECT_EQ(server.stats().requests_invalid, 2u);
    EXPECT_EQ(server.stats().sessions_opened, 1u);
    ctx.TryCancel();
    static_cast<void>(stream->Finish());
}

TEST(LinkStream, ClientRefusesInvalidRequestsBeforeSending) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(test_server_options(), renderer.function());
    Received received;
    LinkClient client(test_client_options(server.endpoint().port, TestPki::get().museum1), received.callback());
    ViewRequest bad = test_request();
    bad.quality.resolution_scale = 2.0;
    std::string error;
    EXPECT_EQ(client.submit(bad, &error), 0u);
    EXPECT_NE(error.find("quality.resolution_scale"), std::string::npos) << error;
    EXPECT_EQ(client.submit(test_request()), 1u);  // ids are not consumed by refused requests
    ASSERT_TRUE(wait_until([&] { return client.stats().last_request_id == 1; }));
    EXPECT_EQ(server.stats().requests_invalid, 0u);
}

TEST(LinkStream, RendererFailureCostsOnlyThatRequest) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(test_server_options(), renderer.function());
    Received received;
    LinkClient client(test_client_options(server.endpoint().port, TestPki::get().museum1), received.callback());
    ViewRequest poisoned = test_request();
    poisoned.seed = kPoisonSeed;
    client.submit(poisoned);
    ASSERT_TRUE(wait_until([&] { return server.stats().render_failures == 1; }));
    ViewRequest too_small = test_request(0.0, 64, 32);  // the synthetic renderer throws invalid_argument
    client.submit(too_small);
    ASSERT_TRUE(wait_until([&] { return server.stats().render_failures == 2; }));
    const auto id = client.submit(test_request(3.0));
    ASSERT_TRUE(wait_until([&] { return client.stats().last_request_id == id; }));
    EXPECT_EQ(received.request_ids(), (std::vector<std::uint64_t>{3}));
    EXPECT_EQ(server.stats().sessions_opened, 1u);
    EXPECT_EQ(client.stats().sessions_opened, 1u);
    received.expect_clean_and_increasing();
}

}  // namespace
}  // namespace mogao
