// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/tls_material.h"

#include <fcntl.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include <openssl/err.h>

#include "common/link_types.h"
#include "common/unique_fd.h"
#include "renderfarm/link/openssl_util.h"

namespace mogao {

std::string read_pem_file(const std::filesystem::path& path) {
    constexpr std::size_t kMaxPemBytes = 1u << 20;  // a PEM chain is a few KiB; refuse to slurp a disk image
    const UniqueFd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
    if (!fd.valid()) throw LinkError("cannot open " + path.string() + ": " + std::strerror(errno));
    std::string text;
    char buffer[4096];
    for (;;) {
        const ssize_t n = ::read(fd.get(), buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw LinkError("cannot read " + path.string() + ": " + std::strerror(errno));
        if (n == 0) break;
        text.append(buffer, static_cast<std::size_t>(n));
        if (text.size() > kMaxPemBytes) throw LinkError(path.string() + " is larger than 1 MiB: not a PEM file");
    }
    if (text.empty()) throw LinkError(path.string() + " is empty");
    return text;
}

TlsMaterial load_tls_files(const std::filesystem::path& ca, const std::filesystem::path& cert,
                           const std::filesystem::path& key) {
    return {read_pem_file(ca), read_pem_file(cert), read_pem_file(key)};
}

TlsCheck check_tls_material(const TlsMaterial& m, const std::string& who) {
    TlsCheck check;
    const auto fail = [&](const std::string& what) {
        check.error = who + ": " + what;
        const std::string why = ossl::errors();
        if (!why.empty()) check.error += " (" + why + ")";
        return check;
    };
    auto cas = ossl::parse_certs(m.ca_pem);
    if (cas.empty()) return fail("the CA PEM holds no certificate");
    ossl::Cert cert = ossl::parse_cert(m.cert_pem);
    if (!cert) return fail("the certificate PEM holds no certificate");
    ossl::Pkey key = ossl::parse_key(m.key_pem);
    if (!key) return fail("the private key PEM holds no unencrypted private key");
    if (X509_check_private_key(cert.get(), key.get()) != 1) {
        return fail("the private key does not belong to the certificate (CN=" + ossl::subject_cn(cert.get()) + ")");
    }
    const std::string name = "certificate CN=" + ossl::subject_cn(cert.get());
    if (X509_cmp_current_time(X509_get0_notAfter(cert.get())) <= 0) {
        check.warnings.push_back(who + ": " + name + " expired on " + ossl::not_after_text(cert.get()));
    }
    if (X509_cmp_current_time(X509_get0_notBefore(cert.get())) >= 0) {
        check.warnings.push_back(who + ": " + name + " is not valid yet (check the clock)");
    }
    // Chain check without time (reported above), so a wrong CA is named as such.
    ossl::Store store(X509_STORE_new());
    ossl::StoreCtx ctx(X509_STORE_CTX_new());
    if (!store || !ctx) return fail("out of memory");
    for (const auto& ca : cas) X509_STORE_add_cert(store.get(), ca.get());
    X509_STORE_set_flags(store.get(), X509_V_FLAG_NO_CHECK_TIME);
    if (X509_STORE_CTX_init(ctx.get(), store.get(), cert.get(), nullptr) != 1)
        return fail("cannot set up verification");
    if (X509_verify_cert(ctx.get()) != 1) {
        check.warnings.push_back(who + ": " + name + " does not chain to the CA: " +
                                 X509_verify_cert_error_string(X509_STORE_CTX_get_error(ctx.get())));
    }
    ERR_clear_error();  // leave the queue empty for gRPC, which shares it on this thread
    return check;
}

}  // namespace mogao
