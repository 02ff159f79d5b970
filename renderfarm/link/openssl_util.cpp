// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/openssl_util.h"

#include <openssl/err.h>
#include <openssl/pem.h>

#include <ctime>

namespace mogao::ossl {
namespace {

Bio read_bio(std::string_view text) { return Bio(BIO_new_mem_buf(text.data(), static_cast<int>(text.size()))); }

std::string drain(BIO* bio) {
    char* data = nullptr;
    const long size = BIO_get_mem_data(bio, &data);
    return size > 0 ? std::string(data, static_cast<std::size_t>(size)) : std::string{};
}

}  // namespace

std::string errors() {
    std::string out;
    while (const unsigned long code = ERR_get_error()) {
        char text[256];
        ERR_error_string_n(code, text, sizeof text);
        if (!out.empty()) out += "; ";
        out += text;
    }
    return out;
}

Cert parse_cert(std::string_view pem) {
    if (pem.size() > (1u << 20)) return nullptr;
    Bio bio = read_bio(pem);
    return bio ? Cert(PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr)) : nullptr;
}

std::vector<Cert> parse_certs(std::string_view pem) {
    std::vector<Cert> certs;
    if (pem.size() > (1u << 20)) return certs;
    Bio bio = read_bio(pem);
    while (bio) {
        Cert cert(PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr));
        if (!cert) break;
        certs.push_back(std::move(cert));
    }
    ERR_clear_error();  // the read that ended the loop always "fails" with no start line
    return certs;
}

Pkey parse_key(std::string_view pem) {
    if (pem.size() > (1u << 20)) return nullptr;
    Bio bio = read_bio(pem);
    // No passphrase callback: keys are stored unencrypted, protected by mode 0600 (docs/link.md).
    return bio ? Pkey(PEM_read_bio_PrivateKey(bio.get(), nullptr, nullptr, nullptr)) : nullptr;
}

Crl parse_crl(std::string_view pem) {
    if (pem.size() > (16u << 20)) return nullptr;
    Bio bio = read_bio(pem);
    return bio ? Crl(PEM_read_bio_X509_CRL(bio.get(), nullptr, nullptr, nullptr)) : nullptr;
}

std::string crl_to_pem(X509_CRL* crl) {
    Bio bio(BIO_new(BIO_s_mem()));
    if (!bio || PEM_write_bio_X509_CRL(bio.get(), crl) != 1) return {};
    return drain(bio.get());
}

std::string integer_hex(const ASN1_INTEGER* value) {
    if (!value) return {};
    Bignum bn(ASN1_INTEGER_to_BN(value, nullptr));
    if (!bn) return {};
    char* hex = BN_bn2hex(bn.get());
    if (!hex) return {};
    std::string out(hex);
    OPENSSL_free(hex);
    return out;
}

std::int64_t time_seconds(const ASN1_TIME* time) {
    std::tm tm{};
    if (!time || ASN1_TIME_to_tm(time, &tm) != 1) return 0;
    return static_cast<std::int64_t>(timegm(&tm));
}

std::string cert_to_pem(X509* cert) {
    Bio bio(BIO_new(BIO_s_mem()));
    if (!bio || PEM_write_bio_X509(bio.get(), cert) != 1) return {};
    return drain(bio.get());
}

std::string key_to_pem(EVP_PKEY* key) {
    Bio bio(BIO_new(BIO_s_mem()));
    if (!bio || PEM_write_bio_PrivateKey(bio.get(), key, nullptr, nullptr, 0, nullptr, nullptr) != 1) return {};
    return drain(bio.get());
}

std::string subject_cn(X509* cert) {
    char cn[256] = {};
    if (X509_NAME_get_text_by_NID(X509_get_subject_name(cert), NID_commonName, cn, sizeof cn) < 0) return {};
    return cn;
}

std::string not_after_text(X509* cert) {
    Bio bio(BIO_new(BIO_s_mem()));
    if (!bio || ASN1_TIME_print(bio.get(), X509_get0_notAfter(cert)) != 1) return "?";
    return drain(bio.get());
}

}  // namespace mogao::ossl
