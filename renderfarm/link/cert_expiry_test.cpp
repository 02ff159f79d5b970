// SPDX-License-Identifier: Apache-2.0
// Certificate expiry (renderfarm/link/cert_expiry.h): notAfter read from certificates made here
// with a known lifetime, the warning period with an injected clock, and the held set following
// rotated files.
#include "renderfarm/link/cert_expiry.h"

#include <gtest/gtest.h>

#include <ctime>
#include <fstream>

#include "common/link_types.h"
#include "renderfarm/link/link_test_support.h"
#include "renderfarm/link/pki.h"

namespace mogao {
namespace {

using testing::TempDir;
using testing::TestPki;
constexpr std::int64_t kDay = kSecondsPerDay;

TEST(CertExpiry, NotAfterIsIssueTimePlusTheLifetime) {
    const auto& pki = TestPki::get();
    const std::int64_t before = std::time(nullptr);
    const PemPair cert =
        issue_cert(pki.ca, {CertRole::appliance, "museum-9", {}, -300, 41 * kDay, KeyAlgorithm::ec_p256});
    const std::int64_t after = std::time(nullptr);
    const std::int64_t not_after = certificate_not_after_s(cert.cert_pem);
    EXPECT_GE(not_after, before - 300 + 41 * kDay);
    EXPECT_LE(not_after, after - 300 + 41 * kDay);

    const auto held = certificate_expiries({pki.ca.cert_pem, cert.cert_pem, cert.key_pem}, "appliance");
    ASSERT_EQ(held.size(), 2u);
    EXPECT_EQ(held[0].role, "ca");
    EXPECT_EQ(held[0].name, "mogao test CA");
    EXPECT_EQ(held[0].not_after_s, certificate_not_after_s(pki.ca.cert_pem));
    EXPECT_EQ(held[1], (CertificateExpiry{"appliance", "museum-9", not_after}));
}

TEST(CertExpiry, EveryCaOfABundleIsHeldAndGarbageIsNamed) {
    const auto& pki = TestPki::get();
    const auto held =
        certificate_expiries({pki.ca.cert_pem + pki.foreign_ca.cert_pem, pki.farm.cert_pem, pki.farm.key_pem}, "farm");
    ASSERT_EQ(held.size(), 3u);
    EXPECT_EQ(held[1].name, "someone else's CA");
    EXPECT_EQ(held[2].role, "farm");
    EXPECT_THROW(static_cast<void>(certificate_not_after_s("not a certificate")), LinkError);
    EXPECT_TRUE(certificate_expiries({"x", "y", "z"}, "farm").empty());
}

TEST(CertExpiry, WarnsWithinThePeriodOnlyOnTheInjectedClock) {
    const std::int64_t now = 1'800'000'000;
    const CertificateExpiry at29{"appliance", "museum-1", now + 29 * kDay + 3600};
    const CertificateExpiry at31{"ca", "mogao farm CA", now + 31 * kDay};
    const CertificateExpiry gone{"farm", "farm-1", now - 2 * kDay - 60};
    EXPECT_TRUE(expires_soon(at29, now, kCertificateWarningSeconds));
    EXPECT_FALSE(expires_soon(at31, now, kCertificateWarningSeconds));
    EXPECT_TRUE(expires_soon(gone, now, kCertificateWarningSeconds));
    EXPECT_FALSE(expires_soon(gone, now, 0)) << "a period of 0 never warns";
    EXPECT_EQ(days_left(at29.not_after_s, now), 29);
    EXPECT_EQ(days_left(gone.not_after_s, now), -3);
    EXPECT_EQ(days_left(now, now), 0);

    const auto lines = expiry_warnings({at29, at31, gone}, now, kCertificateWarningSeconds);
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_NE(lines[0].find("the appliance certificate CN=museum-1 expires in 29 day(s) (2027-02-13T09:00:00Z)"),
              std::string::npos)
        << lines[0];
    EXPECT_NE(lines[1].find("CN=farm-1 expired 3 day(s) ago"), std::string::npos) << lines[1];
    EXPECT_EQ(utc_seconds_text(0), "1970-01-01T00:00:00Z");
}

void write(const std::filesystem::path& path, const std::string& text) {
    std::ofstream(path.string() + ".new") << text;
    std::filesystem::rename(path.string() + ".new", path);
}

TEST(HeldCertificates, FollowsRotatedFilesThatCheckAndKeepsTheLastGoodSet) {
    const auto& pki = TestPki::get();
    const TempDir tmp;
    const TlsFilePaths files{tmp.path() / "ca.pem", tmp.path() / "a.pem", tmp.path() / "a.key"};
    write(files.ca, pki.ca.cert_pem);
    write(files.cert, pki.museum1.cert_pem);
    write(files.key, pki.museum1.key_pem);
    HeldCertificates held(load_tls_files(files.ca, files.cert, files.key), files, "appliance", std::chrono::seconds(0));
    ASSERT_EQ(held.current().size(), 2u);
    EXPECT_EQ(held.current()[1].name, "museum-1");

    const PemPair next =
        issue_cert(pki.ca, {CertRole::appliance, "museum-1", {}, -300, 90 * kDay, KeyAlgorithm::ec_p256});
    write(files.cert, next.cert_pem);  // its key not yet replaced: gRPC would not take the pair
    EXPECT_EQ(held.current()[1].not_after_s, certificate_not_after_s(pki.museum1.cert_pem));
    write(files.key, next.key_pem);
    EXPECT_EQ(held.current()[1].not_after_s, certificate_not_after_s(next.cert_pem));
    std::filesystem::remove(files.cert);  // mid-replacement: the last good set stays
    EXPECT_EQ(held.current()[1].not_after_s, certificate_not_after_s(next.cert_pem));
}

}  // namespace
}  // namespace mogao
