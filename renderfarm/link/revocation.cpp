// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/revocation.h"

#include <sys/stat.h>

#include <algorithm>
#include <utility>

#include "common/link_types.h"
#include "renderfarm/link/link_log.h"
#include "renderfarm/link/openssl_util.h"
#include "renderfarm/link/tls_material.h"

namespace mogao {

RevocationList parse_crl(const std::string& crl_pem, const std::string& ca_pem, const std::string& source) {
    const auto fail = [&](const std::string& why) -> LinkError {
        const std::string detail = ossl::errors();
        return LinkError(source + ": " + why + (detail.empty() ? "" : " (" + detail + ")"));
    };
    ossl::Crl crl = ossl::parse_crl(crl_pem);
    if (!crl) throw fail("not a PEM certificate revocation list (X509 CRL)");
    ossl::Cert ca = ossl::parse_cert(ca_pem);
    if (!ca) throw fail("the farm CA certificate does not parse");
    // Issued by the farm CA and signed with its key (RFC 5280 6.3.3 (b), (f)): anyone who can
    // write the file could otherwise un-revoke a certificate by writing a list of their own.
    if (X509_NAME_cmp(X509_CRL_get_issuer(crl.get()), X509_get_subject_name(ca.get())) != 0) {
        throw fail("issued by another CA than ca.pem");
    }
    if (X509_CRL_verify(crl.get(), X509_get0_pubkey(ca.get())) != 1) throw fail("its signature is not the farm CA's");
    RevocationList list;
    list.this_update_s = ossl::time_seconds(X509_CRL_get0_lastUpdate(crl.get()));
    list.next_update_s = ossl::time_seconds(X509_CRL_get0_nextUpdate(crl.get()));
    STACK_OF(X509_REVOKED)* revoked = X509_CRL_get_REVOKED(crl.get());
    for (int i = 0; i < sk_X509_REVOKED_num(revoked); ++i) {
        const X509_REVOKED* entry = sk_X509_REVOKED_value(revoked, i);
        std::string serial = ossl::integer_hex(X509_REVOKED_get0_serialNumber(entry));
        if (serial.empty()) throw fail("entry " + std::to_string(i) + " has no readable serial number");
        list.revoked.push_back({std::move(serial), ossl::time_seconds(X509_REVOKED_get0_revocationDate(entry))});
    }
    return list;
}

std::string cert_serial_hex(const std::string& cert_pem) {
    ossl::Cert cert = ossl::parse_cert(cert_pem);
    if (!cert) {
        static_cast<void>(ossl::errors());
        return {};
    }
    return ossl::integer_hex(X509_get0_serialNumber(cert.get()));
}

bool is_revoked(const RevocationList& list, const std::string& serial_hex) {
    return std::any_of(list.revoked.begin(), list.revoked.end(),
                       [&](const RevokedCert& r) { return r.serial_hex == serial_hex; });
}

RevocationWatcher::RevocationWatcher(std::filesystem::path path, std::string ca_pem, std::chrono::milliseconds recheck)
    : path_(std::move(path)), ca_pem_(std::move(ca_pem)), recheck_(recheck) {
    struct stat st {};
    if (::stat(path_.c_str(), &st) != 0) throw LinkError(path_.string() + ": cannot read the revocation list");
    list_ = parse_crl(read_pem_file(path_), ca_pem_, path_.string());
    id_ = {st.st_ino, st.st_size, std::int64_t{st.st_mtim.tv_sec} * 1'000'000'000 + st.st_mtim.tv_nsec};
    checked_ = std::chrono::steady_clock::now();
}

void RevocationWatcher::refresh_locked() {
    const auto now = std::chrono::steady_clock::now();
    if (now - checked_ < recheck_) return;
    checked_ = now;
    struct stat st {};
    if (::stat(path_.c_str(), &st) != 0) {
        link_log().error("{}: the revocation list is gone; keeping the last one read", path_.string());
        return;
    }
    const FileId id{st.st_ino, st.st_size, std::int64_t{st.st_mtim.tv_sec} * 1'000'000'000 + st.st_mtim.tv_nsec};
    if (id == id_) return;
    id_ = id;  // a bad file is reported once, not on every check
    try {
        list_ = parse_crl(read_pem_file(path_), ca_pem_, path_.string());
        ++generation_;
        link_log().info("{}: revocation list reloaded, {} certificate(s) revoked", path_.string(),
                        list_.revoked.size());
    } catch (const std::exception& e) {
        link_log().error("{}; keeping the last good revocation list ({} revoked)", e.what(), list_.revoked.size());
    }
}

bool RevocationWatcher::revoked(const std::string& serial_hex) {
    const std::lock_guard lock(mutex_);
    refresh_locked();
    return is_revoked(list_, serial_hex);
}

std::uint64_t RevocationWatcher::generation() {
    const std::lock_guard lock(mutex_);
    refresh_locked();
    return generation_;
}

std::int64_t RevocationWatcher::next_update_s() {
    const std::lock_guard lock(mutex_);
    refresh_locked();
    return list_.next_update_s;
}

}  // namespace mogao
