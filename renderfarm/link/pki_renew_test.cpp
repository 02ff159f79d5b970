// SPDX-License-Identifier: Apache-2.0
// `mogao-farm pki renew-appliance` (pki.h): the renewed certificate keeps the key and the subject
// and extends notAfter; what the policy refuses (another CA's certificate, a revoked one, a farm
// certificate, a key weaker than issue-appliance makes) is refused with the reason and leaves the
// files as they were. The handshake with a renewed certificate is in link_renewal_test.cpp.
#include <gtest/gtest.h>
#include <openssl/ec.h>
#include <openssl/rsa.h>

#include <fstream>

#include "renderfarm/link/link_test_support.h"
#include "renderfarm/link/openssl_util.h"
#include "renderfarm/link/pki.h"
#include "renderfarm/link/tls_material.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;
using testing::TestPki;

// `mogao-farm pki ARGS...` in this process.
int run(std::vector<std::string> args) { return testing::run_pki(std::move(args)); }

std::string slurp(const fs::path& p) { return read_pem_file(p); }

// An appliance certificate signed by `ca` for `key` (issue-appliance makes only EC P-256: this is
// what an older or another tool might have issued).
std::string appliance_cert_for(const PemPair& ca, const std::string& name, ossl::Pkey key) {
    ossl::Cert ca_cert = ossl::parse_cert(ca.cert_pem);
    ossl::Pkey ca_key = ossl::parse_key(ca.key_pem);
    ossl::Cert cert(X509_new());
    EXPECT_TRUE(key && ca_cert && ca_key && cert);
    X509_set_version(cert.get(), X509_VERSION_3);
    ASN1_INTEGER_set(X509_get_serialNumber(cert.get()), 4242);
    X509_gmtime_adj(X509_getm_notBefore(cert.get()), -300);
    X509_gmtime_adj(X509_getm_notAfter(cert.get()), kSecondsPerDay);
    X509_NAME_add_entry_by_txt(X509_get_subject_name(cert.get()), "CN", MBSTRING_UTF8,
                               reinterpret_cast<const unsigned char*>(name.c_str()), -1, -1, 0);
    X509_set_issuer_name(cert.get(), X509_get_subject_name(ca_cert.get()));
    X509_set_pubkey(cert.get(), key.get());
    X509V3_CTX ctx;
    X509V3_set_ctx_nodb(&ctx);
    X509V3_set_ctx(&ctx, ca_cert.get(), cert.get(), nullptr, nullptr, 0);
    for (const auto& [nid, value] :
         {std::pair{NID_basic_constraints, "critical,CA:FALSE"}, std::pair{NID_ext_key_usage, "clientAuth"},
          std::pair{NID_authority_key_identifier, "keyid:always"}}) {
        X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value);
        X509_add_ext(cert.get(), ext, -1);
        X509_EXTENSION_free(ext);
    }
    EXPECT_NE(X509_sign(cert.get(), ca_key.get(), EVP_sha256()), 0);
    return ossl::cert_to_pem(cert.get());
}

TEST(PkiRenew, KeepsTheKeyAndSubjectAndExtendsNotAfter) {
    const TempDir tmp;
    const std::string dir = tmp.path().string();
    ASSERT_EQ(run({"init-ca", "--dir", dir}), 0);
    ASSERT_EQ(run({"issue-appliance", "--dir", dir, "--name", "museum-1", "--days", "10"}), 0);
    const std::string old_pem = slurp(appliance_cert_path(dir, "museum-1"));
    const std::string key_pem = slurp(appliance_key_path(dir, "museum-1"));
    ASSERT_EQ(run({"renew-appliance", "--dir", dir, "--name", "museum-1", "--days", "400"}), 0);

    const ossl::Cert old_cert = ossl::parse_cert(old_pem);
    const ossl::Cert renewed = ossl::parse_cert(slurp(appliance_cert_path(dir, "museum-1")));
    ASSERT_TRUE(old_cert && renewed);
    EXPECT_EQ(EVP_PKEY_eq(X509_get0_pubkey(old_cert.get()), X509_get0_pubkey(renewed.get())), 1) << "a new key";
    EXPECT_EQ(X509_NAME_cmp(X509_get_subject_name(old_cert.get()), X509_get_subject_name(renewed.get())), 0);
    EXPECT_NE(ossl::integer_hex(X509_get0_serialNumber(old_cert.get())),
              ossl::integer_hex(X509_get0_serialNumber(renewed.get())));
    const std::int64_t old_end = ossl::time_seconds(X509_get0_notAfter(old_cert.get()));
    const std::int64_t new_end = ossl::time_seconds(X509_get0_notAfter(renewed.get()));
    EXPECT_NEAR(static_cast<double>(new_end - old_end), 390.0 * kSecondsPerDay, 60.0);
    EXPECT_EQ(X509_check_purpose(renewed.get(), X509_PURPOSE_SSL_CLIENT, 0), 1);
    EXPECT_EQ(X509_check_purpose(renewed.get(), X509_PURPOSE_SSL_SERVER, 0), 0);

    // The key file is untouched and still belongs to the certificate; the old one is kept.
    EXPECT_EQ(slurp(appliance_key_path(dir, "museum-1")), key_pem);
    EXPECT_EQ(slurp(previous_appliance_cert_path(dir, "museum-1")), old_pem);
    const TlsCheck check = check_tls_material(load_appliance_tls(dir, "museum-1"), "appliance");
    EXPECT_EQ(check.error, "");
    EXPECT_TRUE(check.warnings.empty()) << check.warnings.front();

    // Revoking by name revokes both certificates of the key.
    ASSERT_EQ(run({"revoke", "--dir", dir, "--name", "museum-1"}), 0);
    const RevocationList crl = parse_crl(slurp(crl_path(dir)), slurp(ca_cert_path(dir)), "crl.pem");
    EXPECT_TRUE(is_revoked(crl, cert_serial_hex(old_pem)));
    EXPECT_TRUE(is_revoked(crl, cert_serial_hex(slurp(appliance_cert_path(dir, "museum-1")))));
}

