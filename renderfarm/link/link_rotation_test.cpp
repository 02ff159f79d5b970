// SPDX-License-Identifier: Apache-2.0
// Rotating the farm's certificate without downtime: LinkServerOptions::tls_files are re-read while
// the farm serves. An appliance that only accepts the new certificate's name gets in once the files
// are replaced; the appliance streaming since before the rotation keeps its one session throughout.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

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
