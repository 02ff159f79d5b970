// SPDX-License-Identifier: Apache-2.0
// Who gets frames: only appliances with a certificate from the farm CA, over TLS, over IPv6.
// Garbage and oversized input end one connection or session, never the farm.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include "common/unique_fd.h"
#include "renderfarm/link/link_client.h"
#include "renderfarm/link/link_server.h"
#include "renderfarm/link/link_test_support.h"
#include "renderfarm/link/revocation.h"
#include "renderfarm/link/wire_convert.h"

namespace mogao {
namespace {

using namespace testing;
namespace v1 = link::v1;

#define REQUIRE_IPV6_LOOPBACK() \
    if (!ipv6_loopback_available()) GTEST_SKIP() << "IPv6 loopback [::1] is not available on this host"

class LinkSecurity : public ::testing::Test {
protected:
    void SetUp() override {
        if (!ipv6_loopback_available()) GTEST_SKIP() << "IPv6 loopback [::1] is not available on this host";
        server_ = std::make_unique<LinkServer>(test_server_options(), renderer_.function());
    }
    [[nodiscard]] std::string target() const { return server_->endpoint().grpc_target(); }
    // A good appliance still gets a frame: the positive control of every refusal below.
    void expect_good_client_served() {
        const RawOutcome good =
            raw_session_once(tls_channel(target(), TestPki::get().appliance_tls(TestPki::get().museum1)));
        EXPECT_TRUE(good.got_frame) << good.status.error_message();
    }
    void expect_refused(const TlsMaterial& tls, const char* what) {
        const auto before = server_->stats();
        const RawOutcome outcome = raw_session_once(tls_channel(target(), tls));
        EXPECT_FALSE(outcome.got_frame) << what;
        EXPECT_FALSE(outcome.status.ok()) << what;
        EXPECT_EQ(outcome.status.error_code(), grpc::StatusCode::UNAVAILABLE)
            << what << ": " << outcome.status.error_message();
        EXPECT_EQ(server_->stats().sessions_opened, before.sessions_opened) << what << " reached the session handler";
        EXPECT_EQ(server_->stats().render_calls, before.render_calls) << what;
    }