TEST(PkiRenew, RefusesWhatThePolicyForbidsAndChangesNothing) {
    const TempDir tmp;
    const std::string dir = tmp.path().string();
    ASSERT_EQ(run({"init-ca", "--dir", dir}), 0);
    const auto& other = TestPki::get();
    const auto refused = [&](const std::string& name, const std::string& pem) {
        std::ofstream(appliance_cert_path(dir, name)) << pem;
        EXPECT_EQ(run({"renew-appliance", "--dir", dir, "--name", name}), 1) << name;
        EXPECT_EQ(slurp(appliance_cert_path(dir, name)), pem) << name;
        EXPECT_FALSE(fs::exists(previous_appliance_cert_path(dir, name))) << name;
    };
    refused("museum-1", other.foreign_museum1.cert_pem);  // another CA's

    ASSERT_EQ(run({"issue-appliance", "--dir", dir, "--name", "museum-2"}), 0);
    ASSERT_EQ(run({"revoke", "--dir", dir, "--name", "museum-2"}), 0);
    refused("museum-2", slurp(appliance_cert_path(dir, "museum-2")));

    EXPECT_EQ(run({"renew-appliance", "--dir", dir, "--name", "nobody"}), 1) << "no certificate to renew";
    EXPECT_EQ(run({"renew-appliance", "--dir", dir}), 2) << "no --name: a bad command line";
    EXPECT_EQ(run({"renew-appliance", "--dir", dir, "--name", "museum-2", "--days", "0"}), 2);
}

TEST(PkiRenew, TheReasonIsNamed) {
    const auto& pki = TestPki::get();
    const auto why = [&](const std::string& pem) {
        try {
            static_cast<void>(renew_appliance_cert(pki.ca, pem, kSecondsPerDay, {}));
        } catch (const PkiError& e) {
            return std::string(e.what());
        }
        return std::string("renewed");
    };
    EXPECT_NE(why(pki.foreign_museum1.cert_pem).find("was not issued by this CA"), std::string::npos);
    EXPECT_NE(why(pki.farm.cert_pem).find("not an appliance (clientAuth) certificate"), std::string::npos);
    EXPECT_NE(why(pki.ca.cert_pem).find("not an appliance"), std::string::npos);
    const std::string weak = why(appliance_cert_for(pki.ca, "museum-rsa", ossl::Pkey(EVP_RSA_gen(2048))));
    EXPECT_NE(weak.find("RSA 2048 bits (112-bit security), is weaker than what issue-appliance makes"),
              std::string::npos)
        << weak;
    const std::string p224 = why(appliance_cert_for(pki.ca, "museum-224", ossl::Pkey(EVP_EC_gen("P-224"))));
    EXPECT_NE(p224.find("EC P-224 (112-bit security), is weaker"), std::string::npos) << p224;
    EXPECT_EQ(why(appliance_cert_for(pki.ca, "museum-384", ossl::Pkey(EVP_EC_gen("P-384")))), "renewed")
        << "P-384 (192-bit security) is stronger than P-256";
    EXPECT_EQ(why(pki.expired.cert_pem), "renewed") << "an expired certificate keeps its key";
    const std::string serial = cert_serial_hex(pki.museum1.cert_pem);
    try {
        static_cast<void>(renew_appliance_cert(pki.ca, pki.museum1.cert_pem, kSecondsPerDay, {{serial, 0}}));
        ADD_FAILURE() << "renewed a revoked certificate";
    } catch (const PkiError& e) {
        EXPECT_NE(std::string(e.what()).find("is revoked"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mogao
