// SPDX-License-Identifier: Apache-2.0
// Certificates over real gRPC and TLS on [::1]: an appliance whose certificate expired is refused in
// the handshake, and after `pki renew-appliance` (renew_appliance_cert: the same key re-signed by
// the CA) the same key pair is served again -- nothing new was carried to the appliance but the
// certificate. Both sides report the notAfter of what they hold (LinkServerStats::certificates,
// LinkClientStats::certificates).
#include <gtest/gtest.h>

#include <string>

#include "renderfarm/link/cert_expiry.h"
#include "renderfarm/link/link_client.h"
#include "renderfarm/link/link_server.h"
#include "renderfarm/link/link_test_support.h"
#include "renderfarm/link/pki.h"

namespace mogao {
namespace {

using namespace testing;

TEST(LinkRenewal, ARenewedCertificateIsAcceptedWithTheSameKey) {
    if (!ipv6_loopback_available()) GTEST_SKIP() << "IPv6 loopback [::1] is not available on this host";
    const auto& pki = TestPki::get();
    SessionNameRecorder recorder;
    LinkServer server(test_server_options(), recorder.function());
    recorder.attach(server);

    // Expired: the handshake refuses it, nothing is rendered for it.
    const RawOutcome before =
        raw_session_once(tls_channel(server.endpoint().grpc_target(), pki.appliance_tls(pki.expired)));
    EXPECT_FALSE(before.got_frame);
    EXPECT_EQ(before.status.error_code(), grpc::StatusCode::UNAVAILABLE) << before.status.error_message();

    const PemPair renewed{renew_appliance_cert(pki.ca, pki.expired.cert_pem, 30 * kSecondsPerDay, {}),
                          pki.expired.key_pem};
    LinkClient client(test_client_options(server.endpoint().port, renewed), [](LinkFrame&&) {});
    const auto id = client.submit(test_request(1.0));
    EXPECT_TRUE(wait_until([&] { return client.stats().last_request_id == id; }))
        << "the renewed certificate was refused";
    EXPECT_EQ(recorder.count("museum-old"), 1u);
    EXPECT_EQ(client.stats().attempts_failed, 0u);

    // What each side reports holding.
    const auto farm = server.stats().certificates;
    ASSERT_EQ(farm.size(), 2u);
    EXPECT_EQ(farm[0], (CertificateExpiry{"ca", "mogao test CA", certificate_not_after_s(pki.ca.cert_pem)}));
    EXPECT_EQ(farm[1], (CertificateExpiry{"farm", "farm-test", certificate_not_after_s(pki.farm.cert_pem)}));
    const auto appliance = client.stats().certificates;
    ASSERT_EQ(appliance.size(), 2u);
    EXPECT_EQ(appliance[1], (CertificateExpiry{"appliance", "museum-old", certificate_not_after_s(renewed.cert_pem)}));
    EXPECT_GT(appliance[1].not_after_s, certificate_not_after_s(pki.expired.cert_pem) + 29 * kSecondsPerDay);
}

}  // namespace
}  // namespace mogao
