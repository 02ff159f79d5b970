// SPDX-License-Identifier: Apache-2.0
// RAII owners for the OpenSSL 3 objects the link uses and PEM helpers. Internal to
// renderfarm/link (tls_material.cpp, pki.cpp). Every owner frees with the object's own *_free.
#pragma once

#include <openssl/bio.h>
#include <openssl/bn.h>
#include <openssl/evp.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/unique_handle.h"

namespace mogao::ossl {

using Pkey = UniquePtr<EVP_PKEY, &EVP_PKEY_free>;
using Cert = UniquePtr<X509, &X509_free>;
using Bio = UniquePtr<BIO, &BIO_free_all>;
using Bignum = UniquePtr<BIGNUM, &BN_free>;
using Store = UniquePtr<X509_STORE, &X509_STORE_free>;
using StoreCtx = UniquePtr<X509_STORE_CTX, &X509_STORE_CTX_free>;
using GeneralNames = UniquePtr<GENERAL_NAMES, &GENERAL_NAMES_free>;
using GeneralName = UniquePtr<GENERAL_NAME, &GENERAL_NAME_free>;
using OctetString = UniquePtr<ASN1_OCTET_STRING, &ASN1_OCTET_STRING_free>;
using Crl = UniquePtr<X509_CRL, &X509_CRL_free>;
using Revoked = UniquePtr<X509_REVOKED, &X509_REVOKED_free>;
using Time = UniquePtr<ASN1_TIME, &ASN1_TIME_free>;

// Drains OpenSSL's thread-local error queue into one line ("" when empty).
[[nodiscard]] std::string errors();

// Parses PEM text; null (with the reason left in the error queue) when it holds none.
[[nodiscard]] Cert parse_cert(std::string_view pem);
[[nodiscard]] std::vector<Cert> parse_certs(std::string_view pem);  // every certificate in the text
[[nodiscard]] Pkey parse_key(std::string_view pem);
[[nodiscard]] Crl parse_crl(std::string_view pem);

[[nodiscard]] std::string cert_to_pem(X509* cert);
[[nodiscard]] std::string key_to_pem(EVP_PKEY* key);  // unencrypted PKCS#8
[[nodiscard]] std::string crl_to_pem(X509_CRL* crl);

// Upper-case hexadecimal of an ASN.1 INTEGER (a serial number), "" on failure.
[[nodiscard]] std::string integer_hex(const ASN1_INTEGER* value);
// Seconds since the Unix epoch of an ASN.1 time; 0 when null or unparsable.
[[nodiscard]] std::int64_t time_seconds(const ASN1_TIME* time);

[[nodiscard]] std::string subject_cn(X509* cert);
[[nodiscard]] std::string not_after_text(X509* cert);  // e.g. "Jan  1 00:00:00 2035 GMT"

}  // namespace mogao::ossl
