// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/pki.h"

#include <gtest/gtest.h>
#include <openssl/x509v3.h>
#include <sys/stat.h>

#include <array>

#include "renderfarm/link/link_test_support.h"
#include "renderfarm/link/openssl_util.h"
#include "renderfarm/link/tls_material.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;
using testing::TestPki;

unsigned mode_of(const fs::path& p) {
    struct stat st {};
    EXPECT_EQ(::stat(p.c_str(), &st), 0) << p;
    return st.st_mode & 07777;
}

int run(std::vector<std::string> args) {
    args.insert(args.begin(), "pki");
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    return run_pki_command(static_cast<int>(argv.size()), argv.data());
}

TEST(Pki, CommandsWriteEveryFileWithMode0600) {
    const TempDir tmp;
    const fs::path dir = tmp.path() / "pki";
    // With umask 0277 open(..., 0600) alone would make 0400 files: the mode must be set explicitly.
    const mode_t old_umask = ::umask(0277);
    ASSERT_EQ(run({"init-ca", "--dir", dir.string()}), 0);
    ASSERT_EQ(run({"issue-farm", "--dir", dir.string(), "--name", "farm-1", "--san", "::1,2001:db8::5"}), 0);
    ASSERT_EQ(run({"issue-appliance", "--dir", dir.string(), "--name", "museum-1", "--days", "30"}), 0);
    EXPECT_EQ(mode_of(dir), 0700u);
    const std::array<fs::path, 6> files = {ca_cert_path(dir),
                                           ca_key_path(dir),
                                           farm_cert_path(dir, "farm-1"),
                                           farm_key_path(dir, "farm-1"),
                                           appliance_cert_path(dir, "museum-1"),
                                           appliance_key_path(dir, "museum-1")};
    ::umask(old_umask);
    for (const auto& f : files) EXPECT_EQ(mode_of(f), 0600u) << f;

    // What the two sides load fits together: key matches, chains to the CA, not expired. The farm
    // serves from an exported folder (without ca.key).
    const fs::path served = tmp.path() / "farm-tls";
    ASSERT_EQ(run({"export-farm", "--dir", dir.string(), "--name", "farm-1", "--to", served.string()}), 0);
    const TlsCheck farm = check_tls_material(load_farm_tls(served, "farm-1"), "farm");
    EXPECT_EQ(farm.error, "");
    EXPECT_TRUE(farm.warnings.empty()) << farm.warnings.front();
    const TlsCheck appliance = check_tls_material(load_appliance_tls(dir, "museum-1"), "appliance");
    EXPECT_EQ(appliance.error, "");
    EXPECT_TRUE(appliance.warnings.empty()) << appliance.warnings.front();
}

TEST(Pki, FarmCertificateCarriesIpv6SansAndServerAuthOnly) {
    const TempDir tmp;
    ASSERT_EQ(run({"init-ca", "--dir", tmp.path().string()}), 0);
    ASSERT_EQ(
        run({"issue-farm", "--dir", tmp.path().string(), "--name", "farm-1", "--san", "::1,2001:DB8::5,farm.lan"}), 0);
    const auto cert = ossl::parse_cert(read_pem_file(farm_cert_path(tmp.path(), "farm-1")));
    ASSERT_TRUE(cert);
    EXPECT_EQ(X509_check_ip_asc(cert.get(), "::1", 0), 1);
    EXPECT_EQ(X509_check_ip_asc(cert.get(), "2001:db8::5", 0), 1);
    EXPECT_EQ(X509_check_ip_asc(cert.get(), "::2", 0), 0);
    EXPECT_EQ(X509_check_host(cert.get(), "farm.lan", 0, 0, nullptr), 1);
    EXPECT_EQ(X509_check_host(cert.get(), "farm-1", 0, 0, nullptr), 1);
    EXPECT_EQ(X509_check_purpose(cert.get(), X509_PURPOSE_SSL_SERVER, 0), 1);
    EXPECT_EQ(X509_check_purpose(cert.get(), X509_PURPOSE_SSL_CLIENT, 0), 0);
    EXPECT_EQ(ossl::subject_cn(cert.get()), "farm-1");
}

TEST(Pki, ApplianceCertificateIsClientAuthOnly) {
    const auto cert = ossl::parse_cert(TestPki::get().museum1.cert_pem);
    ASSERT_TRUE(cert);
    EXPECT_EQ(X509_check_purpose(cert.get(), X509_PURPOSE_SSL_CLIENT, 0), 1);
    EXPECT_EQ(X509_check_purpose(cert.get(), X509_PURPOSE_SSL_SERVER, 0), 0);
    EXPECT_EQ(ossl::subject_cn(cert.get()), "museum-1");
}

