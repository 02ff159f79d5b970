// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/cert_expiry.h"

#include <openssl/err.h>

#include <ctime>

#include <fmt/format.h>

#include "common/link_types.h"
#include "renderfarm/link/openssl_util.h"

namespace mogao {
namespace {

CertificateExpiry expiry_of(X509* cert, const std::string& role) {
    return {role, ossl::subject_cn(cert), ossl::time_seconds(X509_get0_notAfter(cert))};
}

std::string role_words(const std::string& role) {
    if (role == "ca") return "the farm CA certificate";
    return "the " + role + " certificate";
}

}  // namespace

std::int64_t certificate_not_after_s(const std::string& cert_pem) {
    const ossl::Cert cert = ossl::parse_cert(cert_pem);
    ERR_clear_error();
    if (!cert) throw LinkError("not a PEM certificate: cannot read its notAfter");
    return ossl::time_seconds(X509_get0_notAfter(cert.get()));
}

std::vector<CertificateExpiry> certificate_expiries(const TlsMaterial& material, const std::string& own_role) {
    std::vector<CertificateExpiry> out;
    for (const auto& ca : ossl::parse_certs(material.ca_pem)) out.push_back(expiry_of(ca.get(), "ca"));
    if (const ossl::Cert own = ossl::parse_cert(material.cert_pem)) out.push_back(expiry_of(own.get(), own_role));
    ERR_clear_error();  // leave the queue empty for gRPC, which shares it on this thread
    return out;
}

std::int64_t days_left(std::int64_t not_after_s, std::int64_t now_s) {
    const std::int64_t left = not_after_s - now_s;
    constexpr std::int64_t kDay = 86'400;
    return left >= 0 ? left / kDay : -((-left + kDay - 1) / kDay);
}

bool expires_soon(const CertificateExpiry& cert, std::int64_t now_s, std::int64_t within_s) {
    return within_s > 0 && cert.not_after_s - now_s < within_s;
}

std::vector<std::string> expiry_warnings(const std::vector<CertificateExpiry>& certs, std::int64_t now_s,
                                         std::int64_t within_s) {
    std::vector<std::string> out;
    for (const auto& c : certs) {
        if (!expires_soon(c, now_s, within_s)) continue;
        const std::int64_t days = days_left(c.not_after_s, now_s);
        const std::string when = c.not_after_s <= now_s ? fmt::format("expired {} day(s) ago", -days)
                                                        : fmt::format("expires in {} day(s)", days);
        out.push_back(fmt::format("{} CN={} {} ({}): renew it (docs/link.md, \"Renewing certificates\")",
                                  role_words(c.role), c.name, when, utc_seconds_text(c.not_after_s)));
    }
    return out;
}

std::string utc_seconds_text(std::int64_t unix_s) {
    const auto seconds = static_cast<std::time_t>(unix_s);
    std::tm utc{};
    if (::gmtime_r(&seconds, &utc) == nullptr) return "?";
    return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}Z", utc.tm_year + 1900, utc.tm_mon + 1, utc.tm_mday,
                       utc.tm_hour, utc.tm_min, utc.tm_sec);
}

HeldCertificates::HeldCertificates(const TlsMaterial& material, TlsFilePaths files, std::string own_role,
                                   std::chrono::seconds refresh)
    : files_(std::move(files)),
      own_role_(std::move(own_role)),
      refresh_(refresh),
      held_(certificate_expiries(material, own_role_)),
      last_(material),
      next_look_(std::chrono::steady_clock::now() + refresh) {}

std::vector<CertificateExpiry> HeldCertificates::current() {
    const std::lock_guard lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (files_.empty() || now < next_look_) return held_;
    next_look_ = now + refresh_;
    try {
        TlsMaterial fresh = load_tls_files(files_.ca, files_.cert, files_.key);
        if (fresh.ca_pem == last_.ca_pem && fresh.cert_pem == last_.cert_pem) return held_;
        if (!check_tls_material(fresh, own_role_).error.empty()) return held_;  // not taken by gRPC either
        held_ = certificate_expiries(fresh, own_role_);
        last_ = std::move(fresh);
    } catch (const std::exception&) {
        // A file replaced right now (or gone): the material in use is still the last good one.
    }
    return held_;
}

}  // namespace mogao
