// SPDX-License-Identifier: Apache-2.0
// Rotating the farm's certificate without downtime: LinkServerOptions::tls_files are re-read while
// the farm serves. An appliance that only accepts the new certificate's name gets in once the files
// are replaced; the appliance streaming since before the rotation keeps its one session throughout.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "renderfarm/link/link_client.h"
#include "renderfarm/link/link_server.h"
#include "renderfarm/link/link_test_support.h"
#include "renderfarm/link/pki.h"

namespace mogao {
namespace {

using namespace testing;
namespace fs = std::filesystem;

void replace_file(const fs::path& path, const std::string& text) {
    std::ofstream(path.string() + ".new") << text;
    fs::rename(path.string() + ".new", path);
}

TEST(LinkRotation, FarmCertificateIsReplacedWhileServing) {
    if (!ipv6_loopback_available()) GTEST_SKIP() << "IPv6 loopback [::1] is not available on this host";
    const auto& pki = TestPki::get();
    const TempDir tmp;
    const TlsFilePaths files{tmp.path() / "ca.pem", tmp.path() / "farm.pem", tmp.path() / "farm.key"};
    replace_file(files.ca, pki.ca.cert_pem);
    replace_file(files.cert, pki.farm.cert_pem);
    replace_file(files.key, pki.farm.key_pem);
    // The successor names the farm "farm-2027" (and ::1): only it satisfies a client expecting that name.
    const PemPair next =
        issue_cert(pki.ca, {CertRole::farm, "farm-2027", {"::1"}, -300, kSecondsPerDay, KeyAlgorithm::ec_p256});

    SyntheticRenderer renderer;
    auto options = test_server_options();
    options.tls_files = files;
    options.tls_refresh_s = 1;
    LinkServer server(options, renderer.function());

    LinkClient streaming(test_client_options(server.endpoint().port, pki.museum1), [](LinkFrame&&) {});
    const auto first = streaming.submit(test_request(1.0));
    ASSERT_TRUE(wait_until([&] { return streaming.stats().last_request_id == first; }));

    auto expecting_next = test_client_options(server.endpoint().port, pki.museum2);
    expecting_next.server_name = "farm-2027";
    {
        LinkClient early(expecting_next, [](LinkFrame&&) {});
        early.submit(test_request());
        ASSERT_TRUE(wait_until([&] { return early.stats().attempts_failed >= 2; }));
        EXPECT_EQ(early.stats().frames_received, 0u) << "the old certificate already names farm-2027";
    }

    // Rotate: key first, then the certificate (gRPC skips a pair that does not match, meanwhile).
    replace_file(files.key, next.key_pem);
    replace_file(files.cert, next.cert_pem);
    LinkClient late(expecting_next, [](LinkFrame&&) {});
    const auto id = late.submit(test_request(2.0));
    EXPECT_TRUE(wait_until([&] { return late.stats().last_request_id == id; }, std::chrono::seconds(20)))
        << "the farm still presents the old certificate";

    // The session opened before the rotation never broke and is still served.
    const auto after = streaming.submit(test_request(3.0));
    EXPECT_TRUE(wait_until([&] { return streaming.stats().last_request_id == after; }));
    EXPECT_EQ(streaming.stats().sessions_opened, 1u);
    EXPECT_EQ(streaming.stats().attempts_failed, 0u);
}

// The appliance's side: LinkClientOptions::tls_files are looked at while streaming. Replacing them
// ends the session at once and opens the next with the new certificate (no backoff); a set whose
// key does not match its certificate is refused and the session goes on.
TEST(LinkRotation, ApplianceCertificateIsReplacedWhileStreaming) {
    if (!ipv6_loopback_available()) GTEST_SKIP() << "IPv6 loopback [::1] is not available on this host";
    const auto& pki = TestPki::get();
    const TempDir tmp;
    const TlsFilePaths files{tmp.path() / "ca.pem", tmp.path() / "museum.pem", tmp.path() / "museum.key"};
    replace_file(files.ca, pki.ca.cert_pem);
    replace_file(files.cert, pki.museum1.cert_pem);
    replace_file(files.key, pki.museum1.key_pem);

    SessionNameRecorder recorder;
    LinkServer server(test_server_options(), recorder.function());
    recorder.attach(server);
    const auto rendered_for = [&](const std::string& name) { return recorder.count(name); };

    auto options = test_client_options(server.endpoint().port, pki.museum1);
    options.tls_files = files;
    options.tls_refresh_s = 1;
    LinkClient client(options, [](LinkFrame&&) {});
    const auto stream_until = [&](const std::function<bool()>& done) {
        return wait_until([&] {
            const auto id = client.submit(test_request(1.0));
            return wait_until([&] { return client.stats().last_request_id >= id; }, std::chrono::seconds(5)) && done();
        });
    };
    ASSERT_TRUE(stream_until([&] { return rendered_for("museum-1") > 0; }));

    replace_file(files.key, pki.museum2.key_pem);
    replace_file(files.cert, pki.museum2.cert_pem);
    EXPECT_TRUE(stream_until([&] { return rendered_for("museum-2") > 0; })) << "the old certificate is still in use";
    EXPECT_EQ(client.stats().tls_reloads, 1u);
    EXPECT_EQ(client.stats().sessions_opened, 2u);
    EXPECT_EQ(client.stats().attempts_failed, 0u);

    // A key that does not match its certificate: refused, the session with museum-2 goes on.
    replace_file(files.key, pki.museum1.key_pem);
    EXPECT_TRUE(wait_until([&] { return client.stats().tls_reloads_refused == 1; }));
    const std::size_t before = rendered_for("museum-2");
    EXPECT_TRUE(stream_until([&] { return rendered_for("museum-2") > before; }));
    EXPECT_EQ(client.stats().sessions_opened, 2u);
    EXPECT_EQ(client.stats().tls_reloads, 1u);
}

TEST(LinkRotation, IncompleteFilePathsAreNamed) {
    SyntheticRenderer renderer;
    auto options = test_server_options();
    options.tls_files.cert = "/etc/mogao/pki/farm-farm.pem";
    try {
        LinkServer server(options, renderer.function());
        ADD_FAILURE() << "started with a certificate path but no key or CA path";
    } catch (const LinkError& e) {
        EXPECT_NE(std::string(e.what()).find("tls_files"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mogao