TEST(Pki, RefusesToOverwriteUnlessForced) {
    const TempDir tmp;
    const fs::path dir = tmp.path();
    ASSERT_EQ(run({"init-ca", "--dir", dir.string()}), 0);
    const std::string first = read_pem_file(ca_cert_path(dir));
    EXPECT_EQ(run({"init-ca", "--dir", dir.string()}), 1);
    EXPECT_EQ(read_pem_file(ca_cert_path(dir)), first);
    EXPECT_THROW(pki_init_ca(dir, "x", 10, KeyAlgorithm::ec_p256, false), PkiError);
    try {
        pki_init_ca(dir, "x", 10, KeyAlgorithm::ec_p256, false);
    } catch (const PkiError& e) {
        EXPECT_NE(std::string(e.what()).find("refusing to overwrite"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("--force"), std::string::npos) << e.what();
    }
    ASSERT_EQ(run({"init-ca", "--dir", dir.string(), "--force"}), 0);
    EXPECT_NE(read_pem_file(ca_cert_path(dir)), first);
    EXPECT_EQ(mode_of(ca_cert_path(dir)), 0600u);
    EXPECT_EQ(mode_of(ca_key_path(dir)), 0600u);
    EXPECT_FALSE(fs::exists(dir / "ca.pem.tmp"));
}

TEST(Pki, BadCommandLinesAndMissingCaFailClearly) {
    const TempDir tmp;
    const std::string dir = tmp.path().string();
    EXPECT_EQ(run({}), 2);
    EXPECT_EQ(run({"frobnicate"}), 2);
    EXPECT_EQ(run({"issue-appliance", "--dir", dir}), 2);  // --name missing
    EXPECT_EQ(run({"issue-appliance", "--dir", dir, "--name", "m", "--days", "0"}), 2);
    EXPECT_EQ(run({"issue-appliance", "--dir", dir, "--name", "museum-1"}), 1);  // no CA yet
    try {
        pki_issue_appliance(dir, "museum-1", 30, false);
        ADD_FAILURE() << "issued without a CA";
    } catch (const PkiError& e) {
        EXPECT_NE(std::string(e.what()).find("init-ca"), std::string::npos) << e.what();
    }
    ASSERT_EQ(run({"init-ca", "--dir", dir}), 0);
    EXPECT_EQ(run({"issue-appliance", "--dir", dir, "--name", "../evil"}), 1);
    EXPECT_EQ(run({"issue-appliance", "--dir", dir, "--name", "-rf"}), 1);
    EXPECT_EQ(run({"issue-farm", "--dir", dir, "--name", "farm", "--san", "not a name!"}), 1);
    EXPECT_FALSE(fs::exists(farm_key_path(dir, "farm")));
}

TEST(Pki, RsaCaWorks) {
    const PemPair ca = make_ca({CertRole::ca, "rsa CA", {}, -300, kSecondsPerDay, KeyAlgorithm::rsa_3072});
    const PemPair leaf =
        issue_cert(ca, {CertRole::appliance, "museum-9", {}, -300, kSecondsPerDay, KeyAlgorithm::ec_p256});
    const TlsCheck check = check_tls_material({ca.cert_pem, leaf.cert_pem, leaf.key_pem}, "appliance");
    EXPECT_EQ(check.error, "");
    EXPECT_TRUE(check.warnings.empty());
    const auto key = ossl::parse_key(ca.key_pem);
    ASSERT_TRUE(key);
    EXPECT_EQ(EVP_PKEY_get_bits(key.get()), 3072);
}

TEST(TlsCheck, NamesExpiredForeignAndMismatchedMaterial) {
    const TestPki& pki = TestPki::get();
    const TlsCheck expired = check_tls_material(pki.appliance_tls(pki.expired), "appliance");
    EXPECT_EQ(expired.error, "");
    ASSERT_EQ(expired.warnings.size(), 1u);
    EXPECT_NE(expired.warnings[0].find("expired"), std::string::npos) << expired.warnings[0];

    const TlsCheck foreign = check_tls_material(pki.appliance_tls(pki.foreign_museum1), "appliance");
    EXPECT_EQ(foreign.error, "");
    ASSERT_EQ(foreign.warnings.size(), 1u);
    EXPECT_NE(foreign.warnings[0].find("does not chain"), std::string::npos) << foreign.warnings[0];

    const TlsCheck mismatched =
        check_tls_material({pki.ca.cert_pem, pki.museum1.cert_pem, pki.museum2.key_pem}, "appliance");
    EXPECT_NE(mismatched.error.find("does not belong"), std::string::npos) << mismatched.error;

    const TlsCheck garbage = check_tls_material({"garbage", pki.museum1.cert_pem, pki.museum1.key_pem}, "appliance");
    EXPECT_NE(garbage.error.find("CA PEM"), std::string::npos) << garbage.error;
}

TEST(TlsFiles, MissingFileIsNamed) {
    const TempDir tmp;
    try {
        static_cast<void>(read_pem_file(tmp.path() / "nope.pem"));
        ADD_FAILURE() << "read a missing file";
    } catch (const LinkError& e) {
        EXPECT_NE(std::string(e.what()).find("nope.pem"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mogao
