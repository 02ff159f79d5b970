// RAII owners for the OpenSSL 3 objects the link uses and PEM helpers. Internal to
// renderfarm/link (tls_material.cpp, pki.cpp). Every owner frees with the object's own *_free.
#pragma once

#include <openssl/bio.h>
#include <openssl/bn.h>
#include <openssl/evp.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace mogao::ossl {

template <auto Free>
struct Deleter {
    template <typename T>
    void operator()(T* p) const noexcept {
        Free(p);
    }
};

using Pkey = std::unique_ptr<EVP_PKEY, Deleter<&EVP_PKEY_free>>;
using Cert = std::unique_ptr<X509, Deleter<&X509_free>>;
using Bio = std::unique_ptr<BIO, Deleter<&BIO_free_all>>;
using Bignum = std::unique_ptr<BIGNUM, Deleter<&BN_free>>;
using Store = std::unique_ptr<X509_STORE, Deleter<&X509_STORE_free>>;
using StoreCtx = std::unique_ptr<X509_STORE_CTX, Deleter<&X509_STORE_CTX_free>>;
using GeneralNames = std::unique_ptr<GENERAL_NAMES, Deleter<&GENERAL_NAMES_free>>;
using GeneralName = std::unique_ptr<GENERAL_NAME, Deleter<&GENERAL_NAME_free>>;
using OctetString = std::unique_ptr<ASN1_OCTET_STRING, Deleter<&ASN1_OCTET_STRING_free>>;

// Drains OpenSSL's thread-local error queue into one line ("" when empty).
[[nodiscard]] std::string errors();

// Parses PEM text; null (with the reason left in the error queue) when it holds none.
[[nodiscard]] Cert parse_cert(std::string_view pem);
[[nodiscard]] std::vector<Cert> parse_certs(std::string_view pem);  // every certificate in the text
[[nodiscard]] Pkey parse_key(std::string_view pem);

[[nodiscard]] std::string cert_to_pem(X509* cert);
[[nodiscard]] std::string key_to_pem(EVP_PKEY* key);  // unencrypted PKCS#8

[[nodiscard]] std::string subject_cn(X509* cert);
[[nodiscard]] std::string not_after_text(X509* cert);  // e.g. "Jan  1 00:00:00 2035 GMT"

}  // namespace mogao::ossl