    void expect_refused_by_revocation(const PemPair& who) {
        const RawOutcome outcome = raw_session_once(tls_channel(target(), TestPki::get().appliance_tls(who)));
        EXPECT_FALSE(outcome.got_frame);
        EXPECT_EQ(outcome.status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << outcome.status.error_message();
    }

    SyntheticRenderer renderer_;
    std::unique_ptr<LinkServer> server_;
};

TEST_F(LinkSecurity, GoodApplianceIsServed) { expect_good_client_served(); }

TEST_F(LinkSecurity, ClientWithoutCertificateIsRefused) {
    expect_refused({TestPki::get().ca.cert_pem, "", ""}, "no client certificate");
    expect_good_client_served();
}

TEST_F(LinkSecurity, CertificateFromAnotherCaIsRefused) {
    const auto& pki = TestPki::get();
    // Trusts our farm, presents a museum-1 certificate signed by someone else.
    expect_refused({pki.ca.cert_pem, pki.foreign_museum1.cert_pem, pki.foreign_museum1.key_pem}, "foreign CA");
    expect_good_client_served();
}

TEST_F(LinkSecurity, ExpiredCertificateIsRefused) {
    expect_refused(TestPki::get().appliance_tls(TestPki::get().expired), "expired certificate");
    expect_good_client_served();
}

TEST_F(LinkSecurity, FarmCertificateCannotActAsAnAppliance) {
    const auto& pki = TestPki::get();
    expect_refused({pki.ca.cert_pem, pki.farm.cert_pem, pki.farm.key_pem}, "serverAuth-only certificate as client");
}

TEST_F(LinkSecurity, PlaintextClientIsRefused) {
    grpc::ChannelArguments args;
    args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
    const RawOutcome outcome =
        raw_session_once(grpc::CreateCustomChannel(target(), grpc::InsecureChannelCredentials(), args));
    EXPECT_FALSE(outcome.got_frame);
    EXPECT_FALSE(outcome.status.ok());
    EXPECT_EQ(server_->stats().sessions_opened, 0u);
    expect_good_client_served();
}

TEST_F(LinkSecurity, LinkClientWithExpiredCertificateKeepsBackingOffAndGetsNothing) {
    int frames = 0;
    LinkClient client(test_client_options(server_->endpoint().port, TestPki::get().expired),
                      [&](LinkFrame&&) { ++frames; });
    client.submit(test_request());
    ASSERT_TRUE(wait_until([&] { return client.stats().attempts_failed >= 3; }));
    const auto stats = client.stats();
    EXPECT_EQ(stats.sessions_opened, 0u);
    EXPECT_EQ(stats.frames_received, 0u);
    EXPECT_FALSE(stats.connected);
    EXPECT_GT(stats.next_backoff, std::chrono::milliseconds(20));   // it doubled
    EXPECT_LE(stats.next_backoff, std::chrono::milliseconds(200));  // up to the cap
    EXPECT_EQ(server_->stats().sessions_opened, 0u);
    client.stop();
    EXPECT_EQ(frames, 0);
}

TEST_F(LinkSecurity, ClientRefusesAFarmWhoseCertificateDoesNotNameIt) {
    auto options = test_client_options(server_->endpoint().port, TestPki::get().museum1);
    options.server_name = "some-other-farm";  // the farm certificate has farm-test, ::1, 127.0.0.1
    LinkClient client(options, [](LinkFrame&&) {});
    client.submit(test_request());
    ASSERT_TRUE(wait_until([&] { return client.stats().attempts_failed >= 2; }));
    EXPECT_EQ(client.stats().frames_received, 0u);
    EXPECT_EQ(server_->stats().sessions_opened, 0u);
}

TEST_F(LinkSecurity, ClientAcceptsTheFarmByDnsName) {
    auto options = test_client_options(server_->endpoint().port, TestPki::get().museum1);
    options.server_name = "farm-test";
    LinkClient client(options, [](LinkFrame&&) {});
    const auto id = client.submit(test_request());
    EXPECT_TRUE(wait_until([&] { return client.stats().last_request_id == id; }));
}

TEST_F(LinkSecurity, GarbageBytesAreRefusedAndTheFarmKeepsServing) {
    const UniqueFd fd(::socket(AF_INET6, SOCK_STREAM | SOCK_CLOEXEC, 0));
    ASSERT_TRUE(fd.valid()) << std::strerror(errno);
    sockaddr_in6 addr{};
    addr.sin6_family = AF_INET6;
    addr.sin6_addr = in6addr_loopback;
    addr.sin6_port = htons(server_->endpoint().port);
    ASSERT_EQ(::connect(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr), 0) << std::strerror(errno);
    timeval guard{30, 0};  // hang guard only: the farm answers garbage by closing long before
    ASSERT_EQ(::setsockopt(fd.get(), SOL_SOCKET, SO_RCVTIMEO, &guard, sizeof guard), 0);
    std::string garbage = "GET / HTTP/1.1\r\nHost: farm\r\n\r\n";
    for (int i = 0; i < 4096; ++i) garbage.push_back(static_cast<char>((i * 7919) & 0xff));
    ASSERT_EQ(::send(fd.get(), garbage.data(), garbage.size(), MSG_NOSIGNAL), static_cast<ssize_t>(garbage.size()));
    char buffer[4096];
    ssize_t n = 0;
    do {
        n = ::recv(fd.get(), buffer, sizeof buffer, 0);  // a TLS alert may come before the close
    } while (n > 0 || (n < 0 && errno == EINTR));
    EXPECT_TRUE(n == 0 || errno == ECONNRESET) << "the farm did not close the connection: " << std::strerror(errno);
    EXPECT_EQ(server_->stats().sessions_opened, 0u);
    expect_good_client_served();
}

TEST_F(LinkSecurity, OversizedMessageEndsOnlyThatSession) {
    std::vector<std::uint64_t> delivered;
    std::mutex mutex;
    LinkClient good(test_client_options(server_->endpoint().port, TestPki::get().museum2), [&](LinkFrame&& f) {
        const std::lock_guard lock(mutex);
        delivered.push_back(f.request_id);
    });
    const auto first = good.submit(test_request(1.0));
    ASSERT_TRUE(wait_until([&] { return good.stats().last_request_id == first; }));

    auto stub = v1::Tour::NewStub(tls_channel(target(), TestPki::get().appliance_tls(TestPki::get().museum1)));
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    auto stream = stub->Session(&ctx);
    ViewRequest r = test_request();
    r.frame_id = 1;
    v1::ViewRequestMsg msg;
    view_to_msg(r, msg);
    // 100 KiB in an unknown field: valid protobuf, above the farm's 64 KiB limit.
    msg.GetReflection()->MutableUnknownFields(&msg)->AddLengthDelimited(1000, std::string(100 * 1024, 'x'));
    stream->Write(msg);
    v1::FrameMsg frame;
    EXPECT_FALSE(stream->Read(&frame));
    const grpc::Status status = stream->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
    EXPECT_EQ(server_->stats().render_calls, 1u);  // only the good client's request

    const auto second = good.submit(test_request(2.0));
    ASSERT_TRUE(wait_until([&] { return good.stats().last_request_id == second; }));
    EXPECT_EQ(good.stats().sessions_opened, 1u);  // never disturbed
}

TEST_F(LinkSecurity, ApplianceOutsideTheAllowedListIsRefused) {
    server_.reset();
    auto options = test_server_options();
    options.allowed_appliances = {"museum-2"};
    server_ = std::make_unique<LinkServer>(options, renderer_.function());
    const RawOutcome refused =
        raw_session_once(tls_channel(target(), TestPki::get().appliance_tls(TestPki::get().museum1)));
    EXPECT_FALSE(refused.got_frame);
    EXPECT_EQ(refused.status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << refused.status.error_message();
    const RawOutcome allowed =
        raw_session_once(tls_channel(target(), TestPki::get().appliance_tls(TestPki::get().museum2)));
    EXPECT_TRUE(allowed.got_frame) << allowed.status.error_message();
    EXPECT_EQ(server_->stats().sessions_refused, 1u);
}

TEST_F(LinkSecurity, RevokedApplianceIsRefusedAndItsOpenSessionEnds) {
    const auto& pki = TestPki::get();
    const TempDir tmp;
    const auto crl = tmp.path() / "crl.pem";
    const auto write_crl = [&](const std::vector<RevokedCert>& revoked) {
        std::ofstream(tmp.path() / "crl.new") << make_crl(pki.ca, revoked, kSecondsPerDay);
        std::filesystem::rename(tmp.path() / "crl.new", crl);
    };
    write_crl({{cert_serial_hex(pki.museum2.cert_pem), 0}});
    server_.reset();
    auto options = test_server_options();
    options.crl_path = crl.string();
    server_ = std::make_unique<LinkServer>(options, renderer_.function());

    const RawOutcome refused = raw_session_once(tls_channel(target(), pki.appliance_tls(pki.museum2)));
    EXPECT_FALSE(refused.got_frame);
    EXPECT_EQ(refused.status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << refused.status.error_message();
    EXPECT_NE(refused.status.error_message().find("revoked"), std::string::npos) << refused.status.error_message();
    EXPECT_EQ(server_->stats().sessions_refused, 1u);

    // museum-1 streams; then its certificate is revoked while the farm runs: the session ends.
    LinkClient client(test_client_options(server_->endpoint().port, pki.museum1), [](LinkFrame&&) {});
    const auto first = client.submit(test_request(1.0));
    ASSERT_TRUE(wait_until([&] { return client.stats().last_request_id == first; }));
    write_crl({{cert_serial_hex(pki.museum2.cert_pem), 0}, {cert_serial_hex(pki.museum1.cert_pem), 0}});
    // The list is re-read at most once a second, on the session's next request.
    std::uint64_t last = first;
    ASSERT_TRUE(wait_until([&] {
        last = client.submit(test_request(2.0));
        return server_->stats().sessions_revoked == 1;
    })) << "the revoked appliance's session is still open";
    EXPECT_TRUE(wait_until([&] { return server_->stats().sessions_active == 0; }));
    // A frame the farm sent before the session ended may still be on its way; once the client has
    // seen the end and been refused again, nothing more may arrive.
    EXPECT_TRUE(wait_until([&] {
        const auto s = client.stats();
        return !s.connected && s.attempts_failed >= 1;
    }));
    // It does not get back in, and is served nothing more.
    const auto served = client.stats().last_request_id;
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_EQ(client.stats().last_request_id, served);
    EXPECT_LT(served, last);
    EXPECT_GE(server_->stats().sessions_refused, 1u);
    expect_refused_by_revocation(pki.museum1);
}

TEST_F(LinkSecurity, OneApplianceCannotTakeEverySessionSlot) {
    const auto& pki = TestPki::get();
    // Two sessions of museum-1 held open (the renderer is held: their first requests stay pending).
    const auto hold = renderer_.hold();
    LinkClient a(test_client_options(server_->endpoint().port, pki.museum1), [](LinkFrame&&) {});
    LinkClient b(test_client_options(server_->endpoint().port, pki.museum1), [](LinkFrame&&) {});
    a.submit(test_request());
    b.submit(test_request());
    ASSERT_TRUE(wait_until([&] { return server_->stats().sessions_active == 2; }));
    // A third of the same certificate is refused, by name; another appliance still gets in.
    const RawOutcome third = raw_session_once(tls_channel(target(), pki.appliance_tls(pki.museum1)));
    EXPECT_EQ(third.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << third.status.error_message();
    EXPECT_NE(third.status.error_message().find("museum-1"), std::string::npos) << third.status.error_message();
    EXPECT_EQ(server_->stats().sessions_active, 2u);
    renderer_.release();
    const RawOutcome other = raw_session_once(tls_channel(target(), pki.appliance_tls(pki.museum2)));
    EXPECT_TRUE(other.got_frame) << other.status.error_message();
}

// The farm applies each appliance's own view policy: it must learn, for a request's session, the
// certificate name that session was admitted with.
TEST(LinkSessionIdentity, ARequestsSessionNamesTheCertificateItWasAdmittedWith) {
    REQUIRE_IPV6_LOOPBACK();
    SessionNameRecorder recorder;
    LinkServer server(test_server_options(), recorder.function());
    recorder.attach(server);
    const auto& pki = TestPki::get();
    EXPECT_TRUE(
        raw_session_once(tls_channel(server.endpoint().grpc_target(), pki.appliance_tls(pki.museum2))).got_frame);
    EXPECT_TRUE(
        raw_session_once(tls_channel(server.endpoint().grpc_target(), pki.appliance_tls(pki.museum1))).got_frame);
    EXPECT_EQ(recorder.names(), (std::vector<std::string>{"museum-2", "museum-1"}));
    EXPECT_EQ(server.appliance_of(0), "");
    EXPECT_EQ(server.appliance_of(12345), "");
}

TEST(LinkIpv6Only, Ipv4PeerOnTheDualStackWildcardIsRefused) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer server(test_server_options("[::]:0"), renderer.function());
    const std::uint16_t port = server.endpoint().port;
    {
        // Skip where IPv4 loopback is missing: then nothing can arrive over IPv4 anyway.
        const UniqueFd probe(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
        sockaddr_in v4{};
        v4.sin_family = AF_INET;
        v4.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        v4.sin_port = htons(port);
        if (!probe.valid() || ::connect(probe.get(), reinterpret_cast<const sockaddr*>(&v4), sizeof v4) != 0) {
            GTEST_SKIP() << "no IPv4 path to the dual-stack socket on this host";
        }
    }
    const auto tls = TestPki::get().appliance_tls(TestPki::get().museum1);
    const RawOutcome v4 = raw_session_once(tls_channel("ipv4:127.0.0.1:" + std::to_string(port), tls));
    EXPECT_FALSE(v4.got_frame);
    EXPECT_EQ(v4.status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << v4.status.error_message();
    const RawOutcome v6 = raw_session_once(tls_channel("ipv6:[::1]:" + std::to_string(port), tls));
    EXPECT_TRUE(v6.got_frame) << v6.status.error_message();
}

TEST(LinkServerSetup, BadOptionsAreNamed) {
    SyntheticRenderer renderer;
    const auto expect_error = [&](LinkServerOptions options, const char* needle) {
        try {
            LinkServer server(std::move(options), renderer.function());
            ADD_FAILURE() << "started with bad options; expected: " << needle;
        } catch (const LinkError& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    auto o = test_server_options("0.0.0.0:7443");
    expect_error(o, "listen");
    o = test_server_options();
    o.max_frames_in_flight = 0;
    expect_error(o, "max_frames_in_flight");
    o = test_server_options();
    o.tls.key_pem = TestPki::get().museum1.key_pem;
    expect_error(o, "does not belong");
    o = test_server_options();
    o.tls.ca_pem = "nonsense";
    expect_error(o, "CA PEM");
}

TEST(LinkServerSetup, PortInUseIsAnError) {
    REQUIRE_IPV6_LOOPBACK();
    SyntheticRenderer renderer;
    LinkServer first(test_server_options(), renderer.function());
    try {
        LinkServer second(test_server_options("[::1]:" + std::to_string(first.endpoint().port)), renderer.function());
        ADD_FAILURE() << "two farms bound the same port";
    } catch (const LinkError& e) {
        EXPECT_NE(std::string(e.what()).find("cannot listen"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mogao
