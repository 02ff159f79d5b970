// SPDX-License-Identifier: Apache-2.0
// Caps on connections before authentication (connection_guard.h): real sockets on [::1], real gRPC
// and TLS behind the guard. A peer over a cap is closed before any TLS; an admitted session frees
// its slot; closed connections are counted back to zero; a connection that never opens a session
// is shut down after its maximum age.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <arpa/inet.h>

#include <cerrno>
#include <cstring>
#include <mutex>
#include <vector>

#include "common/unique_fd.h"
#include "renderfarm/link/connection_guard.h"
#include "renderfarm/link/link_client.h"
#include "renderfarm/link/link_server.h"
#include "renderfarm/link/link_test_support.h"

namespace mogao {
namespace {

using namespace testing;

#define REQUIRE_IPV6_LOOPBACK() \
    if (!ipv6_loopback_available()) GTEST_SKIP() << "IPv6 loopback [::1] is not available on this host"

// A plain TCP connection to [::1]:port that never speaks TLS (a port scan, a slow handshake).
UniqueFd raw_connect(std::uint16_t port) {
    UniqueFd fd(::socket(AF_INET6, SOCK_STREAM | SOCK_CLOEXEC, 0));
    EXPECT_TRUE(fd.valid()) << std::strerror(errno);
    sockaddr_in6 addr{};
    addr.sin6_family = AF_INET6;
    addr.sin6_addr = in6addr_loopback;
    addr.sin6_port = htons(port);
    EXPECT_EQ(::connect(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr), 0) << std::strerror(errno);
    return fd;
}

// True when the far end closed (end of stream or reset) within `seconds`; false when the
// connection is still open then. Reads nothing a TLS server would send unasked.
bool closed_by_farm(const UniqueFd& fd, int seconds) {
    timeval limit{seconds, 0};
    ::setsockopt(fd.get(), SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
    char byte = 0;
    ssize_t n = 0;
    do {
        n = ::recv(fd.get(), &byte, 1, 0);
    } while (n < 0 && errno == EINTR);
    return n == 0 || (n < 0 && errno == ECONNRESET);
}

LinkServerOptions capped(int total, int unauthenticated, int per_address) {
    LinkServerOptions o = test_server_options();
    o.connections.max_connections = total;
    o.connections.max_unauthenticated = unauthenticated;
    o.connections.max_unauthenticated_per_address = per_address;
    return o;
}

TEST(ConnectionGuard, AConnectionOverThePerAddressCapIsClosedBeforeAnyTls) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(capped(16, 8, 2), renderer.function());
    const UniqueFd first = raw_connect(server.endpoint().port);
    UniqueFd second = raw_connect(server.endpoint().port);
    const UniqueFd third = raw_connect(server.endpoint().port);
    EXPECT_TRUE(closed_by_farm(third, 5)) << "a third pre-authentication connection from one address was kept";
    EXPECT_FALSE(closed_by_farm(first, 1)) << "a connection under the cap was closed";
    EXPECT_EQ(server.stats().connections.refused_per_address, 1u);
    // One slot free again: an appliance from the same address gets through and is served.
    second.reset();
    ASSERT_TRUE(wait_until([&] { return server.stats().connections.unauthenticated == 1; }));
    const RawOutcome good = raw_session_once(
        tls_channel(server.endpoint().grpc_target(), TestPki::get().appliance_tls(TestPki::get().museum1)));
    EXPECT_TRUE(good.got_frame) << good.status.error_message();
}

TEST(ConnectionGuard, AnAdmittedSessionFreesItsPreAuthenticationSlot) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(capped(16, 8, 1), renderer.function());
    std::mutex mutex;
    int frames = 0;
    LinkClient appliance(test_client_options(server.endpoint().port, TestPki::get().museum1), [&](LinkFrame&&) {
        const std::lock_guard lock(mutex);
        ++frames;
    });
    appliance.submit(test_request());
    ASSERT_TRUE(wait_until([&] {
        const std::lock_guard lock(mutex);
        return frames > 0;
    }));
    EXPECT_EQ(server.stats().connections.unauthenticated, 0u);
    EXPECT_EQ(server.stats().connections.open, 1u);
    const UniqueFd anonymous = raw_connect(server.endpoint().port);
    EXPECT_FALSE(closed_by_farm(anonymous, 1)) << "the appliance's session still held the address's only slot";
    const UniqueFd second = raw_connect(server.endpoint().port);
    EXPECT_TRUE(closed_by_farm(second, 5));
}

TEST(ConnectionGuard, OpenConnectionsAreCappedInAll) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(capped(2, 2, 2), renderer.function());
    const UniqueFd a = raw_connect(server.endpoint().port);
    const UniqueFd b = raw_connect(server.endpoint().port);
    const UniqueFd c = raw_connect(server.endpoint().port);
    EXPECT_TRUE(closed_by_farm(c, 5));
    EXPECT_EQ(server.stats().connections.refused_open, 1u);
    EXPECT_EQ(server.stats().connections.open, 2u);
}

TEST(ConnectionGuard, ClosedConnectionsAreCountedBackToZero) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(test_server_options(), renderer.function());
    for (int i = 0; i < 3; ++i) {
        const RawOutcome good = raw_session_once(
            tls_channel(server.endpoint().grpc_target(), TestPki::get().appliance_tls(TestPki::get().museum1)));
        EXPECT_TRUE(good.got_frame) << good.status.error_message();
        const UniqueFd anonymous = raw_connect(server.endpoint().port);  // closed by us at scope end
    }
    const RawOutcome refused = raw_session_once(
        tls_channel(server.endpoint().grpc_target(), TestPki::get().appliance_tls(TestPki::get().foreign_museum1)));
    EXPECT_FALSE(refused.got_frame);
    // Closed by the client, by gRPC after a failed handshake, or by gRPC after the session: all seen.
    EXPECT_TRUE(wait_until([&] {
        const auto c = server.stats().connections;
        return c.open == 0 && c.unauthenticated == 0;
    })) << "open "
        << server.stats().connections.open << ", unauthenticated " << server.stats().connections.unauthenticated;
    EXPECT_GE(server.stats().connections.accepted, 7u);
}

TEST(ConnectionGuard, AConnectionWithoutASessionIsShutDownAfterItsMaxAge) {
    REQUIRE_IPV6_LOOPBACK();
    std::mutex mutex;
    std::vector<UniqueFd> held;  // stands in for gRPC: keeps the connection, never closes it
    ConnectionLimits limits;
    limits.unauthenticated_max_age_s = 1.0;
    ConnectionGuard guard(Endpoint{"::1", 0}, limits, [&](UniqueFd fd, int) {
        const std::lock_guard lock(mutex);
        held.push_back(std::move(fd));
    });
    const UniqueFd peer = raw_connect(guard.port());
    EXPECT_TRUE(closed_by_farm(peer, 10)) << "the guard left a connection without a session open";
    EXPECT_EQ(guard.stats().aged_out, 1u);
    EXPECT_TRUE(wait_until([&] { return guard.stats().open == 0; }));
}

TEST(ConnectionGuard, PeersAreNamedAsGrpcNamesThem) {
    sockaddr_in6 v6{};
    v6.sin6_family = AF_INET6;
    ASSERT_EQ(::inet_pton(AF_INET6, "2001:db8::5", &v6.sin6_addr), 1);
    v6.sin6_port = htons(7443);
    EXPECT_EQ(grpc_peer_name(v6), "ipv6:[2001:db8::5]:7443");
    ASSERT_EQ(::inet_pton(AF_INET6, "::ffff:192.0.2.7", &v6.sin6_addr), 1);
    EXPECT_EQ(grpc_peer_name(v6), "ipv4:192.0.2.7:7443");
}

TEST(ConnectionGuard, BadLimitsAreNamed) {
    const auto expect_error = [](ConnectionLimits limits, const char* needle) {
        try {
            ConnectionGuard guard(Endpoint{"::1", 0}, limits, [](UniqueFd, int) {});
            ADD_FAILURE() << "started with bad limits; expected: " << needle;
        } catch (const LinkError& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    ConnectionLimits l;
    l.max_connections = 0;
    expect_error(l, "max_connections");
    l = {};
    l.max_unauthenticated = l.max_connections + 1;
    expect_error(l, "max_unauthenticated");
    l = {};
    l.max_unauthenticated_per_address = l.max_unauthenticated + 1;
    expect_error(l, "max_unauthenticated_per_address");
    l = {};
    l.unauthenticated_max_age_s = 0.0;
    expect_error(l, "unauthenticated_max_age_s");
}

}  // namespace
}  // namespace mogao
